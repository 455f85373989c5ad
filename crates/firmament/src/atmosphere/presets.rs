//! Embedded presets. Each is a complete, commented TOML file under `data/presets/`; a
//! preset is nothing more than such a file, so `firmament atmosphere show NAME` prints it as
//! it is and users edit a copy.

use crate::{Error, Result};

/// Preset names, the default first.
pub const NAMES: [&str; 5] = ["earth", "bruneton2008", "frostbite2016", "hazy", "mars"];

/// The commented TOML text of a preset.
pub fn toml_text(name: &str) -> Result<&'static str> {
    Ok(match name {
        "earth" => include_str!("../../data/presets/earth.toml"),
        "bruneton2008" => include_str!("../../data/presets/bruneton2008.toml"),
        "frostbite2016" => include_str!("../../data/presets/frostbite2016.toml"),
        "hazy" => include_str!("../../data/presets/hazy.toml"),
        "mars" => include_str!("../../data/presets/mars.toml"),
        _ => return Err(Error::UnknownPreset(name.to_string(), NAMES.join(", "))),
    })
}

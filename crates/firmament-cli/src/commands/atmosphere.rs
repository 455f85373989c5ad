//! `firmament atmosphere show|list|check`: print or check atmosphere definitions.

use std::path::PathBuf;

use anyhow::Result;
use clap::Subcommand;
use firmament::atmosphere::{presets, Atmosphere};

/// What `firmament atmosphere` does.
#[derive(Subcommand, Debug)]
pub enum AtmosphereAction {
    /// Print a preset as a complete, commented TOML file.
    Show {
        /// Preset name.
        name: String,
    },
    /// List the presets.
    List,
    /// Check an atmosphere file and print it back, complete.
    Check {
        /// TOML file.
        file: PathBuf,
    },
}

/// Run `firmament atmosphere ACTION`.
pub fn run(action: &AtmosphereAction) -> Result<()> {
    match action {
        AtmosphereAction::Show { name } => print!("{}", presets::toml_text(name)?),
        AtmosphereAction::List => {
            for name in presets::NAMES {
                let atmosphere = Atmosphere::preset(name)?;
                println!("{name:14} {}", atmosphere.description);
            }
        }
        AtmosphereAction::Check { file } => {
            let atmosphere = Atmosphere::from_file(file)?;
            print!("{}", atmosphere.to_toml());
        }
    }
    Ok(())
}

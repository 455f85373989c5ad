//! Scene files (TOML): everything `firmament render` needs, with defaults that make a
//! handsome picture. Unknown fields are refused.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::camera::{Camera, Projection};
use crate::render::tonemap::ToneCurve;
use crate::{Error, Result};

/// Which atmosphere.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneAtmosphere {
    /// Preset name (ignored when `file` is given).
    #[serde(default = "default_preset")]
    pub preset: String,
    /// Atmosphere TOML file, relative to the scene file.
    #[serde(default)]
    pub file: Option<PathBuf>,
    /// `rgb`, `spectral` or `NM,NM,...`.
    #[serde(default = "default_wavelengths")]
    pub wavelengths: String,
}

fn default_preset() -> String {
    "earth".into()
}
fn default_wavelengths() -> String {
    "rgb".into()
}

/// Image size.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneImage {
    /// Width (pixels).
    pub width: usize,
    /// Height (pixels).
    pub height: usize,
}

/// The sun.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneSun {
    /// Zenith angle (degrees, 0–180).
    pub zenith_deg: f64,
    /// Azimuth (degrees clockwise from north).
    #[serde(default)]
    pub azimuth_deg: f64,
    /// Draw the solar disk.
    #[serde(default = "yes")]
    pub disk: bool,
}

fn yes() -> bool {
    true
}

/// Exposure, tone mapping and files.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneOutput {
    /// Exposure value at ISO 100; automatic (log-average luminance) when absent.
    #[serde(default)]
    pub ev100: Option<f64>,
    /// Tone curve for PNG output.
    #[serde(default)]
    pub tonemap: ToneCurve,
    /// White-balance to the sun's colour.
    #[serde(default)]
    pub white_balance: bool,
    /// Output files; the format follows the extension (.png, .exr, .hdr).
    #[serde(default = "default_files")]
    pub files: Vec<PathBuf>,
}

fn default_files() -> Vec<PathBuf> {
    vec![
        PathBuf::from("firmament.png"),
        PathBuf::from("firmament.exr"),
    ]
}

/// A whole scene file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    /// Atmosphere.
    pub atmosphere: SceneAtmosphere,
    /// Camera.
    pub camera: Camera,
    /// Image size.
    pub image: SceneImage,
    /// Sun.
    pub sun: SceneSun,
    /// Output.
    pub output: SceneOutput,
}

impl Default for SceneFile {
    /// Late afternoon from a hill 1.5 km up, looking west-south-west towards the low sun
    /// over the planet's curved horizon.
    fn default() -> Self {
        SceneFile {
            atmosphere: SceneAtmosphere {
                preset: default_preset(),
                file: None,
                wavelengths: default_wavelengths(),
            },
            camera: Camera {
                projection: Projection::Perspective,
                altitude_m: 1500.0,
                heading_deg: 235.0,
                pitch_deg: 8.0,
                roll_deg: 0.0,
                fov_deg: 65.0,
            },
            image: SceneImage {
                width: 1280,
                height: 720,
            },
            sun: SceneSun {
                zenith_deg: 84.0,
                azimuth_deg: 250.0,
                disk: true,
            },
            output: SceneOutput {
                ev100: None,
                tonemap: ToneCurve::Aces,
                white_balance: false,
                files: default_files(),
            },
        }
    }
}

impl SceneFile {
    /// Parse a scene file; relative paths are resolved against its directory.
    pub fn from_file(path: &Path) -> Result<SceneFile> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::File {
            path: path.display().to_string(),
            reason: e.to_string(),
        })?;
        let mut scene: SceneFile = toml::from_str(&text)
            .map_err(|e| Error::Toml(format!("scene {}: {e}", path.display())))?;
        if let (Some(f), Some(dir)) = (&scene.atmosphere.file, path.parent()) {
            if f.is_relative() {
                scene.atmosphere.file = Some(dir.join(f));
            }
        }
        scene.validate()?;
        Ok(scene)
    }

    /// Check every value; messages name the field.
    pub fn validate(&self) -> Result<()> {
        self.camera.validate()?;
        let (w, h) = (self.image.width, self.image.height);
        if !(1..=32768).contains(&w) {
            return Err(Error::invalid("image.width", w, "an integer in [1, 32768]"));
        }
        if !(1..=32768).contains(&h) {
            return Err(Error::invalid(
                "image.height",
                h,
                "an integer in [1, 32768]",
            ));
        }
        if self.camera.projection == Projection::Cubemap && w != 6 * h {
            return Err(Error::invalid(
                "image.width",
                w,
                format!("6 × image.height ({}) for a cube map", 6 * h),
            ));
        }
        if !(self.sun.zenith_deg.is_finite() && (0.0..=180.0).contains(&self.sun.zenith_deg)) {
            return Err(Error::invalid(
                "sun.zenith_deg",
                self.sun.zenith_deg,
                "a number in [0, 180] degrees",
            ));
        }
        if !(self.sun.azimuth_deg.is_finite() && self.sun.azimuth_deg.abs() <= 360.0) {
            return Err(Error::invalid(
                "sun.azimuth_deg",
                self.sun.azimuth_deg,
                "a number in [-360, 360] degrees",
            ));
        }
        if let Some(ev) = self.output.ev100 {
            if !(ev.is_finite() && (-20.0..=30.0).contains(&ev)) {
                return Err(Error::invalid("output.ev100", ev, "a number in [-20, 30]"));
            }
        }
        if self.output.files.is_empty() {
            return Err(Error::invalid("output.files", "[]", "at least one file"));
        }
        for (i, f) in self.output.files.iter().enumerate() {
            crate::io::OutputFormat::from_path(f).map_err(|_| {
                Error::invalid(
                    format!("output.files[{i}]"),
                    f.display(),
                    "a file name ending in .png, .exr or .hdr",
                )
            })?;
        }
        Ok(())
    }
}

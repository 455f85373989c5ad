//! The scene file's `[surface]`: the planet's ground from afar ([`super::planet`]), a
//! procedural Earth by default or a user's equirectangular map (8-bit sRGB PNG).

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::planet::{PlanetSurface, SurfaceMap};
use crate::spectrum::colour::srgb_to_linear;
use crate::{Error, Result};

/// `[surface]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SurfaceConfig {
    /// An equirectangular map (8-bit sRGB PNG, row 0 at 90° N, column 0 at 180° W; relative
    /// to the scene file); none: the procedural Earth.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub map: Option<PathBuf>,
    /// Procedural: seed of the continents.
    pub seed: u64,
    /// Procedural: the share of the sphere that is sea (Earth: 0.71).
    pub ocean_fraction: f64,
    /// Wind speed over the sea (m/s) for the sun's glint (Cox & Munk 1954).
    pub wind_m_s: f64,
    /// The sun's glint on the sea (procedural maps).
    pub glint: bool,
}

impl Default for SurfaceConfig {
    fn default() -> Self {
        SurfaceConfig {
            map: None,
            seed: 3,
            // 361 of 510 million km² (NOAA).
            ocean_fraction: 0.71,
            wind_m_s: 7.0,
            glint: true,
        }
    }
}

impl SurfaceConfig {
    /// Check every value; messages name the field.
    pub fn validate(&self) -> Result<()> {
        if !(self.ocean_fraction.is_finite() && (0.0..=1.0).contains(&self.ocean_fraction)) {
            return Err(Error::invalid(
                "surface.ocean_fraction",
                self.ocean_fraction,
                "a number in [0, 1]",
            ));
        }
        if !(self.wind_m_s.is_finite() && (0.0..=25.0).contains(&self.wind_m_s)) {
            return Err(Error::invalid(
                "surface.wind_m_s",
                self.wind_m_s,
                "a number in [0, 25] m/s (Cox & Munk's range: 1–14)",
            ));
        }
        Ok(())
    }

    /// Paths relative to the scene file's directory.
    pub fn resolve_paths(&mut self, dir: &Path) {
        if let Some(p) = &self.map {
            if p.is_relative() {
                self.map = Some(dir.join(p));
            }
        }
    }

    /// The planet's ground of radius `radius_m`, the observer at (`lat_deg`, `lon_deg`),
    /// spectra at `wavelengths_nm`.
    pub fn build(
        &self,
        radius_m: f64,
        lat_deg: f64,
        lon_deg: f64,
        wavelengths_nm: &[f64],
    ) -> Result<PlanetSurface> {
        self.validate()?;
        let map = match &self.map {
            Some(path) => read_map(path)?,
            None => SurfaceMap::Procedural {
                seed: self.seed,
                ocean_fraction: self.ocean_fraction,
            },
        };
        let wind = self.glint.then_some(self.wind_m_s);
        Ok(PlanetSurface::new(
            radius_m,
            map,
            lat_deg,
            lon_deg,
            wavelengths_nm,
            wind,
        ))
    }
}

/// An 8-bit sRGB PNG (RGB or RGBA, alpha ignored) as linear colours. Errors name the field
/// `surface.map`.
pub fn read_map(path: &Path) -> Result<SurfaceMap> {
    let img = crate::io::png::decode_png_input(path, "surface.map", "an 8-bit sRGB PNG file")?;
    let rgb = match img {
        image::DynamicImage::ImageRgb8(i) => i,
        image::DynamicImage::ImageRgba8(_) => img.to_rgb8(),
        other => {
            return Err(Error::invalid(
                "surface.map",
                format!("{} ({:?})", path.display(), other.color()),
                "an 8-bit sRGB PNG (colour type RGB8 or RGBA8)",
            ))
        }
    };
    let (w, h) = (rgb.width() as usize, rgb.height() as usize);
    if w < 2 || h < 2 {
        return Err(Error::invalid(
            "surface.map",
            format!("{w}×{h} pixels"),
            "at least 2×2 pixels",
        ));
    }
    let lut: Vec<f32> = (0..256)
        .map(|v| srgb_to_linear(v as f64 / 255.0) as f32)
        .collect();
    Ok(SurfaceMap::Image {
        width: w,
        height: h,
        rgb: rgb.pixels().map(|p| p.0.map(|c| lut[c as usize])).collect(),
    })
}

//! Terrain: a heightfield on the planet (heights above the sphere, following its curvature),
//! procedural ([`relief`]) or from a 16-bit PNG ([`heightmap`]); hit exactly by rays
//! ([`grid`]: a max-mip walk over the gnomonic grid), coloured by snow, rock, grass and
//! forest ([`materials`]), occluding the sky ([`occlusion`]), and shadowing itself and the
//! air, which makes the light shafts ([`shadow`]).
//!
//! The scene file's `[terrain]` section is [`TerrainConfig`].

pub mod grid;
pub mod heightfield;
pub mod heightmap;
pub mod materials;
pub mod occlusion;
pub mod relief;
pub mod shadow;
pub mod walk;

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

pub use heightfield::Heightfield;
pub use materials::{Materials, Zones};
pub use relief::ReliefParams;

use crate::{Error, Result};

/// The scene file's `[terrain]`: a procedural relief by default, or a heightmap.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct TerrainConfig {
    /// A 16-bit greyscale PNG of heights (relative to the scene file); none: procedural.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub heightmap: Option<PathBuf>,
    /// Heights (m above the sphere) of black and white in the heightmap.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub height_range_m: Option<[f64; 2]>,
    /// Width west to east (m); the procedural relief is square.
    pub extent_m: f64,
    /// Plane coordinates (east, north; m) of the terrain's centre from the observer.
    pub centre_m: [f64; 2],
    /// Procedural: vertices per side.
    pub resolution: usize,
    /// Procedural: seed of the noise.
    pub seed: u64,
    /// Procedural: height of the ridges above the valley floor (m, about).
    pub height_scale_m: f64,
    /// Procedural: wavelength of the largest mountains (m).
    pub feature_size_m: f64,
    /// Procedural: height of the valley floor (m above the sphere).
    pub floor_m: f64,
    /// Procedural: half-width of the valley through the centre (m; 0 for none).
    pub valley_width_m: f64,
    /// Procedural: heading of the valley (degrees clockwise from north).
    pub valley_heading_deg: f64,
    /// Snow above this height (m).
    pub snow_line_m: f64,
    /// Forest below this height (m).
    pub tree_line_m: f64,
    /// One albedo everywhere instead of the materials.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub albedo: Option<f64>,
    /// Shadows of the terrain on itself and on the ground.
    pub shadows: bool,
    /// Its shadows in the air: the light shafts (with `shadows`).
    pub light_shafts: bool,
    /// Ambient occlusion of the sky light by the terrain.
    pub occlusion: bool,
    /// The terrain's change of the air's multiply scattered light: the sky the mountains
    /// hide from the air and the light they send into it (`render::terrain_air`).
    pub air_light: bool,
}

impl Default for TerrainConfig {
    /// An alpine valley about 40 km across, ridges near 2.4 km.
    fn default() -> Self {
        TerrainConfig {
            heightmap: None,
            height_range_m: None,
            extent_m: 40_000.0,
            centre_m: [0.0, 0.0],
            resolution: 1025,
            seed: 7,
            height_scale_m: 2400.0,
            feature_size_m: 11_000.0,
            floor_m: 420.0,
            valley_width_m: 1800.0,
            valley_heading_deg: 70.0,
            snow_line_m: 2300.0,
            tree_line_m: 1700.0,
            albedo: None,
            shadows: true,
            light_shafts: true,
            occlusion: true,
            air_light: true,
        }
    }
}

impl TerrainConfig {
    /// Check every value; messages name the field.
    pub fn validate(&self) -> Result<()> {
        let positive = |name: &str, v: f64, max: f64| {
            if v.is_finite() && v > 0.0 && v <= max {
                Ok(())
            } else {
                Err(Error::invalid(
                    format!("terrain.{name}"),
                    v,
                    format!("a number in (0, {max}] m"),
                ))
            }
        };
        positive("extent_m", self.extent_m, 2.0e6)?;
        positive("feature_size_m", self.feature_size_m, 1.0e7)?;
        if !(3..=8193).contains(&self.resolution) {
            return Err(Error::invalid(
                "terrain.resolution",
                self.resolution,
                "an integer in [3, 8193] vertices per side",
            ));
        }
        for (name, v) in [
            ("height_scale_m", self.height_scale_m),
            ("floor_m", self.floor_m),
            ("valley_width_m", self.valley_width_m),
        ] {
            if !(v.is_finite() && (0.0..=20_000.0).contains(&v)) {
                return Err(Error::invalid(
                    format!("terrain.{name}"),
                    v,
                    "a number in [0, 20000] m",
                ));
            }
        }
        for (name, v) in [
            ("snow_line_m", self.snow_line_m),
            ("tree_line_m", self.tree_line_m),
            ("valley_heading_deg", self.valley_heading_deg),
            ("centre_m", self.centre_m[0]),
            ("centre_m", self.centre_m[1]),
        ] {
            if !v.is_finite() {
                return Err(Error::invalid(
                    format!("terrain.{name}"),
                    v,
                    "a finite number",
                ));
            }
        }
        if let Some(a) = self.albedo {
            if !(a.is_finite() && (0.0..=1.0).contains(&a)) {
                return Err(Error::invalid("terrain.albedo", a, "a number in [0, 1]"));
            }
        }
        match (&self.heightmap, self.height_range_m) {
            (Some(_), None) => Err(Error::invalid(
                "terrain.height_range_m",
                "missing",
                "[lowest, highest] heights (m) of black and white, with terrain.heightmap",
            )),
            (Some(_), Some([lo, hi])) if !(lo.is_finite() && hi.is_finite() && lo < hi) => {
                Err(Error::invalid(
                    "terrain.height_range_m",
                    format!("[{lo}, {hi}]"),
                    "two finite heights, the first below the second",
                ))
            }
            (Some(_), Some([lo, _])) if lo < 0.0 => Err(Error::invalid(
                "terrain.height_range_m",
                lo,
                "heights ≥ 0 m (above the sphere)",
            )),
            _ => Ok(()),
        }
    }

    /// Paths relative to the scene file's directory `dir`.
    pub fn resolve_paths(&mut self, dir: &Path) {
        if let Some(p) = &self.heightmap {
            if p.is_relative() {
                self.heightmap = Some(dir.join(p));
            }
        }
    }

    /// The heightfield on a planet of radius `radius_m`, its materials at `wavelengths_nm`.
    pub fn build(&self, radius_m: f64, wavelengths_nm: &[f64]) -> Result<Heightfield> {
        self.validate()?;
        let heights = match (&self.heightmap, self.height_range_m) {
            (Some(path), Some(range)) => {
                heightmap::read_heightmap(path, self.extent_m, range, self.centre_m)?
            }
            _ => relief::relief(&ReliefParams {
                seed: self.seed,
                extent_m: self.extent_m,
                resolution: self.resolution,
                height_scale_m: self.height_scale_m,
                feature_size_m: self.feature_size_m,
                floor_m: self.floor_m,
                valley_width_m: self.valley_width_m,
                valley_heading_deg: self.valley_heading_deg,
                centre_m: self.centre_m,
            }),
        };
        let materials = match self.albedo {
            Some(a) => Materials::Uniform(vec![a; wavelengths_nm.len()]),
            None => Materials::ByHeightAndSlope(Zones::new(
                self.snow_line_m,
                self.tree_line_m,
                wavelengths_nm,
            )),
        };
        let occlusion = self
            .occlusion
            .then(|| occlusion::occlusion(&heights, radius_m, occlusion::STRIDE));
        let mut field = Heightfield::new(heights, radius_m, materials);
        field.casts_shadows = self.shadows;
        field.shafts = self.light_shafts;
        field.air_light = self.air_light;
        field.occlusion = occlusion;
        Ok(field)
    }
}

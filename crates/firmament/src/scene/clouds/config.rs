//! A `[[clouds]]` section as a scene file gives it: the layer's settings, the kind's
//! defaults for those left out ([`CloudLayerConfig::resolved`]), and their check, each bad
//! value refused with its field named and the accepted range ([`CloudLayerConfig::validate`]).

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::profile::CloudKind;
use crate::{Error, Result};

/// How the renderer estimates the light scattered more than once in a layer.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum MultipleScattering {
    /// The local plane-parallel δ-Eddington two-stream ([`super::two_stream`]).
    #[default]
    TwoStream,
    /// Octaves (Wrenninge 2015; Hillaire 2016 §5.6), `octaves`, `octave_*`.
    Octaves,
}

/// How a layer's weather map covers the planet.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum WeatherWrap {
    /// The map repeats every `weather_tile_m` ([`WeatherMap`]).
    #[default]
    Tile,
    /// One map over the sphere ([`PlanetaryWeather`]).
    Planet,
}

impl WeatherWrap {
    fn is_tile(&self) -> bool {
        *self == WeatherWrap::Tile
    }
}

/// A `[[clouds]]` section. Values left out take the kind's defaults
/// ([`CloudLayerConfig::resolved`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CloudLayerConfig {
    /// cumulus, altostratus, cirrus or uniform.
    pub kind: CloudKind,
    /// The layer's base above the planet's surface (m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bottom_m: Option<f64>,
    /// The layer's top above the planet's surface (m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub top_m: Option<f64>,
    /// The fraction of the layer's volume with cloud at its profile's peak height, in
    /// [0, 1] (1 for `uniform`); the weather varies it from place to place.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub coverage: Option<f64>,
    /// Extinction coefficient at density 1 (m⁻¹): 0.04–0.12 for cumulus (Hillaire 2016).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub extinction_per_m: Option<f64>,
    /// Single-scattering albedo σ_s/σ_t in [0, 1] (absorption = (1 − albedo)·σ_t); clouds'
    /// water scatters almost without loss at visible wavelengths.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub albedo: Option<f64>,
    /// The phase function's forward lobe asymmetry, in (−1, 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub phase_forward_g: Option<f64>,
    /// The backward lobe's asymmetry, in (−1, 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub phase_back_g: Option<f64>,
    /// The forward lobe's weight, in [0, 1].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub phase_forward_weight: Option<f64>,
    /// The weather map: a PNG (red coverage, green type, blue precipitation); none: the
    /// procedural map.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub weather: Option<PathBuf>,
    /// The weather map's tile (m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub weather_tile_m: Option<f64>,
    /// The base-shape noise's tile, horizontally (m; vertically divided by the kind's
    /// stretch).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shape_tile_m: Option<f64>,
    /// The erosion noise's tile (m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub detail_tile_m: Option<f64>,
    /// How the weather map covers the planet: `tile` (repeated every `weather_tile_m`) or
    /// `planet` (one equirectangular map over the whole sphere, the tiled map adding its
    /// detail near the observer: cloud systems seen from orbit).
    #[serde(default, skip_serializing_if = "WeatherWrap::is_tile")]
    pub weather_wrap: WeatherWrap,
    /// Seed of the procedural weather map.
    #[serde(default)]
    pub seed: u32,
    /// The wind's offset of the whole layer (east, north; m): animation and time-lapse move
    /// it.
    #[serde(default)]
    pub wind_offset_m: [f64; 2],
    /// How the light scattered more than once is estimated: `two-stream` (the default) or
    /// `octaves`.
    #[serde(default)]
    pub multiple_scattering: MultipleScattering,
    /// Multiple scattering by octaves (Wrenninge 2015): the number of octaves.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub octaves: Option<u32>,
    /// Octave n's scattering is aⁿ·σ_s (a ≤ b so that no octave scatters more than it
    /// extinguishes).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub octave_scattering: Option<f64>,
    /// Octave n's extinction towards the light is bⁿ·σ_t.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub octave_extinction: Option<f64>,
    /// Octave n's phase asymmetries are cⁿ·g.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub octave_eccentricity: Option<f64>,
}

/// A layer's settings with every default filled in.
#[derive(Clone, Debug, PartialEq)]
pub struct LayerParams {
    /// Kind.
    pub kind: CloudKind,
    /// Base and top above the surface (m).
    pub bottom_m: f64,
    /// Top (m).
    pub top_m: f64,
    /// Coverage in [0, 1].
    pub coverage: f64,
    /// σ_t at density 1 (m⁻¹).
    pub extinction_per_m: f64,
    /// σ_s/σ_t.
    pub albedo: f64,
    /// Dual-lobe HG: forward g, backward g, forward weight.
    pub phase: [f64; 3],
    /// Weather map file, if any.
    pub weather: Option<PathBuf>,
    /// Tiles (m): weather, shape, detail.
    pub tiles_m: [f64; 3],
    /// Tiled or planetary weather.
    pub weather_wrap: WeatherWrap,
    /// Procedural weather seed.
    pub seed: u32,
    /// Wind offset (m).
    pub wind_offset_m: [f64; 2],
    /// Two-stream or octaves.
    pub multiple_scattering: MultipleScattering,
    /// Octaves: count, a, b, c.
    pub octaves: u32,
    /// a, b, c.
    pub octave_gains: [f64; 3],
}

impl CloudLayerConfig {
    /// A layer of `kind` with every value at its default.
    pub fn of_kind(kind: CloudKind) -> CloudLayerConfig {
        CloudLayerConfig {
            kind,
            bottom_m: None,
            top_m: None,
            coverage: None,
            extinction_per_m: None,
            albedo: None,
            phase_forward_g: None,
            phase_back_g: None,
            phase_forward_weight: None,
            weather: None,
            weather_tile_m: None,
            shape_tile_m: None,
            detail_tile_m: None,
            weather_wrap: WeatherWrap::Tile,
            seed: 0,
            wind_offset_m: [0.0; 2],
            multiple_scattering: MultipleScattering::TwoStream,
            octaves: None,
            octave_scattering: None,
            octave_extinction: None,
            octave_eccentricity: None,
        }
    }

    /// The settings with the kind's defaults where none is given: cumulus 1.5–3.5 km,
    /// coverage 0.45, 0.05 m⁻¹ (Hillaire 2016's 0.04–0.12); altostratus 4–5.5 km, 0.8,
    /// 0.01 m⁻¹; cirrus 8–9.5 km, 0.5, 10⁻³ m⁻¹ (optical depth ≈ 0.5, Sassen & Cho
    /// 1992's thin cirrus); uniform 1–2 km, 0.01 m⁻¹ (optical thickness 10). Phase: g
    /// 0.8 / −0.5 weighted 0.8 / 0.2 (Hillaire 2016, fig. 39's balance of forward peak and
    /// back scatter); octaves 3 with a = b = c = 0.5 (Wrenninge 2015; Hillaire 2016).
    pub fn resolved(&self) -> LayerParams {
        let (bottom, top, coverage, extinction, tile) = match self.kind {
            CloudKind::Cumulus => (1500.0, 3500.0, 0.45, 0.05, 10_000.0),
            CloudKind::Altostratus => (4000.0, 5500.0, 0.8, 0.01, 20_000.0),
            CloudKind::Cirrus => (8000.0, 9500.0, 0.5, 1e-3, 30_000.0),
            CloudKind::Uniform => (1000.0, 2000.0, 1.0, 0.01, 6000.0),
        };
        LayerParams {
            kind: self.kind,
            bottom_m: self.bottom_m.unwrap_or(bottom),
            top_m: self.top_m.unwrap_or(top),
            coverage: self.coverage.unwrap_or(coverage),
            extinction_per_m: self.extinction_per_m.unwrap_or(extinction),
            albedo: self.albedo.unwrap_or(0.999),
            phase: [
                self.phase_forward_g.unwrap_or(0.8),
                self.phase_back_g.unwrap_or(-0.5),
                self.phase_forward_weight.unwrap_or(0.8),
            ],
            weather: self.weather.clone(),
            tiles_m: [
                self.weather_tile_m.unwrap_or(tile * 8.0),
                self.shape_tile_m.unwrap_or(tile),
                self.detail_tile_m.unwrap_or(tile / 8.0),
            ],
            weather_wrap: self.weather_wrap,
            seed: self.seed,
            wind_offset_m: self.wind_offset_m,
            multiple_scattering: self.multiple_scattering,
            octaves: self.octaves.unwrap_or(3),
            octave_gains: [
                self.octave_scattering.unwrap_or(0.5),
                self.octave_extinction.unwrap_or(0.5),
                self.octave_eccentricity.unwrap_or(0.5),
            ],
        }
    }

    /// Resolve a relative weather path against `dir` (the scene file's directory).
    pub fn resolve_paths(&mut self, dir: &Path) {
        if let Some(w) = &self.weather {
            if w.is_relative() {
                self.weather = Some(dir.join(w));
            }
        }
    }

    /// Check every value; `prefix` names the section (`clouds[0]`).
    pub fn validate(&self, prefix: &str) -> Result<()> {
        let p = self.resolved();
        let field = |name: &str| format!("{prefix}.{name}");
        let positive = |name: &str, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(Error::invalid(field(name), v, "a finite number > 0"))
            }
        };
        if !(p.bottom_m.is_finite() && (0.0..=100_000.0).contains(&p.bottom_m)) {
            return Err(Error::invalid(
                field("bottom_m"),
                p.bottom_m,
                "a number in [0, 100000] m",
            ));
        }
        if !(p.top_m.is_finite() && p.top_m > p.bottom_m && p.top_m <= 100_000.0) {
            return Err(Error::invalid(
                field("top_m"),
                p.top_m,
                format!(
                    "a number above bottom_m ({} m) and at most 100000 m",
                    p.bottom_m
                ),
            ));
        }
        if !(0.0..=1.0).contains(&p.coverage) {
            return Err(Error::invalid(
                field("coverage"),
                p.coverage,
                "a number in [0, 1]",
            ));
        }
        if self.kind == CloudKind::Uniform && p.coverage != 1.0 {
            return Err(Error::invalid(
                field("coverage"),
                p.coverage,
                "1 for a uniform layer (it has no weather)",
            ));
        }
        positive("extinction_per_m", p.extinction_per_m)?;
        if !(0.0..=1.0).contains(&p.albedo) {
            return Err(Error::invalid(
                field("albedo"),
                p.albedo,
                "a number in [0, 1]",
            ));
        }
        for (name, g) in [
            ("phase_forward_g", p.phase[0]),
            ("phase_back_g", p.phase[1]),
        ] {
            if !(g.is_finite() && g.abs() < 1.0) {
                return Err(Error::invalid(field(name), g, "a number in (-1, 1)"));
            }
        }
        if !(0.0..=1.0).contains(&p.phase[2]) {
            return Err(Error::invalid(
                field("phase_forward_weight"),
                p.phase[2],
                "a number in [0, 1]",
            ));
        }
        for (name, t) in [
            ("weather_tile_m", p.tiles_m[0]),
            ("shape_tile_m", p.tiles_m[1]),
            ("detail_tile_m", p.tiles_m[2]),
        ] {
            positive(name, t)?;
        }
        if !(1..=8).contains(&p.octaves) {
            return Err(Error::invalid(
                field("octaves"),
                p.octaves,
                "an integer in [1, 8]",
            ));
        }
        let [a, b, c] = p.octave_gains;
        for (name, v) in [
            ("octave_scattering", a),
            ("octave_extinction", b),
            ("octave_eccentricity", c),
        ] {
            if !(0.0..=1.0).contains(&v) {
                return Err(Error::invalid(field(name), v, "a number in [0, 1]"));
            }
        }
        if a > b {
            return Err(Error::invalid(
                field("octave_scattering"),
                a,
                format!("at most octave_extinction ({b}): an octave must not scatter more than it extinguishes (Hillaire 2016, a ≤ b)"),
            ));
        }
        if self.kind == CloudKind::Uniform && self.weather_wrap == WeatherWrap::Planet {
            return Err(Error::invalid(
                field("weather_wrap"),
                "planet",
                "tile for a uniform layer (it has no weather)",
            ));
        }
        if self.kind == CloudKind::Uniform && self.weather.is_some() {
            return Err(Error::invalid(
                field("weather"),
                "given",
                "none for a uniform layer",
            ));
        }
        if !self.wind_offset_m.iter().all(|v| v.is_finite()) {
            return Err(Error::invalid(
                field("wind_offset_m"),
                format!("{:?}", self.wind_offset_m),
                "two finite numbers (m)",
            ));
        }
        Ok(())
    }
}

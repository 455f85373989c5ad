//! One cloud layer: its settings as a scene file gives them (`[[clouds]]`), checked, and the
//! density it has at a point: a shell between two altitudes that follows the planet, shaped
//! by the weather map, the type's height profile and the two noise textures, after
//! Schneider (2015) and Hillaire (2016, seed "Cloud distribution and density"):
//!
//! c_loc = clamp(c + k·(w − ½), 0, 1),
//! shape = max(0, remap(base·profile(h, t), 1 − c_loc, 1, 0, 1)),
//! density = max(0, remap(shape, erosion(h)·detail, 1, 0, 1))·(1 + 2p),
//!
//! with c the layer's coverage, w the weather value (uniform on [0, 1]) and k its contrast,
//! base and detail the Perlin–Worley (equalised to uniform on [0, 1]) and Worley fBm
//! textures, t and p the weather's type and precipitation. With base uniform, the fraction
//! of the layer's volume with cloud at the profile's peak is c_loc: the noise carves the
//! cells, the weather gathers them into fields and clears gaps between. The medium's
//! extinction is `extinction_per_m`·density, its scattering albedo `albedo`, its phase
//! function two Henyey–Greenstein lobes.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use serde::{Deserialize, Serialize};

use super::noise::remap;
use super::noise_volume::NoiseVolume;
use super::profile::CloudKind;
use super::weather::WeatherMap;
use crate::math::Vec3;
use crate::{Error, Result};

/// How far the weather moves the local coverage about the layer's: c_loc = c + k·(w − ½).
pub const WEATHER_CONTRAST: f64 = 0.7;
/// How much the weather's precipitation raises the density (1 + gain·p).
pub const PRECIPITATION_GAIN: f64 = 2.0;

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

/// A layer ready to be sampled.
#[derive(Clone, Debug)]
pub struct CloudLayer {
    /// The settings.
    pub params: LayerParams,
    /// Radii of the base and the top (m, planet-centred).
    pub radii_m: [f64; 2],
    /// The planet's radius (m): planar coordinates are arcs on it.
    pub planet_radius_m: f64,
    /// Weather (None for `uniform`).
    pub weather: Option<WeatherMap>,
    /// The base shape and erosion textures (None for `uniform`).
    pub noise: Option<[Arc<NoiseVolume>; 2]>,
}

impl CloudLayer {
    /// Build the layer over a planet of `planet_radius_m` with the shared noise textures.
    /// `prefix` names the section in errors.
    pub fn new(
        config: &CloudLayerConfig,
        planet_radius_m: f64,
        noise: [Arc<NoiseVolume>; 2],
        prefix: &str,
    ) -> Result<CloudLayer> {
        config.validate(prefix)?;
        let params = config.resolved();
        let uniform = params.kind == CloudKind::Uniform;
        let weather = match (&params.weather, uniform) {
            (_, true) => None,
            (Some(path), false) => Some(WeatherMap::from_png(
                path,
                params.kind,
                params.tiles_m[0],
                &format!("{prefix}.weather"),
            )?),
            (None, false) => Some(WeatherMap::procedural(
                params.kind,
                params.seed,
                params.tiles_m[0],
            )),
        };
        Ok(CloudLayer {
            radii_m: [
                planet_radius_m + params.bottom_m,
                planet_radius_m + params.top_m,
            ],
            planet_radius_m,
            weather,
            noise: (!uniform).then_some(noise),
            params,
        })
    }

    /// Planar coordinates (m) of the point above `dir` (a unit vector from the planet's
    /// centre): the gnomonic projection onto the tangent plane of the cube face the
    /// direction falls on, scaled to the planet's radius (the +z face is the observer's: x
    /// east, y north, true distances near the observer's place), so that a flat weather map
    /// covers the planet with seams only at the faces' edges, 45° of arc away. Great circles
    /// map to straight lines.
    #[inline]
    pub fn planar(&self, dir: Vec3) -> (f64, f64) {
        let (ax, ay, az) = (dir.x.abs(), dir.y.abs(), dir.z.abs());
        let r = self.planet_radius_m;
        if az >= ax && az >= ay {
            let s = r / az;
            (dir.x * s, dir.y * s)
        } else if ax >= ay {
            let s = r / ax;
            (dir.y * s + 4.0 * r, dir.z * s)
        } else {
            let s = r / ay;
            (dir.x * s + 8.0 * r, dir.z * s)
        }
    }

    /// The density (dimensionless, extinction over `extinction_per_m`) at `point`, and the
    /// normalised height there.
    pub fn density(&self, point: Vec3) -> f64 {
        self.density_with(point, true)
    }

    /// [`CloudLayer::density`] with the erosion left out when `eroded` is false (a
    /// cheaper, slightly denser estimate for the far samples of a march towards the light:
    /// Schneider 2015's "cheap samples").
    pub fn density_with(&self, point: Vec3, eroded: bool) -> f64 {
        let r = point.length();
        let [rb, rt] = self.radii_m;
        if !(rb..=rt).contains(&r) {
            return 0.0;
        }
        let h = (r - rb) / (rt - rb);
        let (Some(weather), Some([base, detail])) = (&self.weather, &self.noise) else {
            return 1.0;
        };
        let (x, y) = self.planar(point / r);
        let (x, y) = (
            x + self.params.wind_offset_m[0],
            y + self.params.wind_offset_m[1],
        );
        let [w, t, precipitation, warp_x, warp_y] = weather.sample(x, y);
        let c = (self.params.coverage + WEATHER_CONTRAST * (w - 0.5)).clamp(0.0, 1.0);
        let profile = self.params.kind.density(h, t);
        // The shape is 0 unless base·profile > 1 − c, and base ≤ 1.
        if profile <= 1.0 - c {
            return 0.0;
        }
        let [_, shape_tile, detail_tile] = self.params.tiles_m;
        let stretch = self.params.kind.horizontal_stretch();
        let z = r - rb;
        let (u, v) = (x / shape_tile + warp_x, y / shape_tile + warp_y);
        let b = base.sample([u, v, z * stretch / shape_tile]);
        let shape = remap(b * profile, 1.0 - c, 1.0, 0.0, 1.0).max(0.0);
        if shape <= 0.0 {
            return 0.0;
        }
        if !eroded {
            return shape * (1.0 + PRECIPITATION_GAIN * precipitation);
        }
        let e = self.params.kind.erosion(h);
        let k = shape_tile / detail_tile;
        let d = detail.sample([u * k, v * k, z * stretch / detail_tile]);
        let eroded = remap(shape, e * d, 1.0, 0.0, 1.0).max(0.0);
        eroded * (1.0 + PRECIPITATION_GAIN * precipitation)
    }

    /// Whether the density at `point` is 0 whatever the noise: outside the shell, or where
    /// the type's profile is at most 1 − c_loc (the shape needs base·profile > 1 − c_loc,
    /// base ≤ 1).
    pub fn surely_empty(&self, point: Vec3) -> bool {
        let r = point.length();
        let [rb, rt] = self.radii_m;
        if !(rb..=rt).contains(&r) {
            return true;
        }
        let Some(weather) = &self.weather else {
            return false;
        };
        let (x, y) = self.planar(point / r);
        let [w, t, ..] = weather.sample(
            x + self.params.wind_offset_m[0],
            y + self.params.wind_offset_m[1],
        );
        let c = (self.params.coverage + WEATHER_CONTRAST * (w - 0.5)).clamp(0.0, 1.0);
        self.params.kind.density((r - rb) / (rt - rb), t) <= 1.0 - c
    }

    /// An upper bound of [`CloudLayer::density`] anywhere in the layer.
    pub fn max_density(&self) -> f64 {
        match &self.weather {
            None => 1.0,
            Some(w) => {
                let p = w.texels.iter().map(|t| t[2] as f64).fold(0.0, f64::max);
                1.0 + PRECIPITATION_GAIN * p
            }
        }
    }
}

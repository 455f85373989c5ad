//! The planet's weather: one equirectangular map of the weather value w, the cloud type t
//! and the precipitation p (the channels of [`super::weather::WeatherMap`]) over the whole
//! sphere, for layers with `weather_wrap = "planet"`, so that the planet seen from orbit
//! carries cloud systems instead of an 80 km tile repeated over it. The map's own fine
//! detail ([`PlanetaryWeather::detail`]) breaks its texels' edges; the layer's tiled map
//! only warps the noise ([`super::layer`]).
//!
//! The procedural map is Earth-like: fBm gradient noise on the sphere, its domain warped
//! twice (Quílez 2002, "domain warping": swirls and fronts rather than blobs), added to the
//! zonal mean cloud amount (the wet equatorial trough, the clear subtropics, the storm
//! tracks at 50–65° with the Southern Ocean's the cloudiest; ISCCP / CALIPSO zonal means,
//! Stubenrauch et al. 2013, BAMS 94, "Assessment of global cloud datasets from satellites",
//! fig. 3, read to about ±0.05), then histogram-equalised over the sphere's area so that w
//! is uniform on [0, 1] as the tiled map's is (a layer's mean coverage stays as set).
//!
//! A user's PNG (red w, green t, blue p, as the tiled map) is read as an equirectangular
//! map: row 0 at 90° N, column 0 at 180° W, as `[surface] map`.
//!
//! Placement: the observer stands at the scene's `[location]` (or 0° N, 0° E), the
//! renderer's x east, y north, z up there ([`crate::scene::planet`]).

use std::f64::consts::{PI, TAU};
use std::path::Path;

use rayon::prelude::*;

use super::profile::CloudKind;
use super::weather::WeatherMap;
use crate::math::{smoothstep, Vec3};
use crate::scene::planet::{bilinear_wrap, noise3, observer_frame};
use crate::Result;

/// Texels of the procedural map in longitude (39 km at the equator) and latitude.
pub const PROCEDURAL_WIDTH: usize = 1024;
/// Texels in latitude.
pub const PROCEDURAL_HEIGHT: usize = 512;
/// Octaves of the procedural field (the finest about 150 km across).
const OCTAVES: u32 = 6;
/// The noise's weight against the zonal mean cloud amount (whose range is about 0.35).
const NOISE_WEIGHT: f64 = 0.45;
/// The fine detail's tiles in the planet's radius (617 and 1 013 km for Earth's; each
/// map's features from a quarter of its tile down to about 10 km).
pub const DETAIL_TILES: [f64; 2] = [0.097, 0.159];
/// The fine detail's gain: the mean of two uniform values has a standard deviation of
/// 0.2, a uniform value's 0.29.
const DETAIL_GAIN: f64 = 1.4;
/// Precipitation where w is above this (the cores of the cloud systems), rising to
/// [`STORM_PRECIPITATION`] at w = 1.
const STORM_W: f64 = 0.85;
/// The precipitation at w = 1: the systems' dark, dense cores.
const STORM_PRECIPITATION: f64 = 0.5;

/// Zonal mean total cloud amount (fraction of the sky) against latitude (degrees, south
/// to north): the shape of the ISCCP / CALIPSO zonal means (module doc).
const ZONAL_CLOUD_AMOUNT: [(f64, f64); 13] = [
    (-90.0, 0.55),
    (-75.0, 0.65),
    (-60.0, 0.88),
    (-45.0, 0.80),
    (-30.0, 0.60),
    (-15.0, 0.58),
    (5.0, 0.72),
    (20.0, 0.52),
    (30.0, 0.55),
    (45.0, 0.70),
    (60.0, 0.78),
    (75.0, 0.70),
    (90.0, 0.62),
];

/// The zonal mean cloud amount at `lat_deg`, linear between the table's rows.
pub fn zonal_cloud_amount(lat_deg: f64) -> f64 {
    let lat = lat_deg.clamp(-90.0, 90.0);
    let i = ZONAL_CLOUD_AMOUNT
        .windows(2)
        .position(|w| lat <= w[1].0)
        .unwrap_or(ZONAL_CLOUD_AMOUNT.len() - 2);
    let ((x0, y0), (x1, y1)) = (ZONAL_CLOUD_AMOUNT[i], ZONAL_CLOUD_AMOUNT[i + 1]);
    y0 + (y1 - y0) * (lat - x0) / (x1 - x0)
}

/// The weather over the whole planet.
#[derive(Clone, Debug)]
pub struct PlanetaryWeather {
    /// Texels in longitude.
    pub width: usize,
    /// Texels in latitude.
    pub height: usize,
    /// [w, t, p] per texel, row-major from 90° N, 180° W.
    pub texels: Vec<[f32; 3]>,
    /// The observer's east, north and up in the planet-fixed frame.
    pub frame: [Vec3; 3],
    /// The fine detail's two maps ([`PlanetaryWeather::detail`]).
    pub detail: [WeatherMap; 2],
}

impl PlanetaryWeather {
    /// The procedural map for a layer of `kind` with `seed`, the observer at (`lat_deg`,
    /// `lon_deg`).
    pub fn procedural(
        kind: CloudKind,
        seed: u32,
        lat_deg: f64,
        lon_deg: f64,
        radius_m: f64,
    ) -> PlanetaryWeather {
        let (width, height) = (PROCEDURAL_WIDTH, PROCEDURAL_HEIGHT);
        let detail = detail_maps(kind, seed, radius_m);
        let seed = seed as u64 ^ 0x706c_616e_6574;
        let (t_mean, t_spread) = kind.default_type();
        // Raw field and type per texel.
        let raw: Vec<(f64, f64)> = (0..width * height)
            .into_par_iter()
            .map(|i| {
                let (lon, lat) = texel_angles(i % width, i / width, width, height);
                let d = direction(lon, lat);
                let v = zonal_cloud_amount(lat.to_degrees()) + NOISE_WEIGHT * warped_fbm(seed, d);
                let t = t_mean + t_spread * 1.5 * noise3(seed ^ 0x7479, 3.0 * d);
                (v, t.clamp(0.0, 1.0))
            })
            .collect();
        // Equalise over the sphere's area: w is the area below a texel's value.
        let area = |i: usize| texel_angles(0, i / width, width, height).1.cos();
        let mut order: Vec<usize> = (0..raw.len()).collect();
        order.sort_by(|&a, &b| raw[a].0.total_cmp(&raw[b].0));
        let total: f64 = (0..raw.len()).map(area).sum();
        let mut texels = vec![[0.0f32; 3]; raw.len()];
        let mut below = 0.0;
        for &i in &order {
            let a = area(i);
            let w = (below + 0.5 * a) / total;
            below += a;
            let p = STORM_PRECIPITATION * smoothstep(STORM_W, 1.0, w);
            texels[i] = [w as f32, raw[i].1 as f32, p as f32];
        }
        PlanetaryWeather {
            width,
            height,
            texels,
            frame: observer_frame(lat_deg, lon_deg),
            detail,
        }
    }

    /// The map from an equirectangular PNG at `path` (channels as the tiled map's,
    /// [`WeatherMap::from_png`]), the observer at (`lat_deg`, `lon_deg`); `field` names the
    /// setting in errors.
    #[allow(clippy::too_many_arguments)]
    pub fn from_png(
        path: &Path,
        kind: CloudKind,
        seed: u32,
        lat_deg: f64,
        lon_deg: f64,
        radius_m: f64,
        field: &str,
    ) -> Result<PlanetaryWeather> {
        let map = WeatherMap::from_png(path, kind, 1.0, field)?;
        let (width, height) = (map.width, map.height);
        // The tiled map's rows run from the south; this one's from the north.
        let texels = (0..height)
            .rev()
            .flat_map(|j| map.texels[j * width..(j + 1) * width].to_vec())
            .map(|t| [t[0], t[1], t[2]])
            .collect();
        Ok(PlanetaryWeather {
            width,
            height,
            texels,
            frame: observer_frame(lat_deg, lon_deg),
            detail: detail_maps(kind, seed, radius_m),
        })
    }

    /// The planet-fixed direction of a renderer-frame unit direction.
    #[inline]
    pub fn fixed(&self, dir: Vec3) -> Vec3 {
        let [e, n, u] = self.frame;
        dir.x * e + dir.y * n + dir.z * u
    }

    /// The map's own fine detail at planar coordinates (x, y) (m), about in [−½, ½]: the
    /// mean of two tiled fBm maps ([`WeatherMap::procedural`]) whose tiles,
    /// [`DETAIL_TILES`] of the planet's radius, are incommensurate, so that the pattern
    /// does not repeat over the planet, finer than the map's texels, so that the systems'
    /// edges seen from orbit are ragged rather than the texels' bilinear polygons.
    #[inline]
    pub fn detail(&self, x: f64, y: f64) -> f64 {
        let [a, b] = &self.detail;
        DETAIL_GAIN * (0.5 * (a.sample(x, y)[0] + b.sample(x, y)[0]) - 0.5)
    }

    /// [w, t, p] above the renderer-frame unit direction `dir`, bilinear.
    #[inline]
    pub fn sample(&self, dir: Vec3) -> [f64; 3] {
        let d = self.fixed(dir);
        let lat = d.z.clamp(-1.0, 1.0).asin();
        let lon = d.y.atan2(d.x);
        let x = (lon / TAU + 0.5) * self.width as f64 - 0.5;
        let y = (0.5 - lat / PI) * self.height as f64 - 0.5;
        bilinear_wrap(&self.texels, self.width, self.height, x, y)
    }
}

/// The fine detail's maps for a planet of `radius_m`.
fn detail_maps(kind: CloudKind, seed: u32, radius_m: f64) -> [WeatherMap; 2] {
    let map = |i: usize| {
        let salt = seed.wrapping_add(0x6465_7461 + i as u32);
        WeatherMap::procedural(kind, salt, DETAIL_TILES[i] * radius_m)
    };
    [map(0), map(1)]
}

/// Longitude and latitude (radians) of texel (i, j)'s centre.
fn texel_angles(i: usize, j: usize, width: usize, height: usize) -> (f64, f64) {
    let lon = ((i as f64 + 0.5) / width as f64 - 0.5) * TAU;
    let lat = (0.5 - (j as f64 + 0.5) / height as f64) * PI;
    (lon, lat)
}

/// The planet-fixed unit direction at (`lon`, `lat`) (radians).
fn direction(lon: f64, lat: f64) -> Vec3 {
    Vec3::new(lat.cos() * lon.cos(), lat.cos() * lon.sin(), lat.sin())
}

/// fBm of [`OCTAVES`] octaves at `d`, about in [−1, 1].
fn fbm(seed: u64, d: Vec3) -> f64 {
    let (mut sum, mut norm) = (0.0, 0.0);
    let (mut f, mut a) = (2.0, 1.0);
    for o in 0..OCTAVES {
        sum += a * noise3(seed.wrapping_add(o as u64), f * d);
        norm += a;
        f *= 2.1;
        a *= 0.55;
    }
    sum / norm
}

/// fBm with its domain warped twice by fBm (q = d + 0.5·f(d), result f(d + 0.5·f(q))).
fn warped_fbm(seed: u64, d: Vec3) -> f64 {
    let warp = |p: Vec3, salt: u64| {
        Vec3::new(
            fbm(seed ^ salt, p),
            fbm(seed ^ (salt + 1), p + Vec3::new(5.2, 1.3, 2.8)),
            fbm(seed ^ (salt + 2), p + Vec3::new(1.7, 9.2, 4.4)),
        )
    };
    let q = d + 0.5 * warp(d, 0x10);
    let r = d + 0.5 * warp(q, 0x20);
    fbm(seed, r)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::lattice::sphere_directions;

    #[test]
    fn procedural_weather_is_uniform_over_the_sphere_and_follows_the_zones() {
        let map = PlanetaryWeather::procedural(CloudKind::Cumulus, 3, 0.0, 0.0, 6.36e6);
        // Equalised by area: over evenly spread directions, the share with w > 1 − c is c.
        let points = sphere_directions(20_000);
        let w: Vec<f64> = points.iter().map(|&d| map.sample(d)[0]).collect();
        for c in [0.2, 0.5, 0.8] {
            let share = w.iter().filter(|&&v| v > 1.0 - c).count() as f64 / w.len() as f64;
            assert!((share - c).abs() < 0.02, "{c}: {share}");
        }
        // The zones: the Southern Ocean's storm track is cloudier than the subtropics.
        let band = |lat0: f64, lat1: f64| {
            let (mut sum, mut n) = (0.0, 0);
            for (&d, &v) in points.iter().zip(&w) {
                let lat = map.fixed(d).z.asin().to_degrees();
                if (lat0..lat1).contains(&lat) {
                    sum += v;
                    n += 1;
                }
            }
            sum / n as f64
        };
        let (storms, subtropics) = (band(-65.0, -55.0), band(15.0, 30.0));
        assert!(storms > subtropics + 0.2, "{storms} vs {subtropics}");
    }

    #[test]
    fn the_observer_stands_at_the_location() {
        // The renderer's up at (lat, lon) is the planet-fixed direction of that place.
        let map = PlanetaryWeather::procedural(CloudKind::Cumulus, 0, 40.0, -100.0, 6.36e6);
        let d = map.fixed(Vec3::Z);
        assert!((d.z.asin().to_degrees() - 40.0).abs() < 1e-9);
        assert!((d.y.atan2(d.x).to_degrees() + 100.0).abs() < 1e-9);
        assert!((zonal_cloud_amount(-60.0) - 0.88).abs() < 1e-12);
        assert!((zonal_cloud_amount(-52.5) - 0.84).abs() < 1e-12);
    }
}

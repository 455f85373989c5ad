//! One cloud layer built from its settings ([`super::config`]) and the density it has at a
//! point: a shell between two altitudes that follows the planet, shaped
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
//!
//! With `weather_wrap = "planet"` the weather value comes from the planet's map
//! ([`super::planetary`]); seen from afar the density is filtered over a pixel's footprint
//! ([`super::lod`]).

use std::sync::Arc;

use super::config::{CloudLayerConfig, LayerParams, WeatherWrap};
use super::lod::{filter_weight, LazyMeanDensity, MeanDensity};
use super::noise::remap;
use super::noise_volume::NoiseVolume;
use super::planetary::PlanetaryWeather;
use super::profile::CloudKind;
use super::weather::{WeatherCell, WeatherMap};
use crate::math::Vec3;
use crate::Result;

/// How far the weather moves the local coverage about the layer's: c_loc = c + k·(w − ½).
pub const WEATHER_CONTRAST: f64 = 0.7;
/// How much the weather's precipitation raises the density (1 + gain·p).
pub const PRECIPITATION_GAIN: f64 = 2.0;

/// Where the camera is and how wide its pixels are: the footprint a pixel covers at a
/// point, for the filtered density ([`super::lod`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ViewFootprint {
    /// The camera's position (m, planet-centred).
    pub eye: Vec3,
    /// A pixel's angular width (rad).
    pub pixel_angle_rad: f64,
}

/// The weather at a point of the layer: what decides whether there is room for cloud (the
/// height, the local coverage and the type), and where to read the rest.
#[derive(Clone, Copy, Debug)]
struct Local {
    /// Normalised height in the layer.
    h: f64,
    /// Local coverage c_loc and type.
    c: f64,
    t: f64,
    /// Planar coordinates with the wind (m).
    x: f64,
    y: f64,
    /// Where the precipitation and the noise's warp are read.
    rest: Rest,
}

/// The weather's precipitation and warp at a point, read only where there is room for
/// cloud ([`Local`]).
#[derive(Clone, Copy, Debug)]
enum Rest {
    /// The uniform layer: none.
    Uniform,
    /// The tiled map's sample there (precipitation and warp).
    Tiled(WeatherCell),
    /// The planet's precipitation, the tiled map's warp.
    Planet(WeatherCell, f64),
}

impl Local {
    /// The type's profile here when it leaves room for cloud (the shape is 0 unless
    /// base·profile > 1 − c, with base and the profile ≤ 1), None where the density is 0
    /// whatever the noise.
    #[inline]
    fn room(&self, kind: CloudKind) -> Option<f64> {
        if self.c <= 0.0 {
            return None;
        }
        let profile = kind.density(self.h, self.t);
        (profile > 1.0 - self.c).then_some(profile)
    }

    /// The precipitation p and the noise's warp (tiles) at the point.
    #[inline]
    fn rest(&self, weather: Option<&WeatherMap>) -> (f64, [f64; 2]) {
        let warp = |w: &WeatherMap, cell: &WeatherCell| [w.channel(cell, 3), w.channel(cell, 4)];
        match (self.rest, weather) {
            (Rest::Tiled(cell), Some(w)) => (w.channel(&cell, 2), warp(w, &cell)),
            (Rest::Planet(cell, p), Some(w)) => (p, warp(w, &cell)),
            _ => (0.0, [0.0; 2]),
        }
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
    /// The planet's weather (`weather_wrap = "planet"`).
    pub planetary: Option<PlanetaryWeather>,
    /// The base shape and erosion textures (None for `uniform`).
    pub noise: Option<[Arc<NoiseVolume>; 2]>,
    /// The camera's footprint and the mean density it filters towards (None: the noise's
    /// density everywhere, as the reference and point queries take it).
    pub filter: Option<(ViewFootprint, Arc<LazyMeanDensity>)>,
}

/// How far the planetary weather moves the local coverage about the layer's (c_loc = c +
/// k·(w − ½)): more than the tiled map's [`WEATHER_CONTRAST`], so that systems part into
/// clear skies and overcast decks as satellite images show.
pub const PLANET_CONTRAST: f64 = 1.5;
/// The planetary map's fine detail's share in its weather value: w = w_planet + k·detail
/// ([`PlanetaryWeather::detail`], tens of kilometres; the layer's tiled map only warps the
/// noise, so that its 80 km repetition never shows from afar).
pub const PLANET_DETAIL: f64 = 0.4;

impl CloudLayer {
    /// Build the layer over a planet of `planet_radius_m` with the shared noise textures,
    /// the observer at (`lat_deg`, `lon_deg`) of a planetary weather map. `prefix` names the
    /// section in errors.
    pub fn new(
        config: &CloudLayerConfig,
        planet_radius_m: f64,
        noise: [Arc<NoiseVolume>; 2],
        location: (f64, f64),
        prefix: &str,
    ) -> Result<CloudLayer> {
        config.validate(prefix)?;
        let params = config.resolved();
        let uniform = params.kind == CloudKind::Uniform;
        let planet = params.weather_wrap == WeatherWrap::Planet;
        let (lat, lon) = location;
        let field = format!("{prefix}.weather");
        let planetary = match (&params.weather, planet) {
            (_, false) => None,
            (Some(path), true) => Some(PlanetaryWeather::from_png(
                path,
                params.kind,
                params.seed,
                lat,
                lon,
                planet_radius_m,
                &field,
            )?),
            (None, true) => Some(PlanetaryWeather::procedural(
                params.kind,
                params.seed,
                lat,
                lon,
                planet_radius_m,
            )),
        };
        let weather = match (&params.weather, uniform) {
            (_, true) => None,
            (Some(path), false) if !planet => Some(WeatherMap::from_png(
                path,
                params.kind,
                params.tiles_m[0],
                &field,
            )?),
            _ => Some(WeatherMap::procedural(
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
            planetary,
            noise: (!uniform).then_some(noise),
            filter: None,
            params,
        })
    }

    /// Filter the density over the footprint of `view`'s pixels ([`super::lod`]), with
    /// `mean` (None: tabulated when a sample first needs it, [`LazyMeanDensity`]) for the
    /// layer's kind.
    pub fn set_view(&mut self, view: ViewFootprint, mean: Option<Arc<MeanDensity>>) {
        let Some([base, detail]) = &self.noise else {
            return;
        };
        let mean = match mean {
            Some(mean) => LazyMeanDensity::ready(mean),
            None => {
                let [_, shape_tile, detail_tile] = self.params.tiles_m;
                let z = (self.radii_m[1] - self.radii_m[0]) * self.params.kind.horizontal_stretch();
                LazyMeanDensity::new(
                    self.params.kind,
                    [base.clone(), detail.clone()],
                    [z / shape_tile, z / detail_tile],
                    self.params.extinction_per_m * (self.radii_m[1] - self.radii_m[0]),
                    1.0 - self.phase_mean_cosine(),
                )
            }
        };
        self.filter = Some((view, Arc::new(mean)));
    }

    /// The mean cosine of the layer's phase function.
    pub fn phase_mean_cosine(&self) -> f64 {
        let [g1, g2, weight] = self.params.phase;
        crate::medium::PhaseFunction::DualLobeHg { g1, g2, weight }.mean_cosine()
    }

    /// The size (m) of the base shape's cells (eight across its tile): the scale the filter
    /// works at.
    pub fn cell_m(&self) -> f64 {
        self.params.tiles_m[1] / 8.0
    }

    /// Planar coordinates (m) of the point above `dir` (a vector from the planet's centre,
    /// of any length: a point itself): the gnomonic projection onto the tangent plane of
    /// the cube face the direction falls on, scaled to the planet's radius (the +z face is the observer's: x
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

    /// The pixel's footprint at `point` (m; 0 without a view).
    #[inline]
    fn footprint(&self, point: Vec3) -> f64 {
        self.filter
            .as_ref()
            .map_or(0.0, |(v, _)| (point - v.eye).length() * v.pixel_angle_rad)
    }

    /// The weather at `point` (None outside the shell; the uniform layer: c = 1).
    #[inline]
    fn local(&self, point: Vec3) -> Option<Local> {
        let r = point.length();
        let [rb, rt] = self.radii_m;
        if !(rb..=rt).contains(&r) {
            return None;
        }
        let h = (r - rb) / (rt - rb);
        // The projection is the direction's: the point itself, unnormalised.
        let (x, y) = self.planar(point);
        let (x, y) = (
            x + self.params.wind_offset_m[0],
            y + self.params.wind_offset_m[1],
        );
        let Some(weather) = &self.weather else {
            return Some(Local {
                h,
                c: 1.0,
                t: 0.0,
                x,
                y,
                rest: Rest::Uniform,
            });
        };
        let cell = weather.cell(x, y);
        let (w, t, rest, contrast) = match &self.planetary {
            None => (
                weather.channel(&cell, 0),
                weather.channel(&cell, 1),
                Rest::Tiled(cell),
                WEATHER_CONTRAST,
            ),
            Some(planet) => {
                let [wp, tp, pp] = planet.sample(point / r);
                let w = (wp + PLANET_DETAIL * planet.detail(x, y)).clamp(0.0, 1.0);
                (w, tp, Rest::Planet(cell, pp), PLANET_CONTRAST)
            }
        };
        Some(Local {
            h,
            c: (self.params.coverage + contrast * (w - 0.5)).clamp(0.0, 1.0),
            t,
            x,
            y,
            rest,
        })
    }

    /// The density (dimensionless, extinction over `extinction_per_m`) at `point`, and the
    /// normalised height there.
    pub fn density(&self, point: Vec3) -> f64 {
        self.density_with(point, true)
    }

    /// [`CloudLayer::density`] with the erosion left out when `eroded` is false (a
    /// cheaper, slightly denser estimate for the far samples of a march towards the light:
    /// Schneider 2015's "cheap samples"). With a view ([`CloudLayer::set_view`]), filtered
    /// over the footprint of a pixel there ([`super::lod`]).
    pub fn density_with(&self, point: Vec3, eroded: bool) -> f64 {
        let Some(local) = self.local(point) else {
            return 0.0;
        };
        let Some([base, detail]) = &self.noise else {
            return 1.0;
        };
        let Some(profile) = local.room(self.params.kind) else {
            return 0.0;
        };
        let (precipitation, warp) = local.rest(self.weather.as_ref());
        let gain = 1.0 + PRECIPITATION_GAIN * precipitation;
        let (weight, mean) = match &self.filter {
            Some((_, mean)) => (filter_weight(self.footprint(point), self.cell_m()), mean),
            None => return gain * self.noise_density(&local, warp, profile, base, detail, eroded),
        };
        if weight <= 0.0 {
            return gain * self.noise_density(&local, warp, profile, base, detail, eroded);
        }
        // The noise's density blended towards the mean scaled by χ (lod::MeanDensity).
        let mean = mean.get().effective(local.h, local.c, local.t);
        gain * if weight >= 1.0 {
            mean
        } else {
            let noise = self.noise_density(&local, warp, profile, base, detail, eroded);
            noise + weight * (mean - noise)
        }
    }

    /// The noise's density (before precipitation's gain) at the weather `local` (its noise
    /// coordinates moved by `warp`, tiles) with the type's `profile` there.
    fn noise_density(
        &self,
        local: &Local,
        warp: [f64; 2],
        profile: f64,
        base: &NoiseVolume,
        detail: &NoiseVolume,
        eroded: bool,
    ) -> f64 {
        let [_, shape_tile, detail_tile] = self.params.tiles_m;
        let stretch = self.params.kind.horizontal_stretch();
        let z = local.h * (self.radii_m[1] - self.radii_m[0]);
        let (u, v) = (
            local.x / shape_tile + warp[0],
            local.y / shape_tile + warp[1],
        );
        let b = base.sample([u, v, z * stretch / shape_tile]);
        let shape = remap(b * profile, 1.0 - local.c, 1.0, 0.0, 1.0).max(0.0);
        if shape <= 0.0 || !eroded {
            return shape;
        }
        let e = self.params.kind.erosion(local.h);
        let k = shape_tile / detail_tile;
        let d = detail.sample([u * k, v * k, z * stretch / detail_tile]);
        remap(shape, e * d, 1.0, 0.0, 1.0).max(0.0)
    }

    /// Whether the density at `point` is 0 whatever the noise: outside the shell, or where
    /// the type's profile is at most 1 − c_loc (the shape needs base·profile > 1 − c_loc,
    /// base ≤ 1).
    pub fn surely_empty(&self, point: Vec3) -> bool {
        match self.local(point) {
            None => true,
            Some(_) if self.weather.is_none() => false,
            Some(l) => l.room(self.params.kind).is_none(),
        }
    }

    /// An upper bound of [`CloudLayer::density`] anywhere in the layer.
    pub fn max_density(&self) -> f64 {
        let p = match (&self.planetary, &self.weather) {
            (Some(planet), _) => planet
                .texels
                .iter()
                .map(|t| t[2] as f64)
                .fold(0.0, f64::max),
            (None, Some(w)) => w.texels.iter().map(|t| t[2] as f64).fold(0.0, f64::max),
            (None, None) => 0.0,
        };
        1.0 + PRECIPITATION_GAIN * p
    }
}

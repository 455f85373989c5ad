//! Spectral Monte Carlo reference renderer: a path tracer through the same resolved
//! [`Model`] as the precomputed tables, used to measure their error and exposed to users
//! (`--method reference`).
//!
//! Physics: spherical planet (any radius up to the plane-parallel limit, R_g = 1e12 m),
//! layered density profiles, every constituent with its own scattering, absorption and
//! phase function, a Lambertian ground with per-wavelength albedo, all scattering orders.
//! Each wavelength is traced independently with its own coefficients (independent random
//! streams, so channel errors are independent). Free paths by delta tracking with a
//! piecewise majorant; the scattering constituent is chosen in proportion to its
//! scattering coefficient at the collision and its phase function is importance-sampled;
//! absorption by weighting with the single-scattering albedo, Russian roulette after
//! [`ReferenceSettings::roulette_after`] events; next-event estimation towards a point
//! drawn on the sun disk (limb darkening as in the model) with a deterministically
//! integrated transmittance (0 behind the planet). See [`tracer`] for the details.
//!
//! Meaning of the results (same as [`crate::sky::Sky::sky_radiance`]): the radiance that
//! reaches the camera along the view ray *after at least one scattering in the air*: the
//! sun disk seen directly is excluded; light reflected by the ground and then scattered
//! in the air is included (as in the tables' multiple scattering). With
//! `include_ground = false` (default) a view ray that hits the ground returns only the light
//! scattered in the air in front of the ground, like `Sky::sky_radiance`; with
//! `include_ground = true` the ground's own reflected radiance (sun + sky, attenuated to the
//! camera) is added, which is what an image of the whole scene needs.
//!
//! Determinism: results depend only on the inputs and the seed (random streams are keyed by
//! seed, pixel index, wavelength index and sample index; sums are reduced in a fixed
//! order), not on the number of threads.
//!
//! Units: radiance W·m⁻²·sr⁻¹·nm⁻¹, irradiance W·m⁻²·nm⁻¹, positions planet-centred in
//! metres, directions unit vectors (normalised here if they are not).

pub mod rng;
pub mod tracer;

use std::f64::consts::PI;

use rayon::prelude::*;
use serde::Serialize;

use crate::atmosphere::Model;
use crate::geometry::{dot, normalize, ray_sphere, Vec3};
use crate::{Error, Result};
use rng::Rng;
use tracer::{Channel, Frame, BUDGET_TALLIES};

/// Samples per block: the unit of parallel work and of the fixed-order reduction.
const BLOCK: usize = 256;

/// Random-stream domains, so different estimators never share streams.
const DOMAIN_RADIANCE: u64 = 0;
const DOMAIN_IRRADIANCE: u64 = 0x1_0000_0000;
const DOMAIN_BUDGET: u64 = 0x2_0000_0000;

/// Settings of the reference path tracer.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ReferenceSettings {
    /// Paths per wavelength (per pixel). ≥ 2 (the standard error needs two).
    pub samples: usize,
    /// Seed of the random streams.
    pub seed: u64,
    /// Largest number of scattering and ground-reflection events on a path (1 = single
    /// scattering only). Paths longer than this are cut, which biases the result low; with
    /// Russian roulette only conservative, very thick media get near the default 100.
    pub max_bounces: usize,
    /// Events before Russian roulette starts (survival probability = the path weight).
    pub roulette_after: usize,
    /// Whether the ground seen directly by a camera ray adds its reflected radiance
    /// (false: like `Sky::sky_radiance`; true: whole-scene images).
    pub include_ground: bool,
    /// Gauss–Legendre segments (4 nodes each) per smooth piece of a sun ray (between the
    /// closest approach and the altitudes where a profile has a kink; half as many on the
    /// pieces away from the lowest point) for the next-event transmittance.
    pub transmittance_segments: usize,
}

impl Default for ReferenceSettings {
    fn default() -> Self {
        ReferenceSettings {
            samples: 4096,
            seed: 0,
            max_bounces: 100,
            roulette_after: 5,
            include_ground: false,
            transmittance_segments: 6,
        }
    }
}

impl ReferenceSettings {
    /// Defaults with `samples` paths per wavelength.
    pub fn with_samples(samples: usize) -> Self {
        ReferenceSettings {
            samples,
            ..Default::default()
        }
    }

    /// Check the numbers (the error names the field).
    pub fn validate(&self) -> Result<()> {
        if self.samples < 2 {
            return Err(Error::invalid("samples", self.samples, "an integer ≥ 2"));
        }
        if self.max_bounces < 1 {
            return Err(Error::invalid(
                "max_bounces",
                self.max_bounces,
                "an integer ≥ 1",
            ));
        }
        if self.transmittance_segments < 1 {
            return Err(Error::invalid(
                "transmittance_segments",
                self.transmittance_segments,
                "an integer ≥ 1",
            ));
        }
        Ok(())
    }
}

/// A Monte Carlo estimate of a spectral radiance.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RadianceEstimate {
    /// Mean radiance per wavelength (W·m⁻²·sr⁻¹·nm⁻¹).
    pub radiance: Vec<f64>,
    /// Standard error of each mean (same unit).
    pub stderr: Vec<f64>,
    /// Paths per wavelength.
    pub samples: usize,
}

/// A Monte Carlo estimate of a spectral irradiance (diffuse: the direct sun beam excluded).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct IrradianceEstimate {
    /// Mean irradiance per wavelength (W·m⁻²·nm⁻¹).
    pub irradiance: Vec<f64>,
    /// Standard error of each mean.
    pub stderr: Vec<f64>,
    /// Paths per wavelength.
    pub samples: usize,
}

/// A value per wavelength with its standard error.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Tally {
    /// Mean per wavelength.
    pub value: Vec<f64>,
    /// Standard error per wavelength.
    pub stderr: Vec<f64>,
}

/// Where the power of a collimated beam entering the top of the atmosphere goes, as
/// fractions of that power, per wavelength (photons traced from the sun side).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FluxBudget {
    /// Leaves through the top of the atmosphere.
    pub reflected: Tally,
    /// Absorbed by the ground.
    pub ground_absorbed: Tally,
    /// Absorbed in the air.
    pub medium_absorbed: Tally,
    /// Arrives at the ground without any scattering or reflection (direct beam).
    pub ground_direct: Tally,
    /// Arrives at the ground after at least one scattering or reflection.
    pub ground_diffuse: Tally,
    /// Carried by paths cut at `max_bounces` (bias).
    pub truncated: Tally,
    /// Photons per wavelength.
    pub samples: usize,
}

impl RadianceEstimate {
    /// Luminance (cd/m²) and its standard error (channels are independent).
    pub fn luminance(&self, wavelengths_nm: &[f64]) -> (f64, f64) {
        linear_functional(wavelengths_nm, &self.radiance, &self.stderr)
    }

    /// Largest relative standard error over the wavelengths (0 where the radiance is 0).
    pub fn max_relative_stderr(&self) -> f64 {
        self.radiance
            .iter()
            .zip(&self.stderr)
            .map(|(v, e)| if *v > 0.0 { e / v } else { 0.0 })
            .fold(0.0, f64::max)
    }
}

/// Y of a spectrum and its standard error, from the CIE weights of each channel (the
/// conversion is linear).
fn linear_functional(wavelengths_nm: &[f64], values: &[f64], stderr: &[f64]) -> (f64, f64) {
    let y = crate::spectrum::luminance_from_spectrum(wavelengths_nm, values);
    let mut var = 0.0;
    let mut unit = vec![0.0; values.len()];
    for k in 0..values.len() {
        unit[k] = 1.0;
        let wk = crate::spectrum::luminance_from_spectrum(wavelengths_nm, &unit);
        unit[k] = 0.0;
        var += (wk * stderr[k]).powi(2);
    }
    (y, var.sqrt())
}

/// Running mean and variance (Welford; merged with Chan et al.'s formula).
#[derive(Clone, Copy, Debug, Default)]
struct Stats {
    n: f64,
    mean: f64,
    m2: f64,
}

impl Stats {
    #[inline]
    fn push(&mut self, x: f64) {
        self.n += 1.0;
        let delta = x - self.mean;
        self.mean += delta / self.n;
        self.m2 += delta * (x - self.mean);
    }

    fn merge(self, o: Stats) -> Stats {
        if self.n == 0.0 {
            return o;
        }
        if o.n == 0.0 {
            return self;
        }
        let n = self.n + o.n;
        let delta = o.mean - self.mean;
        Stats {
            n,
            mean: self.mean + delta * o.n / n,
            m2: self.m2 + o.m2 + delta * delta * self.n * o.n / n,
        }
    }

    fn stderr(&self) -> f64 {
        if self.n < 2.0 {
            f64::INFINITY
        } else {
            (self.m2 / (self.n - 1.0) / self.n).max(0.0).sqrt()
        }
    }
}

/// Runs `f` for `settings.samples` samples per wavelength; returns per-wavelength stats of
/// each of the M tallies. Blocks of samples are run in parallel when `parallel`, and always
/// reduced in the same order.
fn estimate<const M: usize, F>(
    model: &Model,
    settings: &ReferenceSettings,
    key: u64,
    parallel: bool,
    f: F,
) -> Vec<[Stats; M]>
where
    F: Fn(&Channel, &mut Rng, &mut tracer::Scratch) -> [f64; M] + Sync,
{
    let n_ch = model.channels();
    let samples = settings.samples;
    let blocks = samples.div_ceil(BLOCK).max(1);
    let channels: Vec<Channel> = (0..n_ch)
        .map(|k| Channel::new(model, k, settings))
        .collect();
    let run = |job: usize| -> [Stats; M] {
        let (k, blk) = (job / blocks, job % blocks);
        let ch = &channels[k];
        let mut scratch = ch.scratch();
        let mut stats = [Stats::default(); M];
        for i in blk * BLOCK..((blk + 1) * BLOCK).min(samples) {
            let mut rng = Rng::for_key(settings.seed, key, k as u64, i as u64);
            let v = f(ch, &mut rng, &mut scratch);
            for m in 0..M {
                stats[m].push(v[m]);
            }
        }
        stats
    };
    let per_block: Vec<[Stats; M]> = if parallel {
        (0..n_ch * blocks).into_par_iter().map(run).collect()
    } else {
        (0..n_ch * blocks).map(run).collect()
    };
    (0..n_ch)
        .map(|k| {
            let mut acc = [Stats::default(); M];
            for blk in 0..blocks {
                for m in 0..M {
                    acc[m] = acc[m].merge(per_block[k * blocks + blk][m]);
                }
            }
            acc
        })
        .collect()
}

/// Where a ray starts inside the atmosphere: the camera itself, or where the ray enters
/// the atmosphere from space; None if it misses.
fn ray_start(model: &Model, camera: Vec3, view: Vec3) -> Option<Vec3> {
    let top = model.top_radius_m;
    if dot(camera, camera) <= top * top {
        return Some(camera);
    }
    let (near, far) = ray_sphere(camera, view, top)?;
    if far <= 0.0 {
        return None;
    }
    let t = near.max(0.0);
    Some([
        camera[0] + t * view[0],
        camera[1] + t * view[1],
        camera[2] + t * view[2],
    ])
}

fn radiance_pixel(
    model: &Model,
    camera: Vec3,
    view: Vec3,
    sun: Vec3,
    settings: &ReferenceSettings,
    key: u64,
    parallel: bool,
) -> RadianceEstimate {
    let n = model.channels();
    let view = normalize(view);
    let sun = normalize(sun);
    let Some(start) = ray_start(model, camera, view) else {
        return RadianceEstimate {
            radiance: vec![0.0; n],
            stderr: vec![0.0; n],
            samples: settings.samples,
        };
    };
    let frame = Frame::below(start, model.bottom_radius_m);
    let o = frame.offset(start);
    let primaries: Vec<tracer::Primary> = (0..n)
        .map(|k| {
            Channel::new(model, k, settings).primary(&frame, o, view, tracer::PRIMARY_INTERVALS)
        })
        .collect();
    let stats = estimate::<1, _>(
        model,
        settings,
        DOMAIN_RADIANCE ^ key,
        parallel,
        |ch, rng, scratch| {
            [ch.radiance_sample(
                &frame,
                &primaries[ch.index()],
                sun,
                settings.include_ground,
                rng,
                scratch,
            )]
        },
    );
    RadianceEstimate {
        radiance: stats.iter().map(|s| s[0].mean).collect(),
        stderr: stats.iter().map(|s| s[0].stderr()).collect(),
        samples: settings.samples,
    }
}

/// Radiance seen from `camera` along `view` with the sun in direction `sun` (see the module
/// documentation for what is included). Samples run in parallel.
pub fn sky_radiance(
    model: &Model,
    camera: Vec3,
    view: Vec3,
    sun: Vec3,
    settings: &ReferenceSettings,
) -> RadianceEstimate {
    radiance_pixel(model, camera, view, sun, settings, 0, true)
}

/// [`sky_radiance`] with the random streams keyed by `key` (estimates with different keys
/// are independent; key 0 is [`sky_radiance`]). Samples run in parallel.
pub fn sky_radiance_keyed(
    model: &Model,
    camera: Vec3,
    view: Vec3,
    sun: Vec3,
    settings: &ReferenceSettings,
    key: u64,
) -> RadianceEstimate {
    radiance_pixel(model, camera, view, sun, settings, key, true)
}

/// [`sky_radiance`] for many (camera, view) rays, in parallel over pixels; pixel `i` uses
/// the random streams of index `i` (so the first pixel equals [`sky_radiance`]).
pub fn render_pixels(
    model: &Model,
    rays: &[(Vec3, Vec3)],
    sun: Vec3,
    settings: &ReferenceSettings,
) -> Vec<RadianceEstimate> {
    render_pixels_with_progress(model, rays, sun, settings, &|| {})
}

/// [`render_pixels`], calling `progress` once per finished pixel (from any thread).
pub fn render_pixels_with_progress(
    model: &Model,
    rays: &[(Vec3, Vec3)],
    sun: Vec3,
    settings: &ReferenceSettings,
    progress: &(dyn Fn() + Sync),
) -> Vec<RadianceEstimate> {
    render_pixels_from(model, rays, 0, sun, settings, progress)
}

/// [`render_pixels_with_progress`] for a batch of pixels that starts at pixel index
/// `first` (pixel `first + i` uses the streams of that index), so an image rendered in
/// batches (e.g. to check for cancellation between them) equals one rendered at once.
pub fn render_pixels_from(
    model: &Model,
    rays: &[(Vec3, Vec3)],
    first: u64,
    sun: Vec3,
    settings: &ReferenceSettings,
    progress: &(dyn Fn() + Sync),
) -> Vec<RadianceEstimate> {
    rays.par_iter()
        .enumerate()
        .map(|(i, &(camera, view))| {
            let e = radiance_pixel(model, camera, view, sun, settings, first + i as u64, false);
            progress();
            e
        })
        .collect()
}

/// Diffuse irradiance (W·m⁻²·nm⁻¹) on a small surface at `point` facing unit `normal`:
/// ∫ L(ω) (ω·n) dω over the hemisphere around `normal` of the radiance [`sky_radiance`]
/// would return (cosine-weighted directions, one path each), so the direct sun beam is
/// excluded and the ground seen in that hemisphere counts only with `include_ground`.
/// The direct beam on a horizontal surface is `E·μ_s·T`.
pub fn irradiance(
    model: &Model,
    point: Vec3,
    normal: Vec3,
    sun: Vec3,
    settings: &ReferenceSettings,
) -> IrradianceEstimate {
    let normal = normalize(normal);
    let sun = normalize(sun);
    let stats =
        estimate::<1, _>(
            model,
            settings,
            DOMAIN_IRRADIANCE,
            true,
            |ch, rng, scratch| {
                let dir = tracer::cosine_direction(normal, rng);
                let Some(start) = ray_start(model, point, dir) else {
                    return [0.0];
                };
                let frame = Frame::below(start, model.bottom_radius_m);
                let primary = ch.primary(&frame, frame.offset(start), dir, 16);
                [PI * ch.radiance_sample(
                    &frame,
                    &primary,
                    sun,
                    settings.include_ground,
                    rng,
                    scratch,
                )]
            },
        );
    IrradianceEstimate {
        irradiance: stats.iter().map(|s| s[0].mean).collect(),
        stderr: stats.iter().map(|s| s[0].stderr()).collect(),
        samples: settings.samples,
    }
}

/// Photon budget of a collimated beam from the sun (`sun`, unit, towards the sun) entering
/// the atmosphere at `entry` (a point on or above the top of the atmosphere, on the sunlit
/// side): each photon starts where the ray from `entry` along −sun enters the atmosphere
/// and is followed (analog albedo weighting, Russian roulette) until it leaves through the
/// top or is absorbed. With no absorption and a black ground,
/// `reflected + ground_absorbed = 1` photon by photon; in general the five sinks
/// (reflected, ground_absorbed, medium_absorbed, truncated, roulette) sum to 1 in
/// expectation. In a plane-parallel slab `reflected` is the plane albedo and
/// `ground_direct + ground_diffuse` the total transmission.
pub fn flux_budget(
    model: &Model,
    entry: Vec3,
    sun: Vec3,
    settings: &ReferenceSettings,
) -> FluxBudget {
    let n = model.channels();
    let sun = normalize(sun);
    let d = [-sun[0], -sun[1], -sun[2]];
    let start = ray_start(model, entry, d);
    let stats: Vec<[Stats; BUDGET_TALLIES]> = match start {
        Some(start) => {
            let frame = Frame::below(start, model.bottom_radius_m);
            let o = frame.offset(start);
            estimate::<BUDGET_TALLIES, _>(
                model,
                settings,
                DOMAIN_BUDGET,
                true,
                |ch, rng, scratch| ch.budget_sample(&frame, o, d, rng, scratch),
            )
        }
        None => vec![[Stats::default(); BUDGET_TALLIES]; n],
    };
    let tally = |m: usize| Tally {
        value: stats.iter().map(|s| s[m].mean).collect(),
        stderr: stats
            .iter()
            .map(|s| if s[m].n >= 2.0 { s[m].stderr() } else { 0.0 })
            .collect(),
    };
    FluxBudget {
        reflected: tally(tracer::T_REFLECTED),
        ground_absorbed: tally(tracer::T_GROUND_ABSORBED),
        medium_absorbed: tally(tracer::T_MEDIUM_ABSORBED),
        ground_direct: tally(tracer::T_GROUND_DIRECT),
        ground_diffuse: tally(tracer::T_GROUND_DIFFUSE),
        truncated: tally(tracer::T_TRUNCATED),
        samples: settings.samples,
    }
}

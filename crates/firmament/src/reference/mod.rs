//! Spectral Monte Carlo reference renderer: a path tracer through the same resolved
//! [`Model`] as the precomputed tables, used to measure their error and exposed to users
//! (`--method reference`).
//!
//! Physics: spherical planet (any radius up to the plane-parallel limit, R_g = 1e12 m),
//! layered density profiles, every constituent with its own scattering, absorption and
//! phase function, a Lambertian ground with per-wavelength albedo, all scattering orders;
//! the scene's volumes and its surfaces (terrain, balls: Lambertian, each with its own
//! albedo, casting shadows) besides the ground sphere where given.
//! Each wavelength is traced independently with its own coefficients (independent random
//! streams, so channel errors are independent). Free paths by delta tracking with a
//! piecewise majorant; the scattering constituent is chosen in proportion to its
//! scattering coefficient at the collision and its phase function is importance-sampled;
//! absorption by weighting with the single-scattering albedo, Russian roulette after
//! [`ReferenceSettings::roulette_after`] events; next-event estimation towards a point
//! drawn on the sun disk (limb darkening as in the model) with a deterministically
//! integrated transmittance (0 behind the planet); by default (`lit_sampling`) that NEE is
//! made along each flight, at a point drawn ∝ its sunlit single scattering, rather than at
//! the flight's collision, which keeps twilight as cheap as daylight. See [`tracer`] for
//! the details.
//!
//! Meaning of the results (same as [`crate::sky::SkyView::sky_radiance`]): the radiance that
//! reaches the camera along the view ray *after at least one scattering in the air*: the
//! sun disk seen directly is excluded; light reflected by the ground and then scattered
//! in the air is included (as in the tables' multiple scattering). With
//! `include_ground = false` (default) a view ray that hits the ground returns only the light
//! scattered in the air in front of the ground, like `SkyView::sky_radiance`; with
//! `include_ground = true` the ground's own reflected radiance (sun + sky, attenuated to the
//! camera) is added, which is what an image of the whole scene needs.
//!
//! Determinism: results depend only on the inputs and the seed (random streams are keyed by
//! seed, pixel index, wavelength index and sample index; sums are reduced in a fixed
//! order), not on the number of threads.
//!
//! Units: radiance W·m⁻²·sr⁻¹·nm⁻¹, irradiance W·m⁻²·nm⁻¹, positions planet-centred in
//! metres, directions unit vectors (normalised here if they are not).

mod render;
mod results;
pub mod rng;
mod sampler;
mod settings;
pub mod tracer;

use std::f64::consts::PI;
use std::sync::OnceLock;

use rayon::prelude::*;

use crate::atmosphere::Model;
use crate::math::sphere::ray_sphere;
use crate::math::Vec3;
use crate::scene::{Surface, Volume};
pub use render::{render_frame, Progress};
pub use results::{FluxBudget, IrradianceEstimate, RadianceEstimate, Tally};
use sampler::{estimate, Stats};
pub use settings::ReferenceSettings;
use tracer::{Channel, Frame, BUDGET_TALLIES};

/// Random-stream domains, so different estimators never share streams.
const DOMAIN_RADIANCE: u64 = 0;
const DOMAIN_IRRADIANCE: u64 = 0x1_0000_0000;
const DOMAIN_BUDGET: u64 = 0x2_0000_0000;

/// The means and standard errors per wavelength of a one-tally estimate.
fn means(stats: &[[Stats; 1]]) -> (Vec<f64>, Vec<f64>) {
    (
        stats.iter().map(|s| s[0].mean).collect(),
        stats.iter().map(|s| s[0].stderr()).collect(),
    )
}

/// Where a ray starts inside the atmosphere: the camera itself, or where the ray enters
/// the atmosphere from space; None if it misses.
fn ray_start(model: &Model, camera: Vec3, view: Vec3) -> Option<Vec3> {
    let top = model.top_radius_m;
    if camera.dot(camera) <= top * top {
        return Some(camera);
    }
    let (near, far) = ray_sphere(camera, view, top)?;
    if far <= 0.0 {
        return None;
    }
    Some(camera + near.max(0.0) * view)
}

#[allow(clippy::too_many_arguments)]
fn radiance_pixel(
    model: &Model,
    volumes: &[Box<dyn Volume + '_>],
    surfaces: &[Box<dyn Surface + '_>],
    camera: Vec3,
    view: Vec3,
    sun: Vec3,
    settings: &ReferenceSettings,
    key: u64,
    parallel: bool,
) -> RadianceEstimate {
    let n = model.channels();
    let view = view.normalize_or_zero();
    let sun = sun.normalize_or_zero();
    let Some(start) = ray_start(model, camera, view) else {
        return RadianceEstimate {
            radiance: vec![0.0; n],
            stderr: vec![0.0; n],
            samples: settings.samples,
        };
    };
    let frame = Frame::below(start, model.bottom_radius_m);
    let o = frame.offset(start);
    // Built on first use by the sampler's own channel (with its sun table), once per
    // wavelength.
    let primaries: Vec<OnceLock<tracer::Primary>> = (0..n).map(|_| OnceLock::new()).collect();
    let primary = |ch: &Channel| -> &tracer::Primary {
        primaries[ch.index()].get_or_init(|| {
            let mut p = ch.primary(&frame, o, view, tracer::PRIMARY_INTERVALS);
            ch.primary_line(&frame, &mut p, sun);
            p
        })
    };
    let stats = estimate::<1, _>(
        model,
        volumes,
        surfaces,
        settings,
        DOMAIN_RADIANCE ^ key,
        parallel,
        |ch, rng, scratch| {
            [ch.radiance_sample(
                &frame,
                primary(ch),
                sun,
                settings.include_ground,
                rng,
                scratch,
            )]
        },
    );
    let (radiance, stderr) = means(&stats);
    RadianceEstimate {
        radiance,
        stderr,
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
    radiance_pixel(model, &[], &[], camera, view, sun, settings, 0, true)
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
    radiance_pixel(model, &[], &[], camera, view, sun, settings, key, true)
}

/// [`sky_radiance_keyed`] through the scene's `volumes` too (clouds and other media besides
/// the atmosphere's constituents): their extinction in delta tracking and towards the sun,
/// their scattering and phase functions at collisions; and with its `surfaces` besides the
/// planet's ground sphere (terrain, balls; the ground sphere itself is the model's and must
/// not be among them, though an equal sphere changes nothing): a path that meets one inside
/// the atmosphere is reflected there (Lambertian, the surface's albedo, NEE with the hit's
/// normal), a shadow ray that meets one carries no sunlight, and the surface seen directly
/// counts like the ground (`include_ground`).
#[allow(clippy::too_many_arguments)]
pub fn scene_radiance(
    model: &Model,
    volumes: &[Box<dyn Volume + '_>],
    surfaces: &[Box<dyn Surface + '_>],
    camera: Vec3,
    view: Vec3,
    sun: Vec3,
    settings: &ReferenceSettings,
    key: u64,
) -> RadianceEstimate {
    radiance_pixel(
        model, volumes, surfaces, camera, view, sun, settings, key, true,
    )
}

/// [`scene_radiance`] for many (camera, view) rays, in parallel over pixels; pixel
/// `first + i` uses the random streams of that index (so pixel 0 equals [`sky_radiance`]
/// without volumes or surfaces, and an image rendered in batches equals one rendered at
/// once).
/// `progress` is called once per finished pixel (from any thread).
#[allow(clippy::too_many_arguments)]
pub fn render_pixels(
    model: &Model,
    volumes: &[Box<dyn Volume + '_>],
    surfaces: &[Box<dyn Surface + '_>],
    rays: &[(Vec3, Vec3)],
    first: u64,
    sun: Vec3,
    settings: &ReferenceSettings,
    progress: &(dyn Fn() + Sync),
) -> Vec<RadianceEstimate> {
    rays.par_iter()
        .enumerate()
        .map(|(i, &(camera, view))| {
            let key = first + i as u64;
            let e = radiance_pixel(
                model, volumes, surfaces, camera, view, sun, settings, key, false,
            );
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
    let normal = normal.normalize_or_zero();
    let sun = sun.normalize_or_zero();
    let stats =
        estimate::<1, _>(
            model,
            &[],
            &[],
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
    let (irradiance, stderr) = means(&stats);
    IrradianceEstimate {
        irradiance,
        stderr,
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
    let sun = sun.normalize_or_zero();
    let d = -sun;
    let start = ray_start(model, entry, d);
    let stats: Vec<[Stats; BUDGET_TALLIES]> = match start {
        Some(start) => {
            let frame = Frame::below(start, model.bottom_radius_m);
            let o = frame.offset(start);
            estimate::<BUDGET_TALLIES, _>(
                model,
                &[],
                &[],
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

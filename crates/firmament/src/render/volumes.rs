//! The scene's volumes in front of what a ray sees, ray-marched with the energy-conserving
//! step of Hillaire 2016 (§5.6.3: the in-scattered source S integrated analytically over a
//! step of constant extinction, ∫₀^d S·e^{−σ_t s} ds = (S − S·e^{−σ_t d})/σ_t).
//!
//! Each sample is lit by every light through the air (the sky method's transmittance to the
//! light) and through the volumes (their optical depth towards the light, or the cheaper
//! march a volume offers: [`Volume::light_optical_depth`]), by octaves of multiple
//! scattering (Wrenninge 2015; Hillaire 2016 §5.6: octave n scatters aⁿσ_s with bⁿ times
//! the optical depth to the light and cⁿ times the phase asymmetry; one octave for a
//! volume that does not ask for more), and by the sky from above and the ground from
//! below, taken as isotropic (an ambient term, as the engines' clouds do): with hemispheric
//! irradiances E↓ (the sky's, from the view) and E↑ (the ground's reflection of its own
//! irradiance below the sample), the in-scattered radiance is σ_s·(w↓E↓ + w↑E↑)/(2π) (a
//! uniform hemisphere of irradiance E has radiance E/π, fluence 2E), each dimmed by the
//! volume's optical depth τ above or below the sample as a conservative slab's two-stream
//! diffuse transmission, w = 1/(1 + (1 − g)τ) (hemispheric-mean two-stream closure,
//! Meador & Weaver 1980; g the phase function's mean cosine): the height gradient of the
//! clouds' ambient light, bright tops and darker bases.
//!
//! Steps: by optical depth (0.1 of the majorant per step, 32 to 1024 steps), or, for volumes
//! that name a feature size (clouds), at that size growing with distance (but crossing the
//! thinnest shell in at least [`VERTICAL_STEPS`] steps), skipping empty
//! stretches in leaps of six steps, and stopping once the volumes are opaque. The steps
//! are jittered per ray (a hash of its direction).
//!
//! Composition: the air in front of the volumes' transmittance-weighted mean depth d̄ is left
//! unattenuated, the volumes' light is seen through the air to d̄ (the aerial perspective
//! of the clouds, Hillaire 2016 §5.7), and everything behind is attenuated by their
//! transmittance: L = S_air(0 → d̄) + T_air(d̄)·L_vol + T_vol·(L_behind − S_air(0 → d̄)).

use std::f64::consts::PI;

use super::cloud_shadow::CloudShadow;
use super::shadowed_air::{dim_multiple, Dimmed};
use crate::math::hash::{lowbias32, unit};
use crate::math::Vec3;
use crate::scene::{DiffuseLight, Octaves, Ray, Scene};
use crate::sky::{Shadow, SkyView};
use crate::spectrum::MAX_CHANNELS;

/// Optical depth per march step at most (then at least [`MIN_STEPS`], at most
/// [`MAX_STEPS`] steps), for volumes without a feature size.
const STEP_OPTICAL_DEPTH: f64 = 0.1;
const MIN_STEPS: usize = 32;
const MAX_STEPS: usize = 1024;
/// Adaptive steps grow with the distance t as max(feature, STEP_DISTANCE_FRACTION·t): 250 m
/// at 50 km, a quarter of a cumulus there.
pub const STEP_DISTANCE_FRACTION: f64 = 0.005;
/// The fewest steps a far ray takes across the thinnest shell, however far it is (seen
/// from orbit, a step of 0.5 % of the distance would cross a cloud layer in one).
pub const VERTICAL_STEPS: f64 = 32.0;
/// Steps in a volume's feature size (its finest texel): a step per texel at the closest,
/// jittered (1.5 texels shows as grain in thin cloud).
pub const FEATURE_STEPS: f64 = 1.0;
/// Empty samples in a row before the march leaps ahead.
pub const EMPTY_BEFORE_LEAP: usize = 1;
/// Steps in one leap over empty space.
pub const LEAP_STEPS: f64 = 6.0;
/// The march stops once the volumes' transmittance is below this in every channel and
/// octave.
pub const OPAQUE_TRANSMITTANCE: f64 = 1e-4;
/// The most octaves of multiple scattering.
pub const MAX_OCTAVES: usize = 8;

/// Per-channel scratch of one march.
struct Buffers {
    sigma_t: [f64; MAX_CHANNELS],
    e_v: [f64; MAX_CHANNELS],
    /// The source of each octave.
    source: [[f64; MAX_CHANNELS]; MAX_OCTAVES],
    t_light: [f64; MAX_CHANNELS],
    tau_light: [f64; MAX_CHANNELS],
    /// [E↓ of the sky at the sample, the direct and the sky irradiance of the clear
    /// ground below it].
    ambient: [[f64; MAX_CHANNELS]; 3],
    /// The air's light at a sample (transmittance to the light and `ambient`), per light
    /// (up to [`CACHED_LIGHTS`]), kept for the samples within [`AIR_LIGHT_REUSE_M`] of it.
    air: [Option<(Vec3, AirLight)>; CACHED_LIGHTS],
}

/// The air's light at a point for one light.
#[derive(Clone, Copy)]
struct AirLight {
    t_light: [f64; MAX_CHANNELS],
    ambient: [[f64; MAX_CHANNELS]; 3],
}

/// Lights whose air light a march keeps.
pub const CACHED_LIGHTS: usize = 4;
/// How far (m) a sample may be from the one whose air light (the sky method's
/// transmittance to the light and irradiances, which vary over kilometres) it reuses.
pub const AIR_LIGHT_REUSE_M: f64 = 250.0;

/// A [`Shadow`] that owns its intervals, with the stretches under the clouds whose multiple
/// scattering is dimmed ([`super::shadowed_air`]).
pub(super) struct OwnedShadow {
    /// [`Shadow::Lit`]'s intervals; None: all lit.
    lit: Option<Vec<(f64, f64)>>,
    dimmed: Dimmed,
}

impl OwnedShadow {
    pub(super) fn new(shadow: Shadow, dimmed: &Dimmed) -> OwnedShadow {
        OwnedShadow {
            lit: match shadow {
                Shadow::None | Shadow::Length(_) => None,
                Shadow::Lit(l) => Some(l.to_vec()),
            },
            dimmed: dimmed.clone(),
        }
    }

    fn as_shadow(&self) -> Shadow<'_> {
        match &self.lit {
            None => Shadow::None,
            Some(l) => Shadow::Lit(l),
        }
    }
}

/// Composite the volumes crossed by `ray` before `end` over `out` (the radiance behind);
/// `shadows` holds each light's shadow along the ray (the air in front of the volumes is
/// lit only where the light reaches it; the sky method clips the intervals to the point).
pub(super) fn composite(
    scene: &Scene,
    views: &[std::sync::Arc<dyn SkyView + '_>],
    ray: &Ray,
    end: f64,
    shadows: &[OwnedShadow],
    out: &mut [f64],
) {
    let n = out.len();
    let Some((a, b)) = scene
        .volumes
        .iter()
        .filter_map(|v| v.bounds(ray))
        .map(|(a, b)| (a, b.min(end)))
        .filter(|(a, b)| b > a)
        .reduce(|x, y| (x.0.min(y.0), x.1.max(y.1)))
    else {
        return;
    };
    let feature = scene
        .volumes
        .iter()
        .filter_map(|v| v.feature_size_m())
        .reduce(f64::min);
    let uniform_dt = match feature {
        Some(_) => 0.0,
        None => {
            let majorant = (0..n)
                .map(|k| {
                    scene
                        .volumes
                        .iter()
                        .map(|v| v.majorant(ray, a, b, k))
                        .sum::<f64>()
                })
                .fold(0.0, f64::max);
            let steps = ((majorant * (b - a) / STEP_OPTICAL_DEPTH).ceil() as usize)
                .clamp(MIN_STEPS, MAX_STEPS);
            (b - a) / steps as f64
        }
    };
    // The thinnest shell: far steps cross it in at least VERTICAL_STEPS.
    let thinnest = scene
        .volumes
        .iter()
        .filter_map(|v| v.radii_m())
        .map(|[lo, hi]| hi - lo)
        .reduce(f64::min);
    let step_at = |t: f64| match feature {
        Some(f) => {
            let dt = (FEATURE_STEPS * f).max(STEP_DISTANCE_FRACTION * t);
            match thinnest {
                Some(h) => {
                    let mu = ray.dir.dot((ray.origin + t * ray.dir).normalize_or_zero());
                    dt.min((h / (VERTICAL_STEPS * mu.abs().max(1e-3))).max(f))
                }
                None => dt,
            }
        }
        None => uniform_dt,
    };
    let jitter = ray_jitter(ray);

    let mut buf = Buffers {
        sigma_t: [0.0; MAX_CHANNELS],
        e_v: [0.0; MAX_CHANNELS],
        source: [[0.0; MAX_CHANNELS]; MAX_OCTAVES],
        t_light: [0.0; MAX_CHANNELS],
        tau_light: [0.0; MAX_CHANNELS],
        ambient: [[0.0; MAX_CHANNELS]; 3],
        air: [None; CACHED_LIGHTS],
    };
    // Each volume's scattering coefficient at the current sample.
    let mut scattering = vec![[0.0f64; MAX_CHANNELS]; scene.volumes.len()];
    // The octaves of the march: the most any volume asks for, with its extinction gain.
    let octaves = scene
        .volumes
        .iter()
        .map(|v| v.octaves())
        .max_by_key(|o| o.count)
        .unwrap_or(Octaves::SINGLE);
    let count = (octaves.count as usize).min(MAX_OCTAVES);
    // Octave m's transmittance along the view, through b^m times the extinction.
    let mut t_vol = [[1.0f64; MAX_CHANNELS]; MAX_OCTAVES];
    let mut l_vol = [0.0f64; MAX_CHANNELS];
    // Σ opacity·t and Σ opacity (channel means) for the mean depth.
    let (mut depth_sum, mut weight_sum) = (0.0, 0.0);
    let (mut t, mut empty_run) = (a, 0usize);
    while t < b {
        let dt = step_at(t).min(b - t);
        let x = ray.origin + (t + jitter * dt) * ray.dir;
        let sigma_t = &mut buf.sigma_t[..n];
        sigma_t.iter_mut().for_each(|v| *v = 0.0);
        for (volume, s_v) in scene.volumes.iter().zip(scattering.iter_mut()) {
            volume.coefficients(x, &mut buf.e_v[..n], &mut s_v[..n]);
            for k in 0..n {
                sigma_t[k] += buf.e_v[k];
            }
        }
        if sigma_t.iter().all(|&s| s == 0.0) {
            empty_run += 1;
            if feature.is_some() && empty_run >= EMPTY_BEFORE_LEAP {
                // Leap when the point a leap ahead is empty too.
                // Leap where no volume can have medium at either end (a bound that ignores
                // the fine noise, so the leaps do not depend on the jitter: no grain).
                let leap = LEAP_STEPS * dt;
                let probe = ray.origin + (t + leap + jitter * dt) * ray.dir;
                if t + leap < b
                    && scene
                        .volumes
                        .iter()
                        .all(|v| v.surely_empty(x) && v.surely_empty(probe))
                {
                    t += leap;
                    continue;
                }
            }
            t += dt;
            continue;
        }
        empty_run = 0;
        light_sources(scene, views, x, ray.dir, jitter, &scattering, &mut buf, n);
        let mut opacity = 0.0;
        let mut gain_t = 1.0;
        for (m, t_m) in t_vol.iter_mut().enumerate().take(count) {
            for k in 0..n {
                let sigma = gain_t * buf.sigma_t[k];
                let step_t = (-sigma * dt).exp();
                let source = buf.source[m][k];
                l_vol[k] += t_m[k] * step_integral(source, sigma, dt, step_t);
                if m == 0 {
                    opacity += t_m[k] * (1.0 - step_t);
                }
                t_m[k] *= step_t;
            }
            gain_t *= octaves.extinction;
        }
        let mid = t + 0.5 * dt;
        depth_sum += opacity * mid;
        weight_sum += opacity;
        if t_vol[..count]
            .iter()
            .all(|t_m| t_m[..n].iter().all(|&v| v < OPAQUE_TRANSMITTANCE))
        {
            break;
        }
        t += dt;
    }
    if weight_sum <= 0.0 {
        return;
    }
    // The air to the mean depth: in front of the volumes' light, and its transmittance.
    let d_mean = depth_sum / weight_sum;
    let point = ray.origin + d_mean * ray.dir;
    let mut front = [0.0f64; MAX_CHANNELS];
    let mut l = [0.0f64; MAX_CHANNELS];
    for (j, view) in views.iter().enumerate() {
        let shadow = shadows.get(j).map_or(Shadow::None, |s| s.as_shadow());
        view.sky_radiance_to_point(point, shadow, &mut l[..n], &mut [0.0; MAX_CHANNELS][..n]);
        if let Some(s) = shadows.get(j) {
            dim_multiple(view.as_ref(), ray, &s.dimmed, d_mean, &mut l[..n]);
        }
        for k in 0..n {
            front[k] += l[k];
        }
    }
    let mut t_air = [0.0f64; MAX_CHANNELS];
    views[0].transmittance_to_point(point, &mut t_air[..n]);
    for k in 0..n {
        out[k] = front[k] + t_air[k] * l_vol[k] + t_vol[0][k] * (out[k] - front[k]);
    }
}

/// ∫₀^dt S·e^{−σs} ds = (S − S·e^{−σ·dt})/σ (Hillaire 2016 §5.6.3, eq. 17), `step_t` being
/// e^{−σ·dt}; S·dt where σ = 0.
#[inline]
pub fn step_integral(source: f64, sigma: f64, dt: f64, step_t: f64) -> f64 {
    if sigma > 0.0 {
        (source - source * step_t) / sigma
    } else {
        source * dt
    }
}

/// A jitter in [0, 1) from the ray's direction (stable per pixel, varying between pixels).
fn ray_jitter(ray: &Ray) -> f64 {
    let bits = |v: f64| (v.to_bits() ^ (v.to_bits() >> 32)) as u32;
    unit(lowbias32(
        bits(ray.dir.x) ^ lowbias32(bits(ray.dir.y) ^ lowbias32(bits(ray.dir.z))),
    ))
}

/// The in-scattered source at `x` seen along `dir` (W·m⁻³·sr⁻¹ per unit irradiance's
/// channels) into `buf.source`: every light through the air and the volumes, by each
/// scattering volume's octaves, and the ambient light from above and below; `scattering`
/// holds each volume's scattering coefficient at `x`.
fn light_sources(
    scene: &Scene,
    views: &[std::sync::Arc<dyn SkyView + '_>],
    x: Vec3,
    dir: Vec3,
    jitter: f64,
    scattering: &[[f64; MAX_CHANNELS]],
    buf: &mut Buffers,
    n: usize,
) {
    buf.source
        .iter_mut()
        .for_each(|s| s[..n].iter_mut().for_each(|v| *v = 0.0));
    for (j, view) in views.iter().enumerate() {
        let light = view.light();
        let mut lit = false;
        for (volume, s_v) in scene.volumes.iter().zip(scattering) {
            if s_v[..n].iter().all(|&s| s == 0.0) {
                continue;
            }
            if !lit {
                let cached = buf.air.get(j).copied().flatten();
                match cached {
                    Some((at, air)) if (at - x).length_squared() < AIR_LIGHT_REUSE_M.powi(2) => {
                        buf.t_light = air.t_light;
                        buf.ambient = air.ambient;
                    }
                    _ => {
                        view.transmittance_to_light(x, &mut buf.t_light[..n]);
                        ambient_irradiance(scene, view.as_ref(), x, &mut buf.ambient, n);
                        if let Some(slot) = buf.air.get_mut(j) {
                            let air = AirLight {
                                t_light: buf.t_light,
                                ambient: buf.ambient,
                            };
                            *slot = Some((x, air));
                        }
                    }
                }
                light_optical_depth(scene, x, light.direction, jitter, &mut buf.tau_light[..n]);
                lit = true;
            }
            let octaves = volume.octaves();
            let phase = volume.phase(x);
            let cos = dir.dot(light.direction);
            let (mut gain_s, mut gain_t, mut gain_g) = (1.0, 1.0, 1.0);
            for source in buf
                .source
                .iter_mut()
                .take((octaves.count as usize).min(MAX_OCTAVES))
            {
                let p = phase.eval_scaled(cos, gain_g);
                for k in 0..n {
                    let t_vol = (-gain_t * buf.tau_light[k]).exp();
                    source[k] += gain_s * s_v[k] * p * light.irradiance[k] * buf.t_light[k] * t_vol;
                }
                gain_s *= octaves.scattering;
                gain_t *= octaves.extinction;
                gain_g *= octaves.eccentricity;
            }
            let up = x.normalize_or_zero();
            let mu_light = light.direction.dot(up);
            if let Some(f0) = volume.diffuse_radiance(x, mu_light, buf.tau_light[0], 0) {
                // The volume's own estimate of its diffuse light, scattered isotropically;
                // the ground below lit through the column.
                let albedo = &scene.sky.model().ground_albedo;
                let [_, ground_direct, ground_sky] = &buf.ambient;
                // The phase the δ-scaling keeps, towards the eye; the forward peak's share of
                // the beam (the same in every channel where the depth to the light is).
                let p_kept = phase.eval(cos).min(f0.forward_phase_cap);
                let peak0 = f0.forward_peak(buf.tau_light[0]);
                for k in 0..n {
                    let f = if volume.is_grey() || k == 0 {
                        f0
                    } else {
                        volume
                            .diffuse_radiance(x, mu_light, buf.tau_light[k], k)
                            .unwrap_or(f0)
                    };
                    let beam = light.irradiance[k] * buf.t_light[k];
                    let ground = (ground_direct[k] * f.base_direct
                        + beam * f.base_from_light
                        + ground_sky[k] * f.base_from_above)
                        / (1.0 - albedo[k] * f.base_reflectance);
                    // The field's moments, then the radiance scattered towards the eye
                    // (travelling along −dir): I₀ + g′·I₁·μ.
                    let e = [beam, buf.ambient[0][k], albedo[k] * ground];
                    let moments = [f.from_light, f.from_above, f.from_below];
                    let (mut i0, mut i1) = (0.0, 0.0);
                    for (m, e) in moments.iter().zip(e) {
                        i0 += m[0] * e;
                        i1 += m[1] * e;
                    }
                    let towards_eye = -dir.dot(up);
                    let radiance = (i0 + f.asymmetry * i1 * towards_eye).max(0.0);
                    // The beam's light in the forward peak (δ-scaled minus unscattered),
                    // scattered towards the eye with the phase the δ-scaling keeps.
                    let peak = if buf.tau_light[k] == buf.tau_light[0] {
                        peak0
                    } else {
                        f.forward_peak(buf.tau_light[k])
                    };
                    buf.source[1][k] +=
                        s_v[k] * (f.scattering_scale * radiance + p_kept * beam * peak);
                }
                continue;
            }
            let one_minus_g = 1.0 - phase.mean_cosine();
            let depths = volume.vertical_optical_depths(x, 0);
            let grey = volume.is_grey();
            for k in 0..n {
                let [up, down] = if grey || k == 0 {
                    depths
                } else {
                    volume.vertical_optical_depths(x, k)
                };
                let w_sky = 1.0 / (1.0 + one_minus_g * up);
                let w_ground = 1.0 / (1.0 + one_minus_g * down);
                let ground = albedo_of(scene, k) * (buf.ambient[1][k] + buf.ambient[2][k]);
                buf.source[0][k] +=
                    s_v[k] * (w_sky * buf.ambient[0][k] + w_ground * ground) / (2.0 * PI);
            }
        }
    }
}

/// The volumes' optical depth from `x` towards a light in `direction`, per channel.
fn light_optical_depth(scene: &Scene, x: Vec3, direction: Vec3, jitter: f64, out: &mut [f64]) {
    let towards = Ray {
        origin: x,
        dir: direction,
    };
    out.iter_mut().for_each(|v| *v = 0.0);
    for volume in &scene.volumes {
        if volume.bounds(&towards).is_none() {
            continue;
        }
        if volume.is_grey() {
            let tau = volume.light_optical_depth(&towards, 0, jitter);
            out.iter_mut().for_each(|v| *v += tau);
        } else {
            for (k, o) in out.iter_mut().enumerate() {
                *o += volume.light_optical_depth(&towards, k, jitter);
            }
        }
    }
}

/// The ambient hemispheric irradiances at `x` under the view's light: [E↓ from the sky
/// above, the direct and the sky irradiance of the ground below] (clear: the volumes'
/// shadow is applied by the caller).
fn ambient_irradiance(
    scene: &Scene,
    view: &dyn SkyView,
    x: Vec3,
    out: &mut [[f64; MAX_CHANNELS]; 3],
    n: usize,
) {
    let up = x.normalize_or_zero();
    let [sky, ground_direct, ground_sky] = out;
    view.sun_and_sky_irradiance(x, up, &mut ground_direct[..n], &mut sky[..n]);
    let ground = up * scene.sky.model().bottom_radius_m;
    view.sun_and_sky_irradiance(ground, up, &mut ground_direct[..n], &mut ground_sky[..n]);
}

/// The ground's albedo in channel `k`.
fn albedo_of(scene: &Scene, k: usize) -> f64 {
    scene.sky.model().ground_albedo[k]
}

/// The light a surface at `x` (normal `normal`) gets under the volumes (cloud shadows on
/// the ground), for a light in `direction` of irradiance `e_light` (W·m⁻²·nm⁻¹ at the top
/// of the atmosphere) with transmittance `t_air` through the air to it: `direct` (the beam
/// on the surface, as the sky method gave it) is dimmed by the volumes' transmittance
/// towards the light e^{−τ_l} (from the shadow `map` where it covers `x`, averaged over
/// the light's disk: the penumbra; else the march towards the light), and the beam the
/// volumes scatter forward reaches the surface as diffuse light, added to `sky`
/// (the sky's irradiance, itself dimmed by the volumes above), on a tilted surface by
/// (1 + n·up)/2 like the sky's:
///
/// - a volume with its own diffuse estimate ([`Volume::diffuse_radiance`], the clouds'
///   two-stream) gives the flux leaving the base of the column above the point;
/// - otherwise the volume's total transmission of light from above is taken as a
///   conservative slab's two-stream transmission 1/(1 + (1 − g)τ↑), τ↑ its optical depth
///   straight up (the hemispheric-mean closure, as for the ambient light in
///   [`composite`]), of which the beam's unscattered part e^{−τ_l} is taken out.
///
/// Several volumes stack: the light one diffuses crosses those below like the sky's.
#[allow(clippy::too_many_arguments)]
pub(super) fn dim_surface_light(
    scene: &Scene,
    map: Option<&CloudShadow>,
    x: Vec3,
    normal: Vec3,
    direction: Vec3,
    e_light: &[f64],
    t_air: &[f64],
    direct: &mut [f64],
    sky: &mut [f64],
) {
    let n = direct.len();
    let up = x.normalize_or_zero();
    let mu = direction.dot(up);
    let towards = Ray {
        origin: x,
        dir: direction,
    };
    let above = Ray { origin: x, dir: up };
    let mut beam = [1.0f64; MAX_CHANNELS];
    let mut sky_factor = [1.0f64; MAX_CHANNELS];
    let mut diffuse = [0.0f64; MAX_CHANNELS];
    let mut bounce = [1.0f64; MAX_CHANNELS];
    // The shadow map's depth towards the light (all volumes together; grey), where it
    // covers the point, in place of each volume's march.
    let mapped = map.and_then(|m| m.disk_optical_depth(x));
    let shells = scene
        .volumes
        .iter()
        .filter(|v| v.radii_m().is_some())
        .count()
        .max(1);
    for volume in &scene.volumes {
        let crosses = volume.bounds(&towards).is_some();
        let over = volume.bounds(&above).is_some();
        if !crosses && !over {
            continue;
        }
        let one_minus_g = 1.0 - volume.phase(x).mean_cosine();
        let mut first: Option<(f64, f64, Option<DiffuseLight>)> = None;
        for k in 0..n {
            let (tau_l, tau_up, f) = match first {
                Some(v) if volume.is_grey() => v,
                _ => {
                    let tau_l = match (mapped, volume.radii_m()) {
                        // Shared between the shells the map sums.
                        (Some(t), Some(_)) => t / shells as f64,
                        _ if crosses => volume.light_optical_depth(&towards, k, 0.5),
                        _ => 0.0,
                    };
                    let f = volume.diffuse_radiance(x, mu, tau_l, k);
                    let tau_up = match f {
                        Some(_) => 0.0,
                        None if over => volume.light_optical_depth(&above, k, 0.5),
                        None => 0.0,
                    };
                    first = Some((tau_l, tau_up, f));
                    (tau_l, tau_up, f)
                }
            };
            let unscattered = (-tau_l).exp();
            let (through, from_beam) = match f {
                Some(f) => {
                    // The ground and the column's base light each other.
                    bounce[k] /= 1.0 - albedo_of(scene, k) * f.base_reflectance;
                    (f.base_from_above, f.base_from_light)
                }
                None => {
                    let total = 1.0 / (1.0 + one_minus_g * tau_up);
                    (total, mu.max(0.0) * (total - unscattered).max(0.0))
                }
            };
            diffuse[k] = diffuse[k] * through + beam[k] * from_beam;
            sky_factor[k] *= through;
            beam[k] *= unscattered;
        }
    }
    let open = 0.5 * (1.0 + normal.dot(up));
    for k in 0..n {
        direct[k] *= beam[k];
        sky[k] = sky[k] * sky_factor[k] + e_light[k] * t_air[k] * diffuse[k] * open;
        // What the ground and the cloud base reflect between them comes back as diffuse
        // light: the whole irradiance times 1/(1 − A·R).
        sky[k] += (bounce[k] - 1.0) * (direct[k] + sky[k]);
    }
}

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
//! that name a feature size (clouds), at that size growing with distance, skipping empty
//! stretches in leaps of three steps, and stopping once the volumes are opaque. The steps
//! are jittered per ray (a hash of its direction).
//!
//! Composition: the air in front of the volumes' transmittance-weighted mean depth d̄ is left
//! unattenuated, the volumes' light is seen through the air to d̄ (the aerial perspective
//! of the clouds, Hillaire 2016 §5.7), and everything behind is attenuated by their
//! transmittance: L = S_air(0 → d̄) + T_air(d̄)·L_vol + T_vol·(L_behind − S_air(0 → d̄)).

use std::f64::consts::PI;

use crate::math::hash::{lowbias32, unit};
use crate::math::Vec3;
use crate::scene::{Ray, Scene, Volume};
use crate::sky::{Shadow, SkyView};
use crate::spectrum::MAX_CHANNELS;

/// Optical depth per march step at most (then at least [`MIN_STEPS`], at most
/// [`MAX_STEPS`] steps), for volumes without a feature size.
const STEP_OPTICAL_DEPTH: f64 = 0.1;
const MIN_STEPS: usize = 32;
const MAX_STEPS: usize = 1024;
/// Adaptive steps grow with the distance t as max(feature, STEP_DISTANCE_FRACTION·t): a
/// thousandth of a radian is about a pixel of a 1080p frame's 60° field.
const STEP_DISTANCE_FRACTION: f64 = 0.003;
/// Empty samples in a row before the march leaps ahead.
const EMPTY_BEFORE_LEAP: usize = 2;
/// Steps in one leap over empty space.
const LEAP_STEPS: f64 = 3.0;
/// The march stops once the volumes' transmittance is below this in every channel.
const OPAQUE_TRANSMITTANCE: f64 = 1e-4;

/// Per-channel scratch of one march.
struct Buffers {
    sigma_t: [f64; MAX_CHANNELS],
    e_v: [f64; MAX_CHANNELS],
    s_v: [f64; MAX_CHANNELS],
    source: [f64; MAX_CHANNELS],
    t_light: [f64; MAX_CHANNELS],
    tau_light: [f64; MAX_CHANNELS],
    ambient: [[f64; MAX_CHANNELS]; 2],
    e: [[f64; MAX_CHANNELS]; 2],
}

/// Composite the volumes crossed by `ray` before `end` over `out` (the radiance behind).
pub(super) fn composite(
    scene: &Scene,
    views: &[Box<dyn SkyView + '_>],
    ray: &Ray,
    end: f64,
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
    let step_at = |t: f64| match feature {
        Some(f) => f.max(STEP_DISTANCE_FRACTION * t),
        None => uniform_dt,
    };
    let jitter = ray_jitter(ray);

    let mut buf = Buffers {
        sigma_t: [0.0; MAX_CHANNELS],
        e_v: [0.0; MAX_CHANNELS],
        s_v: [0.0; MAX_CHANNELS],
        source: [0.0; MAX_CHANNELS],
        t_light: [0.0; MAX_CHANNELS],
        tau_light: [0.0; MAX_CHANNELS],
        ambient: [[0.0; MAX_CHANNELS]; 2],
        e: [[0.0; MAX_CHANNELS]; 2],
    };
    // Each volume's scattering coefficient at the current sample.
    let mut scattering = vec![[0.0f64; MAX_CHANNELS]; scene.volumes.len()];
    let mut t_vol = [1.0f64; MAX_CHANNELS];
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
                let leap = LEAP_STEPS * dt;
                let probe = ray.origin + (t + leap + jitter * dt) * ray.dir;
                if t + leap < b && scene.volumes.iter().all(|v| extinction_is_zero(v.as_ref(), probe, &mut buf, n)) {
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
        for k in 0..n {
            let sigma = buf.sigma_t[k];
            let step_t = (-sigma * dt).exp();
            let integral = if sigma > 0.0 {
                (buf.source[k] - buf.source[k] * step_t) / sigma
            } else {
                buf.source[k] * dt
            };
            l_vol[k] += t_vol[k] * integral;
            opacity += t_vol[k] * (1.0 - step_t);
            t_vol[k] *= step_t;
        }
        let mid = t + 0.5 * dt;
        depth_sum += opacity * mid;
        weight_sum += opacity;
        if t_vol[..n].iter().all(|&v| v < OPAQUE_TRANSMITTANCE) {
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
    for view in views {
        view.sky_radiance_to_point(point, Shadow::None, &mut l[..n], &mut [0.0; MAX_CHANNELS][..n]);
        for k in 0..n {
            front[k] += l[k];
        }
    }
    let mut t_air = [0.0f64; MAX_CHANNELS];
    views[0].transmittance_to_point(point, &mut t_air[..n]);
    for k in 0..n {
        out[k] = front[k] + t_air[k] * l_vol[k] + t_vol[k] * (out[k] - front[k]);
    }
}

/// A jitter in [0, 1) from the ray's direction (stable per pixel, varying between pixels).
fn ray_jitter(ray: &Ray) -> f64 {
    let bits = |v: f64| (v.to_bits() ^ (v.to_bits() >> 32)) as u32;
    unit(lowbias32(
        bits(ray.dir.x) ^ lowbias32(bits(ray.dir.y) ^ lowbias32(bits(ray.dir.z))),
    ))
}

/// Whether `volume` has no extinction at `p`.
fn extinction_is_zero(volume: &dyn Volume, p: Vec3, buf: &mut Buffers, n: usize) -> bool {
    volume.coefficients(p, &mut buf.e_v[..n], &mut buf.s_v[..n]);
    buf.e_v[..n].iter().all(|&e| e == 0.0)
}

/// The in-scattered source at `x` seen along `dir` (W·m⁻³·sr⁻¹ per unit irradiance's
/// channels) into `buf.source`: every light through the air and the volumes, by each
/// scattering volume's octaves, and the ambient light from above and below; `scattering`
/// holds each volume's scattering coefficient at `x`.
fn light_sources(
    scene: &Scene,
    views: &[Box<dyn SkyView + '_>],
    x: Vec3,
    dir: Vec3,
    jitter: f64,
    scattering: &[[f64; MAX_CHANNELS]],
    buf: &mut Buffers,
    n: usize,
) {
    buf.source[..n].iter_mut().for_each(|v| *v = 0.0);
    for view in views {
        let light = view.light();
        let mut lit = false;
        for (volume, s_v) in scene.volumes.iter().zip(scattering) {
            if s_v[..n].iter().all(|&s| s == 0.0) {
                continue;
            }
            if !lit {
                view.transmittance_to_light(x, &mut buf.t_light[..n]);
                light_optical_depth(scene, x, light.direction, jitter, &mut buf.tau_light[..n]);
                ambient_irradiance(scene, view.as_ref(), x, &mut buf.ambient, &mut buf.e, n);
                lit = true;
            }
            let octaves = volume.octaves();
            let phase = volume.phase(x);
            let cos = dir.dot(light.direction);
            let (mut gain_s, mut gain_t, mut gain_g) = (1.0, 1.0, 1.0);
            for _ in 0..octaves.count {
                let p = phase.eval_scaled(cos, gain_g);
                for k in 0..n {
                    let t_vol = (-gain_t * buf.tau_light[k]).exp();
                    buf.source[k] +=
                        gain_s * s_v[k] * p * light.irradiance[k] * buf.t_light[k] * t_vol;
                }
                gain_s *= octaves.scattering;
                gain_t *= octaves.extinction;
                gain_g *= octaves.eccentricity;
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
                buf.source[k] += s_v[k]
                    * (w_sky * buf.ambient[0][k] + w_ground * buf.ambient[1][k])
                    / (2.0 * PI);
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
/// above, E↑ reflected by the ground below] (the ground's albedo times its direct and sky
/// irradiance, the air between not counted). `e` is scratch.
fn ambient_irradiance(
    scene: &Scene,
    view: &dyn SkyView,
    x: Vec3,
    out: &mut [[f64; MAX_CHANNELS]; 2],
    e: &mut [[f64; MAX_CHANNELS]; 2],
    n: usize,
) {
    let up = x.normalize_or_zero();
    let [direct, sky] = e;
    view.sun_and_sky_irradiance(x, up, &mut direct[..n], &mut out[0][..n]);
    let model = scene.sky.model();
    let ground = up * model.bottom_radius_m;
    view.sun_and_sky_irradiance(ground, up, &mut direct[..n], &mut sky[..n]);
    for k in 0..n {
        out[1][k] = model.ground_albedo[k] * (direct[k] + sky[k]);
    }
}

//! The scene's volumes in front of what a ray sees: the lights' single scattering ray-marched
//! through them with the energy-conserving step of Hillaire 2016 (§5.6.3: the in-scattered
//! source S integrated analytically over a step of constant extinction,
//! ∫₀^d S·e^{−σ_t s} ds = (S − S·e^{−σ_t d})/σ_t), each sample lit through the air
//! (the sky method's transmittance to the light) and through the volumes (their optical
//! depth towards the light), and seen through the air between it and the observer.
//!
//! Each sample is also lit by the sky from above and the ground from below, taken as
//! isotropic (an ambient term, as the engines' clouds do): with hemispheric irradiances E↓
//! (the sky's, from the view) and E↑ (the ground's reflection of its own irradiance below
//! the sample), the in-scattered radiance is σ_s·(E↓ + E↑)/(2π) (a uniform hemisphere of
//! irradiance E has radiance E/π, fluence 2E). Neither the volumes' shadowing of that light
//! nor multiple scattering inside them is included (the clouds' octaves and height gradient
//! will add them); `docs/accuracy.md` gives the error against the reference.
//!
//! Composition: the air in front of the volumes is left unattenuated, everything behind
//! their front (including the air within and beyond them) is attenuated by their
//! transmittance, and their own light is added:
//! L = S_air(0 → a) + T_vol·(L_behind − S_air(0 → a)) + L_vol.

use std::f64::consts::PI;

use crate::math::Vec3;
use crate::scene::{Ray, Scene};
use crate::sky::{Shadow, SkyView};
use crate::spectrum::MAX_CHANNELS;

/// Optical depth per march step at most (then at least [`MIN_STEPS`], at most
/// [`MAX_STEPS`] steps).
const STEP_OPTICAL_DEPTH: f64 = 0.1;
const MIN_STEPS: usize = 32;
const MAX_STEPS: usize = 1024;

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
    let majorant = (0..n)
        .map(|k| {
            scene
                .volumes
                .iter()
                .map(|v| v.majorant(ray, a, b, k))
                .sum::<f64>()
        })
        .fold(0.0, f64::max);
    let steps =
        ((majorant * (b - a) / STEP_OPTICAL_DEPTH).ceil() as usize).clamp(MIN_STEPS, MAX_STEPS);
    let dt = (b - a) / steps as f64;

    let mut buf = [[0.0f64; MAX_CHANNELS]; 9];
    let [front, l, t_vol, l_vol, sigma_t, e_v, s_v, source, t_air] = &mut buf;
    let mut ambient = [[0.0f64; MAX_CHANNELS]; 2];
    let mut e = [[0.0f64; MAX_CHANNELS]; 2];
    let (front, l, t_vol, l_vol) = (
        &mut front[..n],
        &mut l[..n],
        &mut t_vol[..n],
        &mut l_vol[..n],
    );
    let (sigma_t, e_v, s_v) = (&mut sigma_t[..n], &mut e_v[..n], &mut s_v[..n]);
    let (source, t_air) = (&mut source[..n], &mut t_air[..n]);
    let mut t_light = [0.0f64; MAX_CHANNELS];
    let t_light = &mut t_light[..n];

    // The air's in-scattering between the observer and the volumes' front.
    let front_point = ray.origin + a * ray.dir;
    for view in views {
        view.sky_radiance_to_point(front_point, Shadow::None, l, &mut [0.0; MAX_CHANNELS][..n]);
        for k in 0..n {
            front[k] += l[k];
        }
    }
    t_vol.iter_mut().for_each(|v| *v = 1.0);
    for i in 0..steps {
        let x = ray.origin + (a + (i as f64 + 0.5) * dt) * ray.dir;
        sigma_t.iter_mut().for_each(|v| *v = 0.0);
        source.iter_mut().for_each(|v| *v = 0.0);
        // The light reaching x (through the air and every volume) and the ambient light there,
        // once per light and step, for the volumes that scatter at x.
        for (j, view) in views.iter().enumerate() {
            let light = view.light();
            let mut lit = false;
            for volume in &scene.volumes {
                volume.coefficients(x, e_v, s_v);
                if j == 0 {
                    for k in 0..n {
                        sigma_t[k] += e_v[k];
                    }
                }
                if s_v.iter().all(|&s| s == 0.0) {
                    continue;
                }
                if !lit {
                    light_transmittance(scene, view.as_ref(), x, t_light);
                    ambient_irradiance(scene, view.as_ref(), x, &mut ambient, &mut e, n);
                    lit = true;
                }
                let p = volume.phase(x).eval(ray.dir.dot(light.direction));
                for k in 0..n {
                    source[k] += s_v[k] * p * light.irradiance[k] * t_light[k];
                    source[k] += s_v[k] * (ambient[0][k] + ambient[1][k]) / (2.0 * PI);
                }
            }
        }
        if sigma_t.iter().all(|&s| s == 0.0) {
            continue;
        }
        views[0].transmittance_to_point(x, t_air);
        for k in 0..n {
            let step_t = (-sigma_t[k] * dt).exp();
            let integral = if sigma_t[k] > 0.0 {
                (source[k] - source[k] * step_t) / sigma_t[k]
            } else {
                source[k] * dt
            };
            l_vol[k] += t_vol[k] * t_air[k] * integral;
            t_vol[k] *= step_t;
        }
    }
    for k in 0..n {
        out[k] = front[k] + t_vol[k] * (out[k] - front[k]) + l_vol[k];
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

/// Transmittance from `x` to the view's light through the air and every volume.
fn light_transmittance(scene: &Scene, view: &dyn SkyView, x: Vec3, out: &mut [f64]) {
    view.transmittance_to_light(x, out);
    let towards = Ray {
        origin: x,
        dir: view.light().direction,
    };
    for volume in &scene.volumes {
        if volume.bounds(&towards).is_some() {
            for (k, o) in out.iter_mut().enumerate() {
                *o *= (-volume.optical_depth(&towards, 0.0, f64::INFINITY, k)).exp();
            }
        }
    }
}

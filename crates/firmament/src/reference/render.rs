//! Whole frames by the reference path tracer: the ground-truth image of the clear-sky scene
//! that `render::render` draws from the tables (ground and surfaces included, the sun's
//! disk added through the air along the view where no surface hides it).

use std::sync::atomic::{AtomicBool, Ordering};

use super::{render_pixels, RadianceEstimate, ReferenceSettings};
use crate::atmosphere::Model;
use crate::io::ImageRgbF32;
use crate::math::sphere::ray_sphere;
use crate::math::Vec3;
use crate::render::{Frame, RenderSettings};
use crate::scene::{Light, Ray, Surface, Volume};
use crate::{Error, Result};

/// How far [`render_frame`] is.
#[derive(Clone, Copy, Debug)]
pub struct Progress {
    /// Fraction of the pixels done, 0–1.
    pub fraction: f64,
    /// Mean relative standard error of the luminance of the pixels done in whole batches
    /// (NaN before the first batch ends).
    pub mean_relative_stderr: f64,
}

/// The frame of `settings` lit by `sun` (the model's sun in a direction) through the
/// atmosphere and `volumes`, with `surfaces` besides the ground sphere (see
/// [`super::scene_radiance`]), every pixel traced with `reference.samples` paths per
/// wavelength (`include_ground` is forced on: a picture shows the ground). Colour and white
/// balance as [`crate::render::render`]; the sun's disk is added where a view ray meets
/// neither the ground nor a surface, attenuated by the transmittance of the model's column
/// integrals. `progress` receives the fraction done and the noise reached; `cancel` stops it
/// between batches of pixels. Returns the frame and the mean relative standard error of the
/// pixels' luminance.
#[allow(clippy::too_many_arguments)]
pub fn render_frame(
    model: &Model,
    volumes: &[Box<dyn Volume + '_>],
    surfaces: &[Box<dyn Surface + '_>],
    settings: &RenderSettings,
    sun: &Light,
    reference: &ReferenceSettings,
    progress: &(dyn Fn(Progress) + Sync),
    cancel: Option<&AtomicBool>,
) -> Result<(Frame, f64)> {
    settings.validate()?;
    let reference = ReferenceSettings {
        include_ground: true,
        ..reference.clone()
    };
    reference.validate()?;
    let (w, h) = (settings.width, settings.height);
    let prepared = settings.camera.prepare(model.bottom_radius_m, w, h);
    let mut pixels = Vec::new();
    let mut rays = Vec::new();
    for y in 0..h {
        for x in 0..w {
            if let Some(ray) = prepared.ray(x as f64 + 0.5, y as f64 + 0.5) {
                pixels.push(y * w + x);
                rays.push((ray.origin, ray.dir));
            }
        }
    }
    let batch = (4 * w).clamp(256, 16_384);
    let done = std::sync::atomic::AtomicUsize::new(0);
    let mut estimates: Vec<RadianceEstimate> = Vec::with_capacity(rays.len());
    let colour = model.colour_matrix();
    // The mean relative standard error of the pixels done so far (f64 bits; updated
    // between batches).
    let noise = std::sync::atomic::AtomicU64::new(f64::NAN.to_bits());
    let (mut noise_sum, mut noise_count) = (0.0, 0usize);
    for (b, chunk) in rays.chunks(batch).enumerate() {
        if cancel.is_some_and(|c| c.load(Ordering::Relaxed)) {
            return Err(Error::Interrupted);
        }
        estimates.extend(render_pixels(
            model,
            volumes,
            surfaces,
            chunk,
            (b * batch) as u64,
            sun.direction,
            &reference,
            &|| {
                let d = done.fetch_add(1, Ordering::Relaxed) + 1;
                if d.is_multiple_of(256) {
                    progress(Progress {
                        fraction: d as f64 / rays.len() as f64,
                        mean_relative_stderr: f64::from_bits(noise.load(Ordering::Relaxed)),
                    });
                }
            },
        ));
        for e in &estimates[noise_count.min(estimates.len())..] {
            let (y, se) = colour.luminance_and_stderr(&e.radiance, &e.stderr);
            if y > 0.0 {
                noise_sum += se / y;
            }
        }
        noise_count = estimates.len();
        noise.store(
            (noise_sum / noise_count as f64).to_bits(),
            Ordering::Relaxed,
        );
    }
    if cancel.is_some_and(|c| c.load(Ordering::Relaxed)) {
        return Err(Error::Interrupted);
    }
    let balance = colour.white_balance(&model.solar_irradiance, settings.white_balance);
    // The tracer's source is the model's sun; another light's irradiance scales it.
    let scale = sun.scale_against(&model.solar_irradiance);
    let mut image = ImageRgbF32::new(w, h);
    let mut mask = vec![false; w * h];
    let (mut stderr_sum, mut stderr_count) = (0.0, 0usize);
    for ((&p, &(origin, dir)), e) in pixels.iter().zip(&rays).zip(&estimates) {
        let mut l: Vec<f64> = e.radiance.iter().zip(&scale).map(|(v, s)| v * s).collect();
        if sun.visible_disk {
            let t = view_transmittance(model, surfaces, origin, dir);
            sun.add_disk_radiance(dir, &t, &mut l);
        }
        let (y, se) = colour.luminance_and_stderr(&e.radiance, &e.stderr);
        if y > 0.0 {
            stderr_sum += se / y;
            stderr_count += 1;
        }
        let c = colour.to_srgb(&l);
        image.data[p] = [
            (c[0] * balance[0]) as f32,
            (c[1] * balance[1]) as f32,
            (c[2] * balance[2]) as f32,
        ];
        mask[p] = true;
    }
    let mean_stderr = if stderr_count > 0 {
        stderr_sum / stderr_count as f64
    } else {
        0.0
    };
    Ok((Frame { image, mask }, mean_stderr))
}

/// Transmittance of the air along a view ray from `origin` to the top of the atmosphere, 0
/// where it meets the ground or any of `surfaces` (the model's column integrals).
fn view_transmittance(
    model: &Model,
    surfaces: &[Box<dyn Surface + '_>],
    origin: Vec3,
    dir: Vec3,
) -> Vec<f64> {
    let n = model.channels();
    if ray_sphere(origin, dir, model.bottom_radius_m).is_some_and(|(near, _)| near > 0.0) {
        return vec![0.0; n];
    }
    let ray = Ray { origin, dir };
    if (surfaces.iter()).any(|s| s.intersect(&ray, f64::INFINITY).is_some()) {
        return vec![0.0; n];
    }
    let mut transmittance = vec![1.0; n];
    if let Some((near, far)) = ray_sphere(origin, dir, model.top_radius_m) {
        if far > 0.0 {
            let start = near.max(0.0);
            let p = origin + start * dir;
            let r = p.length();
            let mu = (p.dot(dir) / r).clamp(-1.0, 1.0);
            let tau = model.optical_depth_along_ray(r, mu, far - start);
            for k in 0..n {
                transmittance[k] = (-tau[k]).exp();
            }
        }
    }
    transmittance
}

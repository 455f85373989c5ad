//! Images: cameras, per-pixel shading of the paper's eq. 16 (sky, ground lit by sun and sky,
//! aerial perspective, sun disk with limb darkening), spectral to colour, exposure and tone
//! mapping.

pub mod camera;
pub mod scene;
pub mod tonemap;

use std::f64::consts::PI;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use rayon::prelude::*;

pub use camera::{Camera, Projection, Ray};
pub use scene::Scene;
pub use tonemap::ToneCurve;

use crate::atmosphere::Model;
use crate::geometry::{
    add_scaled, direction_from_zenith_azimuth, dot, normalize, ray_sphere, Vec3,
};
use crate::io::ImageRgbF32;
use crate::sky::{limb_darkening, Sky, SkySlice};
use crate::spectrum::{spectrum_to_xyz, xyz_to_linear_srgb};
use crate::{Error, Result};

/// What to draw besides the atmosphere.
#[derive(Clone, Debug)]
pub struct ShadeOptions {
    /// Unit vector towards the sun (world frame).
    pub sun: Vec3,
    /// Draw the solar disk.
    pub sun_disk: bool,
}

/// Sun direction from zenith and azimuth (degrees; azimuth clockwise from north).
pub fn sun_direction(zenith_deg: f64, azimuth_deg: f64) -> Vec3 {
    direction_from_zenith_azimuth(zenith_deg.to_radians(), azimuth_deg.to_radians())
}

/// Spectral → colour: XYZ = M·L for the model's samples (the spectrum is linearly
/// interpolated between samples, so the map is linear), then linear sRGB. Rows: X, Y, Z.
pub struct ColourMatrix {
    xyz: Vec<[f64; 3]>,
}

impl ColourMatrix {
    /// For these wavelengths.
    pub fn new(wavelengths_nm: &[f64]) -> ColourMatrix {
        let n = wavelengths_nm.len();
        let xyz = (0..n)
            .map(|k| {
                let mut e = vec![0.0; n];
                e[k] = 1.0;
                spectrum_to_xyz(wavelengths_nm, &e)
            })
            .collect();
        ColourMatrix { xyz }
    }

    /// CIE XYZ (Y in cd/m² for radiance in W·m⁻²·sr⁻¹·nm⁻¹).
    #[inline]
    pub fn to_xyz(&self, l: &[f64]) -> [f64; 3] {
        let mut o = [0.0; 3];
        for (v, m) in l.iter().zip(&self.xyz) {
            o[0] += v * m[0];
            o[1] += v * m[1];
            o[2] += v * m[2];
        }
        o
    }

    /// Linear sRGB with Y in cd/m².
    #[inline]
    pub fn to_srgb(&self, l: &[f64]) -> [f64; 3] {
        xyz_to_linear_srgb(self.to_xyz(l))
    }
}

/// Spectral radiance (W·m⁻²·sr⁻¹·nm⁻¹) arriving along a primary ray: the ground (a
/// Lambertian sphere lit by sun and sky) seen through aerial perspective, or the sky and
/// the sun's disk (paper eq. 16).
pub fn shade(sky: &Sky, ray: &Ray, options: &ShadeOptions, out: &mut [f64]) {
    shade_sliced(sky, None, ray, options, out)
}

/// The [`SkySlice`] for rays from `origin` (None when it is outside the atmosphere).
pub fn camera_slice(sky: &Sky, origin: Vec3, sun: Vec3) -> Option<SkySlice> {
    let r = crate::geometry::length(origin);
    (r <= sky.model.top_radius_m).then(|| sky.slice(r, (dot(origin, sun) / r).clamp(-1.0, 1.0)))
}

/// [`shade`] with a camera slice (see [`Sky::slice`]).
pub fn shade_sliced(
    sky: &Sky,
    slice: Option<&SkySlice>,
    ray: &Ray,
    options: &ShadeOptions,
    out: &mut [f64],
) {
    let n = sky.channels();
    let model = &sky.model;
    let mut t = [0.0f64; 64];
    let t = &mut t[..n];
    let hit =
        ray_sphere(ray.origin, ray.dir, model.bottom_radius_m).filter(|&(near, _)| near > 0.0);
    if let Some((near, _)) = hit {
        let p = add_scaled(ray.origin, near, ray.dir);
        let normal = normalize(p);
        let mut buf = [[0.0f64; 64]; 2];
        let [e_sun, e_sky] = &mut buf;
        let (e_sun, e_sky) = (&mut e_sun[..n], &mut e_sky[..n]);
        sky.sun_and_sky_irradiance(p, normal, options.sun, e_sun, e_sky);
        sky.sky_radiance_to_point_sliced(slice, ray.origin, p, 0.0, options.sun, out, t);
        for k in 0..n {
            out[k] += model.ground_albedo[k] / PI * (e_sun[k] + e_sky[k]) * t[k];
        }
    } else {
        let in_disk =
            options.sun_disk && dot(ray.dir, options.sun) > model.sun_angular_radius_rad.cos();
        if in_disk {
            sky.sky_radiance_sliced(slice, ray.origin, ray.dir, 0.0, options.sun, out, t);
            add_sun_disk(sky, ray.dir, options.sun, t, out);
        } else {
            sky.sky_radiance_sliced(slice, ray.origin, ray.dir, 0.0, options.sun, out, &mut []);
        }
    }
}

/// Adds the solar disk's radiance (limb-darkened, attenuated by `transmittance`) when `dir`
/// falls inside it.
pub fn add_sun_disk(sky: &Sky, dir: Vec3, sun: Vec3, transmittance: &[f64], out: &mut [f64]) {
    let model = &sky.model;
    let alpha = model.sun_angular_radius_rad;
    let cos_angle = dot(dir, sun).clamp(-1.0, 1.0);
    if cos_angle <= alpha.cos() {
        return;
    }
    let angle = cos_angle.acos();
    let x = angle.sin() / alpha.sin();
    let mu = (1.0 - x * x).max(0.0).sqrt();
    let mut centre = [0.0f64; 64];
    sky.solar_radiance_centre(&mut centre[..out.len()]);
    for k in 0..out.len() {
        let lambda = model.wavelengths.nm()[k];
        out[k] += centre[k] * limb_darkening(model.limb_darkening, mu, lambda) * transmittance[k];
    }
}

/// A rendered frame: linear sRGB (Rec. 709 primaries, D65) scaled so that Y is the
/// luminance in cd/m²; pixels outside the projection are NaN-free zeros with `mask` false.
pub struct Frame {
    /// Linear colour, Y in cd/m².
    pub image: ImageRgbF32,
    /// Whether each pixel is inside the projection.
    pub mask: Vec<bool>,
}

impl Frame {
    /// Log-average luminance over the pixels inside the projection (cd/m²), leaving out
    /// black space (below 10⁻⁶ of the brightest pixel) so a planet seen from orbit is
    /// exposed for itself.
    pub fn log_average_luminance(&self) -> f64 {
        let lum = |p: &[f32; 3]| 0.2126 * p[0] as f64 + 0.7152 * p[1] as f64 + 0.0722 * p[2] as f64;
        let max = self.image.data.iter().map(lum).fold(0.0, f64::max);
        let floor = (max * 1e-6).max(1e-6);
        let mut sum = 0.0;
        let mut count = 0usize;
        for (p, &m) in self.image.data.iter().zip(&self.mask) {
            let y = lum(p);
            if m && y > floor {
                sum += y.ln();
                count += 1;
            }
        }
        if count == 0 {
            return 1.0;
        }
        (sum / count as f64).exp()
    }

    /// Tone-mapped 8-bit sRGB: exposure scale × luminance-scaled colour, then the curve, then
    /// the sRGB transfer function.
    pub fn to_srgb8(&self, exposure: f64, curve: ToneCurve) -> Vec<[u8; 3]> {
        // A 2¹⁶-entry table of the 8-bit code of each tone-mapped value in [0, 1]: the code
        // whose interval contains it (binary search on the 255 decision levels, the decoded
        // mid-points), then one lookup per channel.
        let levels: Vec<f32> = (0..255)
            .map(|i| srgb_decode((i as f64 + 0.5) / 255.0) as f32)
            .collect();
        let table: Vec<u8> = (0..=65535u32)
            .map(|i| levels.partition_point(|&l| l <= i as f32 / 65535.0) as u8)
            .collect();
        let encode = |v: f64| table[(v.clamp(0.0, 1.0) * 65535.0 + 0.5) as usize];
        self.image
            .data
            .par_iter()
            .map(|p| p.map(|v| encode(curve.apply(v as f64 * exposure))))
            .collect()
    }
}

/// The sRGB transfer function's inverse (IEC 61966-2-1).
fn srgb_decode(e: f64) -> f64 {
    if e <= 0.04045 {
        e / 12.92
    } else {
        ((e + 0.055) / 1.055).powf(2.4)
    }
}

/// Render settings.
pub struct RenderSettings<'a> {
    /// Camera.
    pub camera: &'a Camera,
    /// Image width (pixels).
    pub width: usize,
    /// Image height (pixels).
    pub height: usize,
    /// Sun and disk.
    pub shade: ShadeOptions,
    /// Divide colours by the top-of-atmosphere sun's colour (white sun); off keeps the
    /// physical colour of the standard D65 white.
    pub white_balance: bool,
}

impl RenderSettings<'_> {
    /// The checks [`render`] makes before drawing (shared with other backends): image size,
    /// camera values, the cube map's 6:1 shape.
    pub fn validate(&self) -> Result<()> {
        let (w, h) = (self.width, self.height);
        if w == 0 || h == 0 || w > 32768 || h > 32768 {
            return Err(Error::invalid(
                "width/height",
                format!("{w}×{h}"),
                "between 1 and 32768 pixels each",
            ));
        }
        self.camera.validate()?;
        if self.camera.projection == Projection::Cubemap && w != 6 * h {
            return Err(Error::invalid(
                "width",
                w,
                format!("6 × height ({}) for a cube map", 6 * h),
            ));
        }
        Ok(())
    }
}

/// Per-channel factors applied to linear sRGB: with `enabled`, those that make the
/// top-of-atmosphere sun white at its own luminance; `[1, 1, 1]` otherwise.
pub fn white_balance(model: &Model, colour: &ColourMatrix, enabled: bool) -> [f64; 3] {
    if !enabled {
        return [1.0; 3];
    }
    let sun = colour.to_srgb(&model.solar_irradiance);
    let y = colour.to_xyz(&model.solar_irradiance)[1];
    sun.map(|c| if c > 0.0 { y / c } else { 1.0 })
}

/// Render a frame on the CPU, rows in parallel. `progress` receives the fraction done.
pub fn render(
    sky: &Sky,
    settings: &RenderSettings,
    progress: &(dyn Fn(f64) + Sync),
    cancel: Option<&AtomicBool>,
) -> Result<Frame> {
    settings.validate()?;
    let (w, h) = (settings.width, settings.height);
    let n = sky.channels();
    let colour = ColourMatrix::new(sky.model.wavelengths.nm());
    let balance = white_balance(&sky.model, &colour, settings.white_balance);
    let origin = [
        0.0,
        0.0,
        sky.model.bottom_radius_m + settings.camera.altitude_m,
    ];
    let slice = camera_slice(sky, origin, settings.shade.sun);
    let prepared = settings.camera.prepare(sky.model.bottom_radius_m, w, h);
    let mut image = ImageRgbF32::new(w, h);
    let mut mask = vec![false; w * h];
    let done = AtomicUsize::new(0);
    let interrupted = AtomicBool::new(false);
    image
        .data
        .par_chunks_mut(w)
        .zip(mask.par_chunks_mut(w))
        .enumerate()
        .for_each(|(y, (row, mrow))| {
            if cancel.is_some_and(|c| c.load(Ordering::Relaxed)) {
                interrupted.store(true, Ordering::Relaxed);
                return;
            }
            let mut l = [0.0f64; 64];
            let l = &mut l[..n];
            for x in 0..w {
                let Some(ray) = prepared.ray(x as f64 + 0.5, y as f64 + 0.5) else {
                    continue;
                };
                shade_sliced(sky, slice.as_ref(), &ray, &settings.shade, l);
                let c = colour.to_srgb(l);
                row[x] = [
                    (c[0] * balance[0]) as f32,
                    (c[1] * balance[1]) as f32,
                    (c[2] * balance[2]) as f32,
                ];
                mrow[x] = true;
            }
            let d = done.fetch_add(1, Ordering::Relaxed) + 1;
            if d.is_multiple_of(16) {
                progress(d as f64 / h as f64);
            }
        });
    if interrupted.load(Ordering::Relaxed) {
        return Err(Error::Interrupted);
    }
    Ok(Frame { image, mask })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fast_srgb_encoding_equals_the_transfer_function() {
        let levels: Vec<f32> = (0..255)
            .map(|i| srgb_decode((i as f64 + 0.5) / 255.0) as f32)
            .collect();
        let mut mismatches = 0;
        for i in 0..=100_000 {
            let v = i as f32 / 100_000.0;
            let fast = levels.partition_point(|&l| l <= v) as u8;
            let exact = crate::io::encode_srgb(v);
            // Ties at a decision level may round either way in f32.
            if fast != exact {
                mismatches += 1;
                assert!((fast as i32 - exact as i32).abs() <= 1);
            }
        }
        assert!(mismatches < 20, "{mismatches}");
    }
}

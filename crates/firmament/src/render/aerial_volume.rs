//! The aerial-perspective volume (Hillaire 2016 §2, "Our approach"; Hillaire 2020 §5.4): a
//! camera-aligned froxel grid holding the in-scattered radiance and the transmittance
//! between the observer and points along each froxel column's direction, at depth slices
//! spread quadratically out to a maximum distance, filled once per frame and light from the
//! sky method's own [`SkyView::sky_radiance_along`] (one march per column for Hillaire 2020,
//! one query per froxel for the tables), so every method can use it. A surface
//! hit then reads its aerial perspective by one trilinear lookup at its pixel's direction
//! and distance instead of asking the method (a march for Hillaire 2020, a pair of 4D
//! lookups for the tables).
//!
//! What it leaves to the per-pixel path: rays with light shafts (the volume holds fully lit
//! rays), points beyond its last slice, directions outside the image (a fisheye's corners),
//! and cube maps (froxels would straddle faces). A column that meets the planet's ground
//! sphere holds the aerial perspective to the ground in its slices beyond it, so the
//! ground's own pixels read the ground's value rather than a blend with air below it. Its error against the per-pixel answer is
//! measured in docs/accuracy.md and `tests/aerial_volume.rs`.

use rayon::prelude::*;

use crate::math::sphere::ray_sphere;
use crate::math::Vec3;
use crate::scene::{PreparedCamera, Projection};
use crate::sky::SkyView;
use crate::{Error, Result};

/// The volume's size and reach.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AerialVolumeConfig {
    /// Froxel columns across the image.
    pub width: usize,
    /// Froxel rows down the image.
    pub height: usize,
    /// Depth slices (quadratic in distance: denser near the camera).
    pub slices: usize,
    /// The last slice's far distance (m); beyond it the per-pixel path answers.
    pub max_distance_m: f64,
}

impl Default for AerialVolumeConfig {
    /// Hillaire 2020's 32³ froxels over 32 km.
    fn default() -> Self {
        AerialVolumeConfig {
            width: 32,
            height: 32,
            slices: 32,
            max_distance_m: 32_000.0,
        }
    }
}

impl AerialVolumeConfig {
    /// Refuse sizes and distances that cannot work.
    pub fn validate(&self) -> Result<()> {
        for (field, v) in [
            ("aerial_volume.width", self.width),
            ("aerial_volume.height", self.height),
            ("aerial_volume.slices", self.slices),
        ] {
            if !(2..=512).contains(&v) {
                return Err(Error::invalid(field, v, "an integer from 2 to 512"));
            }
        }
        if !(self.max_distance_m.is_finite() && self.max_distance_m > 0.0) {
            return Err(Error::invalid(
                "aerial_volume.max_distance_m",
                self.max_distance_m,
                "a positive number of metres",
            ));
        }
        Ok(())
    }
}

/// One light's volume for one camera.
pub struct AerialVolume {
    config: AerialVolumeConfig,
    camera: PreparedCamera,
    /// The image's size (pixels), which the froxel columns divide.
    image: (f64, f64),
    channels: usize,
    /// Per froxel (x, y, slice), radiance then transmittance per channel; NaN where the
    /// column's direction is outside the projection.
    data: Vec<f32>,
    /// Per column, the distance (m) to the planet's ground sphere (∞ when it misses it).
    ground: Vec<f64>,
}

impl AerialVolume {
    /// The volume of `view` (from `observer`, planet-centred m, over a ground sphere of
    /// radius `ground_radius_m`) for the camera `camera` drawing a `width` × `height` image;
    /// None for a cube map.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        view: &dyn SkyView,
        observer: Vec3,
        ground_radius_m: f64,
        camera: &PreparedCamera,
        width: usize,
        height: usize,
        config: AerialVolumeConfig,
        channels: usize,
    ) -> Option<AerialVolume> {
        if camera.projection() == Projection::Cubemap {
            return None;
        }
        let (w, h, d) = (config.width, config.height, config.slices);
        let stride = 2 * channels;
        let mut data = vec![0.0f32; w * h * d * stride];
        let mut ground = vec![f64::INFINITY; w * h];
        data.par_chunks_mut(d * stride)
            .zip(ground.par_iter_mut())
            .enumerate()
            .for_each(|(column, (out, ground_m))| {
                let (x, y) = (column % w, column / w);
                // Columns from edge to edge of the image (no clamped border on lookup).
                let px = x as f64 / (w - 1) as f64 * width as f64;
                let py = y as f64 / (h - 1) as f64 * height as f64;
                let Some(ray) = camera.ray(px, py) else {
                    out.iter_mut().for_each(|v| *v = f32::NAN);
                    return;
                };
                // Where the column meets the planet's ground sphere: the slices beyond hold
                // the aerial perspective to the ground there.
                if let Some((near, _)) = ray_sphere(observer, ray.dir, ground_radius_m) {
                    if near > 0.0 {
                        *ground_m = near;
                    }
                }
                let points: Vec<Vec3> = (0..d)
                    .map(|z| {
                        observer
                            + ray.dir * slice_distance(z, d, config.max_distance_m).min(*ground_m)
                    })
                    .collect();
                let (mut l, mut t) = (vec![0.0; d * channels], vec![0.0; d * channels]);
                view.sky_radiance_along(&points, &mut l, &mut t);
                for (z, froxel) in out.chunks_mut(stride).enumerate() {
                    for k in 0..channels {
                        froxel[k] = l[z * channels + k] as f32;
                        froxel[channels + k] = t[z * channels + k] as f32;
                    }
                }
            });
        Some(AerialVolume {
            config,
            camera: camera.clone(),
            image: (width as f64, height as f64),
            channels,
            data,
            ground,
        })
    }

    /// The radiance scattered towards the observer before `distance` (m) along unit `dir`
    /// and the transmittance there, into `radiance` and `transmittance`; false (nothing
    /// written) where the volume does not answer: beyond its reach, outside the image.
    pub fn sample(
        &self,
        dir: Vec3,
        distance: f64,
        radiance: &mut [f64],
        transmittance: &mut [f64],
    ) -> bool {
        let c = &self.config;
        if distance.is_nan() || distance < 0.0 || distance > c.max_distance_m {
            return false;
        }
        let Some((px, py)) = self.camera.pixel_of(dir) else {
            return false;
        };
        let (x0, x1, tx) = weights(px / self.image.0 * (c.width - 1) as f64, c.width);
        let (y0, y1, ty) = weights(py / self.image.1 * (c.height - 1) as f64, c.height);
        let n = self.channels;
        radiance[..n].iter_mut().for_each(|v| *v = 0.0);
        transmittance[..n].iter_mut().for_each(|v| *v = 0.0);
        let columns = [
            (y0 * c.width + x0, (1.0 - tx) * (1.0 - ty)),
            (y0 * c.width + x1, tx * (1.0 - ty)),
            (y1 * c.width + x0, (1.0 - tx) * ty),
            (y1 * c.width + x1, tx * ty),
        ];
        // Near the horizon the columns' distances to the ground differ widely: one column's
        // slices stop at a ground nearer than the point while another's still hold air.
        // There the per-pixel path answers.
        let nearest = columns
            .iter()
            .map(|&(i, _)| self.ground[i])
            .fold(f64::INFINITY, f64::min);
        let farthest = columns
            .iter()
            .map(|&(i, _)| self.ground[i])
            .fold(0.0, f64::max);
        if distance > nearest && farthest > GROUND_SPREAD * nearest {
            return false;
        }
        for (column, w) in columns {
            if w > 0.0 && !self.add_column(column, distance, w, radiance, transmittance) {
                return false;
            }
        }
        true
    }

    /// Adds `weight` × column `column`'s aerial perspective at `distance` (m), linear in
    /// the slice coordinate, to `radiance` and `transmittance`: towards (0, T = 1) before
    /// the first slice's centre, and up to the column's ground, whose slices beyond hold the
    /// ground's value (so a point on the ground reads the ground's, not a mix with air
    /// under it). False where the column has no direction (outside the projection).
    fn add_column(
        &self,
        column: usize,
        distance: f64,
        weight: f64,
        radiance: &mut [f64],
        transmittance: &mut [f64],
    ) -> bool {
        let c = &self.config;
        let (n, stride) = (self.channels, 2 * self.channels);
        let ground = self.ground[column];
        let slice = |d: f64| (d / c.max_distance_m).sqrt() * c.slices as f64 - 0.5;
        let d = distance.min(ground);
        let s = slice(d);
        let froxel = |z: usize| {
            let i = (column * c.slices + z) * stride;
            &self.data[i..i + stride]
        };
        if froxel(0)[0].is_nan() {
            return false;
        }
        let (z0, z1, t, near) = if s < 0.0 {
            (0, 0, 0.0, (s + 0.5) / 0.5)
        } else {
            let z0 = (s as usize).min(c.slices - 1);
            let z1 = (z0 + 1).min(c.slices - 1);
            // Slice z1's value is the ground's when the ground lies before its centre.
            let s1 = (z1 as f64).min(slice(ground));
            let t = if s1 > z0 as f64 {
                ((s - z0 as f64) / (s1 - z0 as f64)).clamp(0.0, 1.0)
            } else {
                1.0
            };
            (z0, z1, t, 1.0)
        };
        let (a, b) = (froxel(z0), froxel(z1));
        for k in 0..n {
            let l = (1.0 - t) * a[k] as f64 + t * b[k] as f64;
            let tr = (1.0 - t) * a[n + k] as f64 + t * b[n + k] as f64;
            radiance[k] += weight * near * l;
            transmittance[k] += weight * (1.0 - near * (1.0 - tr));
        }
        true
    }
}

/// The largest ratio of the four columns' distances to the ground at which a point beyond
/// the nearest of them is read from the volume (see [`AerialVolume::sample`]).
const GROUND_SPREAD: f64 = 1.25;

/// The far distance (m) of slice `z` of `slices` out to `max`: quadratic, so the first
/// slices are close to the camera, where terrain is densest on screen.
#[inline]
fn slice_distance(z: usize, slices: usize, max: f64) -> f64 {
    let f = (z as f64 + 0.5) / slices as f64;
    max * f * f
}

/// Linear-filter indices and weight at continuous texel coordinate `x` (texel centres at
/// integers) over `n` texels, clamped to the edges.
#[inline]
fn weights(x: f64, n: usize) -> (usize, usize, f64) {
    let x = x.clamp(0.0, (n - 1) as f64);
    let i0 = (x as usize).min(n - 1);
    let i1 = (i0 + 1).min(n - 1);
    (i0, i1, x - i0 as f64)
}

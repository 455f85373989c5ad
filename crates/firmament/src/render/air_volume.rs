//! The terrain's change of the air's light integrated along the views of one observer:
//! ΔS(v, d) = ∫₀^d T(0, s) ΔJ(x_s, v) ds ([`super::terrain_air`]) on a grid of directions
//! and distances (a froxel volume in the manner of Hillaire 2020's aerial-perspective
//! table, here in world directions), so a pixel adds it with one trilinear lookup at its
//! direction and its hit distance.
//!
//! Directions: azimuth uniform, elevation e = 90°·s·|s| for s uniform in [−1, 1] (rows
//! crowd at the horizon, where the terrain's silhouettes are). Distances along each
//! direction: d_j = D·(j/J)², D the distance to the field's ceiling (at most
//! [`MAX_DISTANCE_M`]); beyond D the last value holds.

use rayon::prelude::*;

use super::terrain_air::AirField;
use crate::atmosphere::groups::{AEROSOLS, MOLECULES};
use crate::math::sphere::ray_sphere;
use crate::math::Vec3;
use crate::sky::SkyView;
use crate::spectrum::MAX_CHANNELS;

/// Azimuth columns.
pub const AZIMUTHS: usize = 64;
/// Elevation rows, −90° to 90°.
pub const ELEVATIONS: usize = 49;
/// Distance steps along each direction.
pub const STEPS: usize = 32;
/// The farthest distance integrated (m).
pub const MAX_DISTANCE_M: f64 = 120_000.0;

/// ΔS for one observer.
#[derive(Clone)]
pub struct AirVolume {
    observer: Vec3,
    /// The local frame at the observer: east, north, up.
    frame: [Vec3; 3],
    channels: usize,
    /// D per direction (m), `row·AZIMUTHS + column`.
    reach: Vec<f64>,
    /// ΔS at d_0 … d_J per direction, channel-minor.
    values: Vec<f32>,
}

impl AirVolume {
    /// The volume from `observer` (planet-centred, m) through `field`, the air's
    /// transmittance from `view` (the sky method's view from the observer), the
    /// scattering coefficients from `model`.
    pub fn new(
        field: &AirField,
        view: &dyn SkyView,
        model: &crate::atmosphere::Model,
        observer: Vec3,
    ) -> AirVolume {
        let n = model.channels();
        let up = observer.normalize();
        let east = {
            let e = Vec3::Z.cross(up);
            if e.length() > 1e-9 {
                e.normalize()
            } else {
                Vec3::X
            }
        };
        let frame = [east, up.cross(east), up];
        let ceiling = field.ceiling_radius_m();
        let per_dir = (STEPS + 1) * n;
        let mut values = vec![0.0f32; AZIMUTHS * ELEVATIONS * per_dir];
        let mut reach = vec![0.0; AZIMUTHS * ELEVATIONS];
        values
            .par_chunks_mut(per_dir)
            .zip(reach.par_iter_mut())
            .enumerate()
            .for_each(|(d, (out, reach))| {
                let dir = direction(&frame, d % AZIMUTHS, d / AZIMUTHS);
                let far = ray_sphere(observer, dir, ceiling).map_or(0.0, |(_, f)| f.max(0.0));
                let length = far.min(MAX_DISTANCE_M);
                *reach = length;
                let weights = field.phase_weights(model, dir);
                let groups = &model.groups;
                let (mut sm, mut sa) = ([0.0; MAX_CHANNELS], [0.0; MAX_CHANNELS]);
                let (mut dj, mut t) = ([0.0; MAX_CHANNELS], [0.0; MAX_CHANNELS]);
                let mut sum = [0.0; MAX_CHANNELS];
                for j in 0..STEPS {
                    let (a, b) = (distance(length, j), distance(length, j + 1));
                    let x = observer + 0.5 * (a + b) * dir;
                    let altitude = (x.length() - model.bottom_radius_m).max(0.0);
                    groups.scattering_into(model, MOLECULES, altitude, &mut sm[..n]);
                    groups.scattering_into(model, AEROSOLS, altitude, &mut sa[..n]);
                    field.scattering_change_at(x, &weights, [&sm[..n], &sa[..n]], &mut dj[..n]);
                    if dj[..n].iter().any(|&v| v != 0.0) {
                        view.transmittance_to_point(x, &mut t[..n]);
                        for k in 0..n {
                            sum[k] += t[k] * dj[k] * (b - a);
                        }
                    }
                    for k in 0..n {
                        out[(j + 1) * n + k] = sum[k] as f32;
                    }
                }
            });
        AirVolume {
            observer,
            frame,
            channels: n,
            reach,
            values,
        }
    }

    /// Add ΔS along the ray from the observer in direction `dir` (unit) up to `end` (m;
    /// infinite for the sky) to `out` (per channel).
    pub fn add(&self, dir: Vec3, end: f64, out: &mut [f64]) {
        let n = self.channels;
        let [e, nn, u] = self.frame;
        let elevation = dir.dot(u).clamp(-1.0, 1.0).asin().to_degrees();
        let azimuth = dir
            .dot(e)
            .atan2(dir.dot(nn))
            .rem_euclid(std::f64::consts::TAU);
        let s = elevation.signum() * (elevation.abs() / 90.0).sqrt();
        let row = ((s + 1.0) * 0.5 * (ELEVATIONS - 1) as f64).clamp(0.0, (ELEVATIONS - 1) as f64);
        let col = azimuth / std::f64::consts::TAU * AZIMUTHS as f64;
        let r0 = (row as usize).min(ELEVATIONS - 2);
        let fr = row - r0 as f64;
        let c0 = (col as usize) % AZIMUTHS;
        let fc = col - col.floor();
        let per_dir = (STEPS + 1) * n;
        for (dr, dc, w) in [
            (0, 0, (1.0 - fr) * (1.0 - fc)),
            (0, 1, (1.0 - fr) * fc),
            (1, 0, fr * (1.0 - fc)),
            (1, 1, fr * fc),
        ] {
            if w == 0.0 {
                continue;
            }
            let d = (r0 + dr) * AZIMUTHS + (c0 + dc) % AZIMUTHS;
            let reach = self.reach[d];
            if reach <= 0.0 {
                continue;
            }
            let j = (STEPS as f64 * (end.min(reach) / reach).sqrt()).min(STEPS as f64);
            let j0 = (j as usize).min(STEPS - 1);
            let f = j - j0 as f64;
            let v = &self.values[d * per_dir..(d + 1) * per_dir];
            for k in 0..n {
                let (a, b) = (v[j0 * n + k] as f64, v[(j0 + 1) * n + k] as f64);
                out[k] += w * ((1.0 - f) * a + f * b);
            }
        }
    }

    /// D per direction (m), `row·AZIMUTHS + column` (for a GPU copy of the volume).
    pub fn reach_m(&self) -> &[f64] {
        &self.reach
    }

    /// ΔS at d_0 … d_J per direction, channel-minor: `(direction·(STEPS + 1) + j)·channels
    /// + channel` (W·m⁻²·sr⁻¹·nm⁻¹).
    pub fn values(&self) -> &[f32] {
        &self.values
    }

    /// The observer (m).
    pub fn observer(&self) -> Vec3 {
        self.observer
    }
}

/// The direction of grid column `c`, row `r`.
fn direction(frame: &[Vec3; 3], c: usize, r: usize) -> Vec3 {
    let s = 2.0 * r as f64 / (ELEVATIONS - 1) as f64 - 1.0;
    let elevation = (90.0 * s * s.abs()).to_radians();
    let azimuth = c as f64 / AZIMUTHS as f64 * std::f64::consts::TAU;
    let [e, n, u] = frame;
    let h = elevation.cos();
    (h * azimuth.sin()) * *e + (h * azimuth.cos()) * *n + elevation.sin() * *u
}

/// d_j = D·(j/J)².
fn distance(length: f64, j: usize) -> f64 {
    let f = j as f64 / STEPS as f64;
    length * f * f
}

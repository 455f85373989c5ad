//! The sky-view table (Hillaire 2020 §5.3): for one observer inside the atmosphere and one
//! light, the radiance scattered towards the observer along every direction, in the
//! light-relative (azimuth, zenith) parameterisation of [`super::params::sky_view_uv`],
//! marched once per texel; a view ray then costs one bilinear lookup. Rays that meet the
//! ground end there (the ground's own radiance is the renderer's).

use rayon::prelude::*;

use super::march::{Lighting, MarchRay, Marcher, RayProfile};
use super::params::{sky_view_mu_cos_phi, sky_view_uv};
use crate::math::sphere::{
    distance_to_nearest_atmosphere_boundary, ray_intersects_ground, safe_sqrt,
};
use crate::sky::bruneton4d::Table2;

/// The table for an observer at radius `r` (m) under a light at zenith cosine `mu_s`, per
/// unit light irradiance, `nu` × `nv` texels, `steps` steps per ray.
pub(crate) fn compute(
    marcher: &Marcher,
    r: f64,
    mu_s: f64,
    nu: usize,
    nv: usize,
    steps: usize,
) -> Table2 {
    let model = marcher.medium.model;
    let n = model.channels();
    let (bottom, top) = (model.bottom_radius_m, model.top_radius_m);
    let mut table = Table2::new(nu, nv, n);
    let sin_s = safe_sqrt(1.0 - mu_s * mu_s);
    // Each column's cos φ depends on its u alone: once per table, not per texel (its
    // zenith half is a cosine and an arc cosine, a tenth of the table's time).
    let cos_phi: Vec<f64> = (0..nu)
        .map(|x| sky_view_mu_cos_phi(r, bottom, (x as f64 + 0.5) / nu as f64, 0.5, nu, nv).1)
        .collect();
    table
        .data
        .par_chunks_mut(nu * n)
        .enumerate()
        .for_each(|(y, row)| {
            // The row's rays share their zenith cosine, hence their geometry: one profile,
            // then each column's light.
            let v = (y as f64 + 0.5) / nv as f64;
            let (mu, _) = sky_view_mu_cos_phi(r, bottom, 0.5 / nu as f64, v, nu, nv);
            let ground = ray_intersects_ground(r, mu, bottom);
            let mut ray = MarchRay {
                r,
                mu,
                mu_s,
                nu: 0.0,
                length: distance_to_nearest_atmosphere_boundary(r, mu, bottom, top, ground),
            };
            let mut profile = RayProfile::default();
            marcher.profile_steps_into(&ray, steps, &mut profile);
            let mut phases = Vec::new();
            let mut l = vec![0.0; n];
            let sin_v = safe_sqrt(1.0 - mu * mu);
            for (x, &cos_phi) in cos_phi.iter().enumerate() {
                let view_nu = mu * mu_s + sin_v * sin_s * cos_phi;
                marcher.medium.phases(view_nu, &mut phases);
                ray.nu = view_nu.clamp(-1.0, 1.0);
                marcher.march_profile(&ray, &profile, &phases, &Lighting::ALL, &mut l);
                for k in 0..n {
                    row[x * n + k] = l[k] as f32;
                }
            }
        });
    table
}

/// Radiance per unit light irradiance along (μ, cos φ) from radius `r`, bilinear in the
/// table computed there (see [`compute`]).
#[inline]
pub fn sample(table: &Table2, r: f64, bottom: f64, mu: f64, cos_phi: f64, out: &mut [f64]) {
    let (u, v) = sky_view_uv(r, bottom, mu, cos_phi, table.width, table.height);
    table.sample_into(u, v, out);
}

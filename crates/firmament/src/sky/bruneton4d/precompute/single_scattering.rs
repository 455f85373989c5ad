//! The single-scattering pass (paper eq. 7): molecular and aerosol single scattering
//! integrated apart, without their phase functions.

use std::ops::Range;

use rayon::prelude::*;

use super::ray::RaySamples;
use super::ScatteringGrid;
use super::MAX_CHANNELS;
use crate::atmosphere::{Model, ScatteringGroups};
use crate::sky::bruneton4d::lookup::Lookup;
use crate::sky::bruneton4d::params;
use crate::sky::bruneton4d::table::lerp_weights;

/// The optical-depth table filtered to one radius, for lookups towards the sun from one
/// ray sample at many μ_s.
struct SunRow {
    r: f64,
    rho: f64,
    h: f64,
    cos_h: f64,
    eps: f64,
    row: Vec<f64>,
}

impl SunRow {
    fn new(lookup: &Lookup, r: f64) -> SunRow {
        let radii = &lookup.radii;
        let s = &lookup.sizes;
        let t = lookup.optical_depth;
        let rho = crate::math::sphere::safe_sqrt(r * r - radii.bottom * radii.bottom);
        let v = params::texcoord_from_unit(rho / radii.h(), s.transmittance_r);
        let (y0, y1, ty) = lerp_weights(v, s.transmittance_r);
        let n = t.channels;
        let w = t.width * n;
        let (row0, row1) = (&t.data[y0 * w..][..w], &t.data[y1 * w..][..w]);
        let row = row0
            .iter()
            .zip(row1)
            .map(|(a, b)| (1.0 - ty) * *a as f64 + ty * *b as f64)
            .collect();
        let sin_h = radii.bottom / r;
        SunRow {
            h: radii.h(),
            r,
            rho,
            cos_h: -crate::math::sphere::safe_sqrt(1.0 - sin_h * sin_h),
            eps: sin_h * lookup.sun_angular_radius,
            row,
        }
    }

    /// The filter of [`Lookup::transmittance_to_sun`] at this radius; None when it is zero.
    #[inline]
    fn sun_filter(&self, lookup: &Lookup, mu_s: f64) -> Option<SunFilter> {
        let fraction = crate::math::smoothstep(-self.eps, self.eps, mu_s - self.cos_h);
        if fraction <= 0.0 {
            return None;
        }
        let radii = &lookup.radii;
        let d = crate::math::sphere::distance_to_top_atmosphere_boundary(self.r, mu_s, radii.top);
        let d_min = radii.top - self.r;
        let d_max = self.rho + self.h;
        let x_mu = if d_max > d_min {
            (d - d_min) / (d_max - d_min)
        } else {
            0.0
        };
        let width = lookup.sizes.transmittance_mu;
        let (x0, x1, tx) = lerp_weights(params::texcoord_from_unit(x_mu, width), width);
        Some(SunFilter {
            fraction,
            x0,
            x1,
            tx,
        })
    }
}

/// Where and how much [`SunRow`] is filtered for one μ_s, and the visible solar fraction.
#[derive(Clone, Copy)]
struct SunFilter {
    fraction: f64,
    x0: usize,
    x1: usize,
    tx: f64,
}

/// Single scattering (paper eq. 7; Bruneton 2017 `ComputeSingleScattering`): Rayleigh and
/// Mie integrated separately without phase functions, for the r slices `slices` into
/// `out_rayleigh` and `out_mie` (those slices' part of the tables' data). Each (r, μ) row
/// is computed on its own, so slices computed apart equal the whole pass.
pub(super) fn single_scattering_slices(
    model: &Model,
    lookup: &Lookup,
    grid: &ScatteringGrid,
    groups: &ScatteringGroups,
    slices: Range<usize>,
    out_rayleigh: &mut [f32],
    out_mie: &mut [f32],
) {
    let s = lookup.sizes;
    let n = model.channels();
    let width = s.scattering_nu * s.scattering_mu_s;
    let row_len = width * n;
    debug_assert_eq!(out_rayleigh.len(), slices.len() * s.scattering_mu * row_len);
    let first_row = slices.start * s.scattering_mu;
    out_rayleigh
        .par_chunks_mut(row_len)
        .zip(out_mie.par_chunks_mut(row_len))
        .enumerate()
        .for_each(|(i, (out_r, out_m))| {
            let row = first_row + i;
            let (z, y) = (row / s.scattering_mu, row % s.scattering_mu);
            let (r, mu, _, _, ground) = grid.texel(0, y, z);
            let rays = RaySamples::new(lookup, r, mu, ground, grid.rays.fractions(row), n);
            // Group scattering coefficients at each sample.
            let count = rays.d.len();
            let mut beta = [vec![0.0; count * n], vec![0.0; count * n]];
            for i in 0..count {
                let alt = rays.r[i] - lookup.radii.bottom;
                for group in 0..2 {
                    groups.scattering_into(model, group, alt, &mut beta[group][i * n..(i + 1) * n]);
                }
            }
            // Weights fitted to each group's own β·T.
            let tw = [rays.weights(&beta[0], n), rays.weights(&beta[1], n)];
            let texels: Vec<(f64, f64)> = (0..width)
                .map(|x| {
                    let (_, _, mu_s, nu, _) = grid.texel(x, y, z);
                    (mu_s, nu)
                })
                .collect();
            // Samples outer, texels inner: each sample's transmittance row stays in cache.
            // Per sample, the sun filters of all texels first, then the taps (two short
            // loops overlap better than one long dependent chain).
            let mut acc_r = vec![0.0; width * n];
            let mut acc_m = vec![0.0; width * n];
            let mut sun_filters = vec![None; width];
            let mut tb = [[0.0; MAX_CHANNELS]; 2];
            for i in 0..count {
                let sun_row = SunRow::new(lookup, rays.r[i]);
                let (d_i, inv_r_i) = (rays.d[i], 1.0 / rays.r[i]);
                for k in 0..n {
                    tb[0][k] = tw[0][i * n + k] * beta[0][i * n + k];
                    tb[1][k] = tw[1][i * n + k] * beta[1][i * n + k];
                }
                for (f, &(mu_s, nu)) in sun_filters.iter_mut().zip(&texels) {
                    let mu_s_d = ((r * mu_s + d_i * nu) * inv_r_i).clamp(-1.0, 1.0);
                    *f = sun_row.sun_filter(lookup, mu_s_d);
                }
                let (tb_r, tb_m) = (&tb[0][..n], &tb[1][..n]);
                let row = &sun_row.row;
                for ((ar, am), f) in acc_r
                    .chunks_exact_mut(n)
                    .zip(acc_m.chunks_exact_mut(n))
                    .zip(&sun_filters)
                {
                    let Some(f) = f else { continue };
                    let (t0, t1) = (&row[f.x0 * n..][..n], &row[f.x1 * n..][..n]);
                    for k in 0..n {
                        let t_sun = f.fraction * (-((1.0 - f.tx) * t0[k] + f.tx * t1[k])).exp();
                        ar[k] += tb_r[k] * t_sun;
                        am[k] += tb_m[k] * t_sun;
                    }
                }
            }
            for x in 0..width {
                for k in 0..n {
                    let e = model.solar_irradiance[k];
                    out_r[x * n + k] = (acc_r[x * n + k] * e).max(0.0) as f32;
                    out_m[x * n + k] = (acc_m[x * n + k] * e).max(0.0) as f32;
                }
            }
        });
}

//! The multiple-scattering pass ΔS of order n (paper eq. 12): the scattering density ΔJ
//! integrated along view rays.

use std::ops::Range;

use rayon::prelude::*;

use super::ray::RaySamples;
use super::ScatteringGrid;
use crate::atmosphere::Model;
use crate::math::fast::ln;
use crate::sky::bruneton4d::lookup::Lookup;
use crate::sky::bruneton4d::mu_s_blend::{hermite_exp, tangent, MuSFilter};
use crate::sky::bruneton4d::params;
use crate::sky::bruneton4d::table::{lerp_weights, Table4};

/// Multiple scattering ΔS of order n from ΔJ (paper eq. 12 / Bruneton 2017
/// `ComputeMultipleScattering`), per (r, μ) row: ray samples, their (μ, r) filter weights and
/// transmittances are shared by every (μ_s, ν) texel. For the r slices `slices` into `out`
/// (those slices' part of the table's data; `density` whole, as rays cross the slices);
/// each row on its own, so slices computed apart equal the whole pass.
pub(super) fn multiple_scattering_slices(
    model: &Model,
    lookup: &Lookup,
    grid: &ScatteringGrid,
    density: &Table4,
    slices: Range<usize>,
    out: &mut [f32],
) {
    let s = lookup.sizes;
    let n = model.channels();
    let width = density.width();
    let row_len = density.row_len();
    debug_assert_eq!(out.len(), slices.len() * s.scattering_mu * row_len);
    let first_row = slices.start * s.scattering_mu;
    let radii = lookup.radii;
    let mu_s_positions = super::MuSPositions::new(&radii, s.scattering_mu_s);
    let twilight_cells = lookup.twilight_cells;
    out.par_chunks_mut(row_len).enumerate().for_each(|(i, o)| {
        let row = first_row + i;
        let (z, y) = (row / s.scattering_mu, row % s.scattering_mu);
        let (r, mu, _, _, ground) = grid.texel(0, y, z);
        let rays = RaySamples::new(lookup, r, mu, ground, grid.rays.fractions(row), n);
        let count = rays.d.len();
        // ΔJ is the scattering coefficient times a smooth field: weights fitted to the
        // total β_s·T.
        let mut beta = vec![0.0; count * n];
        for i in 0..count {
            model.scattering_into(rays.r[i] - radii.bottom, &mut beta[i * n..(i + 1) * n]);
        }
        let mut tw = rays.weights(&beta, n);
        // The density table holds ΔJ/β_s (scattering_density.rs): ΔJ at a sample is that,
        // interpolated, times β_s there, folded into the weights.
        tw.iter_mut().zip(&beta).for_each(|(w, b)| *w *= b);
        // Each sample's (μ, r)-filtered row of ΔJ, so a texel's lookup is a bilinear
        // filter in (ν, μ_s) only.
        let row_len = density.row_len();
        let mut blended = Vec::with_capacity(count * row_len);
        for i in 0..count {
            let uvwz = params::scattering_uvwz(&radii, &s, rays.r[i], rays.mu[i], 0.0, 0.0, ground);
            let (y0, y1, ty) = lerp_weights(uvwz[2], s.scattering_mu);
            let (z0, z1, tz) = lerp_weights(uvwz[3], s.scattering_r);
            let (w0, w1, w2, w3) = (
                (1.0 - ty) * (1.0 - tz),
                ty * (1.0 - tz),
                (1.0 - ty) * tz,
                ty * tz,
            );
            let source = |yy, zz| &density.data[density.index(0, yy, zz)..][..row_len];
            let (j0, j1, j2, j3) = (
                source(y0, z0),
                source(y1, z0),
                source(y0, z1),
                source(y1, z1),
            );
            blended.extend(
                j0.iter()
                    .zip(j1)
                    .zip(j2)
                    .zip(j3)
                    .map(|(((v0, v1), v2), v3)| {
                        w0 * *v0 as f64 + w1 * *v1 as f64 + w2 * *v2 as f64 + w3 * *v3 as f64
                    }),
            );
        }
        let nmu_s = s.scattering_mu_s;
        let nnu = s.scattering_nu;
        // ln ΔJ and its tangent (mu_s_blend::tangent) at the μ_s samples the twilight cells
        // read (0 to twilight_cells of each ν column; the next sample for the last
        // tangent), once per ray sample: `[(i·nnu + ν)·tw_s + s]·n + k`.
        let tw_s = (twilight_cells + 1).min(nmu_s);
        let logs: Vec<(f64, f64)> = if twilight_cells == 0 {
            Vec::new()
        } else {
            let mut logs = Vec::with_capacity(count * nnu * tw_s * n);
            let mut ln_column = vec![0.0; (tw_s + 1) * n];
            for i in 0..count {
                for nu in 0..nnu {
                    let start = i * row_len + nu * nmu_s * n;
                    let end = (start + (tw_s + 1) * n).min(start + nmu_s * n);
                    ln_column.iter_mut().for_each(|l| *l = f64::NAN);
                    for (l, v) in ln_column.iter_mut().zip(&blended[start..end]) {
                        *l = ln(*v);
                    }
                    for s in 0..tw_s {
                        for k in 0..n {
                            let prev = if s == 0 {
                                f64::NAN
                            } else {
                                ln_column[(s - 1) * n + k]
                            };
                            let l = ln_column[s * n + k];
                            logs.push((l, tangent(prev, l, ln_column[(s + 1) * n + k])));
                        }
                    }
                }
            }
            logs
        };
        // Per texel: r·μ_s and ν, once.
        let texels: Vec<MultipleTexel> = (0..width)
            .map(|x| {
                let (_, _, mu_s, nu, _) = grid.texel(x, y, z);
                MultipleTexel {
                    r_mu_s: r * mu_s,
                    nu,
                }
            })
            .collect();
        // Samples outer, texels inner: each sample's filtered row stays in cache. Per
        // sample, short loops over all texels rather than one long dependent chain per
        // texel: the sample's (μ_s, u_ν) (plain arithmetic, which vectorises), then the
        // (ν, μ_s) filters (table lookups), then the taps.
        let mut acc = vec![0.0; width * n];
        let mut mu_s_at = vec![0.0; width];
        let mut tex_nu = vec![0.0; width];
        let mut filters = vec![TapFilter::default(); width];
        for i in 0..count {
            let b = &blended[i * row_len..(i + 1) * row_len];
            let (d_i, inv_r_i, mu_i) = (rays.d[i], 1.0 / rays.r[i], rays.mu[i]);
            let wt_t = &tw[i * n..(i + 1) * n];
            for ((m, x), t) in mu_s_at.iter_mut().zip(tex_nu.iter_mut()).zip(&texels) {
                // μ_s at the sample (ν is the same all along the ray); u_ν from the
                // sample's (μ, μ_s, ν).
                let mu_s_i = ((t.r_mu_s + d_i * t.nu) * inv_r_i).clamp(-1.0, 1.0);
                *m = mu_s_i;
                *x = params::u_nu(mu_i, mu_s_i, t.nu) * (nnu - 1) as f64;
            }
            for ((f, &mu_s_i), &tex_x) in filters.iter_mut().zip(&mu_s_at).zip(&tex_nu) {
                let (s0, s1, ts) = mu_s_positions.filter(mu_s_i);
                let nu0 = (tex_x as i32 as usize).min(nnu - 1);
                let nu1 = (nu0 + 1).min(nnu - 1);
                let t_nu = tex_x - nu0 as f64;
                let mu_s = MuSFilter::from_weights(s0, s1, ts, nmu_s, twilight_cells);
                *f = TapFilter {
                    twilight: mu_s.geometric.then_some((mu_s, nu0, nu1, t_nu)),
                    a0: nu0 * nmu_s + s0,
                    a1: nu0 * nmu_s + s1,
                    a2: nu1 * nmu_s + s0,
                    a3: nu1 * nmu_s + s1,
                    w0: (1.0 - t_nu) * (1.0 - ts),
                    w1: (1.0 - t_nu) * ts,
                    w2: t_nu * (1.0 - ts),
                    w3: t_nu * ts,
                };
            }
            let tap = |texel: usize| &b[texel * n..][..n];
            for (a, f) in acc.chunks_exact_mut(n).zip(&filters) {
                let (b0, b1, b2, b3) = (tap(f.a0), tap(f.a1), tap(f.a2), tap(f.a3));
                if let Some((m, nu0, nu1, tn)) = &f.twilight {
                    // A twilight cell: the blend along μ_s of mu_s_blend, then ν.
                    let column = |nu: usize, k: usize| {
                        let at = &logs[(i * nnu + nu) * tw_s * n + k..];
                        let ((l0, m0), (l1, m1)) = (at[m.s0 * n], at[m.s1 * n]);
                        if l0.is_finite() && l1.is_finite() {
                            hermite_exp(l0, l1, m0, m1, m.t)
                        } else {
                            let v = &b[nu * nmu_s * n + k..];
                            v[m.s0 * n] + m.t * (v[m.s1 * n] - v[m.s0 * n])
                        }
                    };
                    for k in 0..n {
                        let j = (1.0 - tn) * column(*nu0, k) + tn * column(*nu1, k);
                        a[k] += wt_t[k] * j;
                    }
                    continue;
                }
                for k in 0..n {
                    let j = f.w0 * b0[k] + f.w1 * b1[k] + f.w2 * b2[k] + f.w3 * b3[k];
                    a[k] += wt_t[k] * j;
                }
            }
        }
        for (o, a) in o.iter_mut().zip(&acc) {
            *o = a.max(0.0) as f32;
        }
    });
}

/// What [`compute_multiple_scattering`] needs of one texel of a row.
struct MultipleTexel {
    /// r·μ_s at the ray origin.
    r_mu_s: f64,
    nu: f64,
}

/// One texel's bilinear (ν, μ_s) filter at one ray sample: texel offsets in the row and
/// weights.
#[derive(Clone, Copy, Default)]
struct TapFilter {
    /// A twilight cell along μ_s: its μ_s filter, the two ν columns and t_ν, blended by
    /// `mu_s_blend`'s Hermite rather than by w0–w3.
    twilight: Option<(MuSFilter, usize, usize, f64)>,
    a0: usize,
    a1: usize,
    a2: usize,
    a3: usize,
    w0: f64,
    w1: f64,
    w2: f64,
    w3: f64,
}

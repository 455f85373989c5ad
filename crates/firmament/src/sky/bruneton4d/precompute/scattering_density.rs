//! The scattering density pass ΔJ (paper eq. 11), by spherical convolution per (r, μ_s):
//! stored as ΔJ/β_s (the multiple-scattering pass multiplies by β_s at its samples); the
//! incident field of the previous order sampled once on a (θ, φ) grid in the sun's frame
//! (`scattering_density_field.wgsl` on the GPU), expanded in azimuthal harmonics and
//! convolved with the phase kernels (`scattering_density.wgsl`).

use std::f64::consts::PI;
use std::ops::Range;

use rayon::prelude::*;

use super::phase_kernels::PhaseKernels;
use super::ScatteringGrid;
use super::{Previous, DENSITY_PHI, DENSITY_THETA, HARMONICS, MAX_CHANNELS};
use crate::atmosphere::{Model, ScatteringGroups};
use crate::math::sphere::{distance_to_bottom_atmosphere_boundary, ray_intersects_ground};
use crate::sky::bruneton4d::lookup::Lookup;
use crate::sky::bruneton4d::table::Table2;

/// Scattering density ΔJ of order n (paper eq. 11 / Bruneton 2017
/// `ComputeScatteringDensity`), by spherical convolution per (r, μ_s), for the r slices
/// `slices` into `out` (those slices' part of the table's data). Parallel over the (r, μ_s)
/// pairs, each computed on its own, so slices computed apart equal the whole pass.
#[allow(clippy::too_many_arguments)]
pub(super) fn scattering_density_slices(
    model: &Model,
    lookup: &Lookup,
    grid: &ScatteringGrid,
    groups: &ScatteringGroups,
    kernels: &PhaseKernels,
    previous: &Previous,
    delta_irradiance: &Table2,
    slices: Range<usize>,
    out: &mut [f32],
) {
    let s = lookup.sizes;
    let n = model.channels();
    let width = s.scattering_nu * s.scattering_mu_s;
    let slab = s.scattering_mu * width * n;
    debug_assert_eq!(out.len(), slices.len() * slab);
    let radii = lookup.radii;
    let dtheta = PI / DENSITY_THETA as f64;
    let dphi = 2.0 * PI / DENSITY_PHI as f64;
    let half_phi = DENSITY_PHI / 2;
    // Cosine series of the even field: c_0 = (2/N)Σ_half, c_m = (4/N)Σ_half cos(mφ_j);
    // `[j][m]`, so that a sample adds to all harmonics at once.
    let cos_table: Vec<f64> = (0..half_phi)
        .flat_map(|j| {
            (0..HARMONICS).map(move |m| {
                let scale = if m == 0 { 2.0 } else { 4.0 } / DENSITY_PHI as f64;
                scale * (m as f64 * (j as f64 + 0.5) * dphi).cos()
            })
        })
        .collect();
    let nmu_s = s.scattering_mu_s;
    let column_len = s.scattering_mu * s.scattering_nu * n;
    // One (r, μ_s) column per task, `[y][ν][channel]`, then scattered into the slices.
    let columns: Vec<Vec<f32>> = (0..slices.len() * nmu_s)
        .into_par_iter()
        .map(|pair| {
            let (z, i_mu_s) = (slices.start + pair / nmu_s, pair % nmu_s);
            let mut column = vec![0.0f32; column_len];
            let (r, _, _, _, _) = grid.texel(0, 0, z);
            let alt = r - radii.bottom;
            let mut beta = [vec![0.0; n], vec![0.0; n]];
            for group in 0..2 {
                groups.scattering_into(model, group, alt, &mut beta[group]);
            }
            // The table holds ΔJ/β_s, each group's share of the total β_s in place of its
            // β_s: ΔJ falls with the scatterers' density, which the multiple-scattering
            // pass's linear interpolation between r rows overestimates (rows 0.57 km apart
            // at 1 km over Earth, `hazy`'s aerosol scale height 1.5 km: up to +1.8 %); the
            // ratio is smooth, and that pass multiplies by β_s at each ray sample.
            for k in 0..n {
                let total = beta[0][k] + beta[1][k];
                for b in &mut beta {
                    b[k] = if total > 0.0 { b[k] / total } else { 0.0 };
                }
            }
            let mut radiance = vec![0.0; n];
            let mut tmp = vec![0.0; n];
            let mut e_ground = vec![0.0; n];
            let mut t_ground = vec![0.0; n];
            // Coefficients `[l][k][m]`, harmonics innermost for the series and the
            // convolution; convolved `[group][m][k]`, channels innermost for the evaluation.
            let mut coeff = vec![0.0; DENSITY_THETA * n * HARMONICS];
            let mut k_acc = vec![0.0; 2 * HARMONICS * n];
            let mut j_out = [0.0f64; MAX_CHANNELS];
            let mut harmonic = [0.0f64; HARMONICS];
            let (_, _, mu_s, _, _) = grid.texel(i_mu_s, 0, z);
            let sin_s = (1.0 - mu_s * mu_s).max(0.0).sqrt();
            for l in 0..DENSITY_THETA {
                let theta = (l as f64 + 0.5) * dtheta;
                let (sin_i, cos_i) = theta.sin_cos();
                let ground = ray_intersects_ground(r, cos_i, radii.bottom);
                let d_ground = if ground {
                    distance_to_bottom_atmosphere_boundary(r, cos_i, radii.bottom)
                } else {
                    0.0
                };
                if ground {
                    lookup.transmittance(r, cos_i, d_ground, true, &mut t_ground);
                }
                let c_l = &mut coeff[l * n * HARMONICS..(l + 1) * n * HARMONICS];
                for j in 0..half_phi {
                    let phi = (j as f64 + 0.5) * dphi;
                    let (sin_p, cos_p) = phi.sin_cos();
                    let w_i = [cos_p * sin_i, sin_p * sin_i, cos_i];
                    let nu_i = (w_i[0] * sin_s + w_i[2] * mu_s).clamp(-1.0, 1.0);
                    previous.radiance(
                        lookup,
                        r,
                        cos_i,
                        mu_s,
                        nu_i,
                        ground,
                        &mut radiance,
                        &mut tmp,
                    );
                    if ground {
                        // Light reflected by the Lambertian ground: T·(α/π)·ΔE(n·ω_s).
                        let p = [d_ground * w_i[0], d_ground * w_i[1], r + d_ground * w_i[2]];
                        let len = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
                        let mu_g = (p[0] * sin_s + p[2] * mu_s) / len;
                        lookup.irradiance(
                            delta_irradiance,
                            radii.bottom,
                            mu_g.clamp(-1.0, 1.0),
                            &mut e_ground,
                        );
                        for k in 0..n {
                            radiance[k] += t_ground[k] * model.ground_albedo[k] / PI * e_ground[k];
                        }
                    }
                    // The sample's share of every harmonic's coefficient.
                    let w_j = &cos_table[j * HARMONICS..(j + 1) * HARMONICS];
                    for (c, &v) in c_l.chunks_exact_mut(HARMONICS).zip(&radiance) {
                        for (c, w) in c.iter_mut().zip(w_j) {
                            *c += w * v;
                        }
                    }
                }
            }
            // Convolve with the phase harmonics (solid angle included) for every view
            // zenith, then evaluate at ν.
            for y in 0..s.scattering_mu {
                let kb = &kernels.b[(z * s.scattering_mu + y) * DENSITY_THETA * 2 * HARMONICS..];
                for group in 0..2 {
                    if groups.members[group].is_empty() {
                        continue;
                    }
                    for k in 0..n {
                        // All harmonics at once, summed over the incident zeniths (the
                        // accumulator stays in registers).
                        let mut acc = [0.0; HARMONICS];
                        for l in 0..DENSITY_THETA {
                            let b = &kb[(l * 2 + group) * HARMONICS..][..HARMONICS];
                            let c = &coeff[(l * n + k) * HARMONICS..][..HARMONICS];
                            for ((a, b), c) in acc.iter_mut().zip(b).zip(c) {
                                *a += b * c;
                            }
                        }
                        for (m, a) in acc.into_iter().enumerate() {
                            k_acc[(group * HARMONICS + m) * n + k] = a;
                        }
                    }
                }
                for i_nu in 0..s.scattering_nu {
                    let x = i_nu * s.scattering_mu_s + i_mu_s;
                    let (_, mu_v, _, nu, _) = grid.texel(x, y, z);
                    let sin_v = (1.0 - mu_v * mu_v).max(0.0).sqrt();
                    let denom = sin_v * sin_s;
                    let cos_phi_v = if denom > 1e-12 {
                        ((nu - mu_v * mu_s) / denom).clamp(-1.0, 1.0)
                    } else {
                        1.0
                    };
                    // 2π for m = 0, π·cos(mφ_v) otherwise (Chebyshev recurrence).
                    harmonic[0] = 2.0 * PI;
                    harmonic[1] = PI * cos_phi_v;
                    let (mut c0, mut c1) = (1.0, cos_phi_v);
                    for h in harmonic.iter_mut().skip(2) {
                        let c2 = 2.0 * cos_phi_v * c1 - c0;
                        *h = PI * c2;
                        c0 = c1;
                        c1 = c2;
                    }
                    let j = &mut j_out[..n];
                    j.iter_mut().for_each(|v| *v = 0.0);
                    for group in 0..2 {
                        if groups.members[group].is_empty() {
                            continue;
                        }
                        for (m, w) in harmonic.iter().enumerate() {
                            let acc = &k_acc[(group * HARMONICS + m) * n..][..n];
                            for ((j, a), b) in j.iter_mut().zip(acc).zip(&beta[group]) {
                                *j += w * a * b;
                            }
                        }
                    }
                    let o = &mut column[(y * s.scattering_nu + i_nu) * n..][..n];
                    for (o, j) in o.iter_mut().zip(j.iter()) {
                        *o = *j as f32;
                    }
                }
            }
            column
        })
        .collect();
    for (pair, column) in columns.iter().enumerate() {
        let (z, i_mu_s) = (pair / nmu_s, pair % nmu_s);
        let slab_out = &mut out[z * slab..(z + 1) * slab];
        for y in 0..s.scattering_mu {
            for i_nu in 0..s.scattering_nu {
                let x = i_nu * nmu_s + i_mu_s;
                slab_out[(y * width + x) * n..][..n]
                    .copy_from_slice(&column[(y * s.scattering_nu + i_nu) * n..][..n]);
            }
        }
    }
}

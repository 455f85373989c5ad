//! The multiple-scattering pass ΔS_n (Bruneton & Neyret 2008 eq. 12) in 3D:
//! ΔS̄_n(r, μ, μ_s) = ∫ T(0, t)·Σ_g β_g(t)·mean_φ G_g(r_t, μ_t, μ_s(t, φ)) dt, with the sun's
//! zenith cosine at the sample, μ_s·cos α + √(1−μ_s²)·sin α·cos φ, averaged over the
//! view–sun azimuth φ by the midpoint rule (the density itself has no azimuth left: the 3D
//! table's approximation).

use std::f64::consts::PI;

use rayon::prelude::*;

use super::kernels::sine;
use super::params::{Params, SunZenithPositions};
use super::ray::TableRays;
use super::table::Table3;
use crate::atmosphere::Model;
use crate::sky::bruneton4d::table::lerp_weights;

/// ΔS̄_n from the density `g` (per group, per unit β_g), one (altitude, view zenith) row
/// per task.
pub(super) fn compute_multiple_scattering(
    model: &Model,
    params: &Params,
    rays: &TableRays,
    g: &[Table3; 2],
    azimuth_nodes: usize,
) -> Table3 {
    let n = model.channels();
    let mut out = Table3::new(params.nh, params.nmu, params.nmu_s, n);
    let row_len = out.row_len();
    let positions = SunZenithPositions::new(params);
    // Midpoint nodes in azimuth: cos φ_j and the weight 1/N, for N = 1, 2 and
    // `azimuth_nodes` (the fewer where the suns of one sample's azimuths lie close).
    let midpoint = |count: usize| -> (Vec<f64>, f64) {
        let nodes = (0..count)
            .map(|j| (PI * (j as f64 + 0.5) / count as f64).cos())
            .collect();
        (nodes, 1.0 / count as f64)
    };
    let rules = [
        midpoint(1),
        midpoint(2.min(azimuth_nodes)),
        midpoint(azimuth_nodes),
    ];
    // Per μ_s texel: μ_s, √(1 − μ_s²) and the texel positions per unit μ_s there, to see
    // whether the suns of one sample's azimuths spread over a texel at all.
    let mu_s: Vec<(f64, f64, f64)> = (0..params.nmu_s)
        .map(|x| {
            let m = params.texel_mu_s(x);
            let h = 1e-4;
            let slope = (params.u_mu_s((m + h).min(1.0)) - params.u_mu_s(m - h)) / (2.0 * h);
            (m, sine(m), slope.abs() * params.nmu_s as f64)
        })
        .collect();
    let present = [model.groups.present(0), model.groups.present(1)];
    out.data
        .par_chunks_mut(row_len)
        .enumerate()
        .for_each(|(row, o)| {
            rays.with_row(row, |rays| {
                let ground = rays.ground;
                // Σ_g w_g·G_g at the sample, (z, y)-filtered, for every μ_s texel; the weights
                // repeated over the row so that the taps are flat loops.
                let mut blended = vec![0.0; row_len];
                let mut weights = vec![0.0; row_len];
                let mut acc = vec![0.0; row_len];
                for i in 0..rays.len() {
                    let (r_i, mu_i) = (rays.r[i], rays.mu[i]);
                    let (z0, z1, tz) = lerp_weights(params.u_h(r_i), params.nh);
                    let (y0, y1, ty) = lerp_weights(params.u_mu(r_i, mu_i, ground), params.nmu);
                    let taps = [
                        (z0, y0, (1.0 - tz) * (1.0 - ty)),
                        (z0, y1, (1.0 - tz) * ty),
                        (z1, y0, tz * (1.0 - ty)),
                        (z1, y1, tz * ty),
                    ];
                    blended.iter_mut().for_each(|v| *v = 0.0);
                    let mut any = false;
                    for group in 0..2 {
                        let w = &rays.weights[group][i * n..][..n];
                        if !present[group] || w.iter().all(|&v| v == 0.0) {
                            continue;
                        }
                        any = true;
                        // Repeated by doubling: a few copies rather than one per texel.
                        weights[..n].copy_from_slice(w);
                        let mut filled = n;
                        while filled < row_len {
                            let len = filled.min(row_len - filled);
                            weights.copy_within(..len, filled);
                            filled += len;
                        }
                        let table = &g[group];
                        for &(zz, yy, wt) in &taps {
                            if wt == 0.0 {
                                continue;
                            }
                            let source = &table.data[table.index(zz, yy, 0)..][..row_len];
                            for ((b, s), w) in blended.iter_mut().zip(source).zip(&weights) {
                                *b += wt * w * *s as f64;
                            }
                        }
                    }
                    if !any {
                        continue;
                    }
                    let (cos_a, sin_a) = (rays.cos_alpha[i], rays.sin_alpha[i]);
                    for (a, &(m, s, slope)) in acc.chunks_exact_mut(n).zip(&mu_s) {
                        let (c0, c1) = (m * cos_a, s * sin_a);
                        // Suns spread over less than a quarter texel read one value, over less
                        // than one texel two.
                        let spread = 2.0 * c1 * slope;
                        let (nodes, scale) = &rules[if spread < 0.25 {
                            0
                        } else if spread < 1.0 {
                            1
                        } else {
                            2
                        }];
                        for c in nodes {
                            let (s0, s1, t) = positions.filter(c0 + c1 * c);
                            let (b0, b1) = (&blended[s0 * n..][..n], &blended[s1 * n..][..n]);
                            for ((a, b0), b1) in a.iter_mut().zip(b0).zip(b1) {
                                *a += scale * ((1.0 - t) * b0 + t * b1);
                            }
                        }
                    }
                }
                for (o, a) in o.iter_mut().zip(&acc) {
                    *o = a.max(0.0) as f32;
                }
            })
        });
    out
}

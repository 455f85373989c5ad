//! The scattering density of order n (Bruneton & Neyret 2008 eq. 11), averaged over the
//! view–sun azimuth: J̄_n(r, μ, μ_s) = Σ_g β_g(r)·G_g(r, μ, μ_s) with
//! G_g = ∫ K_g(μ, μ′) L̄_{n−1}(r, μ′, μ_s) dμ′ ([`super::kernels`]), L̄ the previous order's
//! radiance averaged over azimuth plus, below the horizon, the ground's reflection of the
//! order before (T·(α/π)·ΔE at the ground point, averaged over the azimuth of the
//! incident direction). G is stored per group, per unit scattering coefficient: the ray
//! integral multiplies it by β_g at each sample, exactly, where a table of J would be
//! interpolated across the aerosols' 1.2 km scale height.

use std::f64::consts::PI;

use rayon::prelude::*;

use super::kernels::{column_filter, sine, Gather};
use super::params::Params;
use super::table::Table3;
use crate::atmosphere::Model;
use crate::math::sphere::distance_to_bottom_atmosphere_boundary;
use crate::sky::bruneton4d::{Lookup, Table2};

/// The radiance field of the previous order.
pub(super) enum Field<'a> {
    /// Order 1: the phase-free single scattering; its azimuthal mean is
    /// Σ_g S₃,g·K_g(μ′, μ_s)/(2π).
    Single {
        /// Molecular group.
        rayleigh: &'a Table3,
        /// Aerosol group.
        mie: &'a Table3,
    },
    /// Order ≥ 2: the azimuth-averaged radiance as it is.
    Multiple(&'a Table3),
}

/// G_g (per group, per unit β_g) of the order after `field`, with the ground reflecting
/// `ground_irradiance` (the irradiance of the order before `field`'s, or the sun's for
/// order 2). One altitude texel per task.
#[allow(clippy::too_many_arguments)]
pub(super) fn compute_density(
    model: &Model,
    lookup: &Lookup,
    params: &Params,
    gather: &Gather,
    field: &Field,
    ground_irradiance: &Table2,
    azimuth_nodes: usize,
) -> [Table3; 2] {
    let n = model.channels();
    let (nmu, nmu_s, count) = (params.nmu, params.nmu_s, gather.count);
    let mut out = [
        Table3::new(params.nh, nmu, nmu_s, n),
        Table3::new(params.nh, nmu, nmu_s, n),
    ];
    let slab = nmu * nmu_s * n;
    let cos_phi: Vec<f64> = (0..azimuth_nodes)
        .map(|j| (PI * (j as f64 + 0.5) / azimuth_nodes as f64).cos())
        .collect();
    let [out_r, out_m] = &mut out;
    out_r
        .data
        .par_chunks_mut(slab)
        .zip(out_m.data.par_chunks_mut(slab))
        .enumerate()
        .for_each(|(z, (slab_r, slab_m))| {
            let r = params.texel_r(z);
            let row = nmu_s * n;
            // L̄(μ′_l, μ_s,x) per node: `[(l·nmu_s + x)·n + k]`.
            let mut incident = vec![0.0; count * row];
            let mut t_ground = vec![0.0; n];
            let mut e = vec![0.0; n];
            let mut e_mean = vec![0.0; n];
            for l in 0..count {
                let i = z * count + l;
                let (mu, ground) = (gather.mu[i], gather.ground[i]);
                let (y0, y1, t) = column_filter(params, r, mu, ground);
                let o = &mut incident[l * row..(l + 1) * row];
                let lerp = |table: &Table3, x: usize, k: usize| {
                    let (a, b) = (table.index(z, y0, x), table.index(z, y1, x));
                    (1.0 - t) * table.data[a + k] as f64 + t * table.data[b + k] as f64
                };
                for x in 0..nmu_s {
                    for k in 0..n {
                        o[x * n + k] = match field {
                            Field::Single { rayleigh, mie } => {
                                lerp(rayleigh, x, k) * gather.sun[0][i * nmu_s + x]
                                    + lerp(mie, x, k) * gather.sun[1][i * nmu_s + x]
                            }
                            Field::Multiple(table) => lerp(table, x, k),
                        };
                    }
                }
                if !ground {
                    continue;
                }
                // The Lambertian ground at distance d: T·(α/π)·ΔE(μ_g), with μ_g the sun's
                // zenith cosine there, μ_s·cos α_g + √(1−μ_s²)·sin α_g·cos φ′, averaged
                // over the incident azimuth φ′ by the midpoint rule.
                let d = distance_to_bottom_atmosphere_boundary(r, mu, params.bottom);
                lookup.transmittance(r, mu, d, true, &mut t_ground);
                let cos_g = ((r + d * mu) / params.bottom).clamp(-1.0, 1.0);
                let sin_g = (d * sine(mu) / params.bottom).clamp(0.0, 1.0);
                for x in 0..nmu_s {
                    let mu_s = params.texel_mu_s(x);
                    let (a, b) = (mu_s * cos_g, sine(mu_s) * sin_g);
                    e_mean.iter_mut().for_each(|v| *v = 0.0);
                    for c in &cos_phi {
                        let mu_g = (a + b * c).clamp(-1.0, 1.0);
                        lookup.irradiance(ground_irradiance, params.bottom, mu_g, &mut e);
                        for (m, v) in e_mean.iter_mut().zip(&e) {
                            *m += v / cos_phi.len() as f64;
                        }
                    }
                    for k in 0..n {
                        o[x * n + k] += t_ground[k] * model.ground_albedo[k] / PI * e_mean[k];
                    }
                }
            }
            // G_g(μ_y, ·) = Σ_l kernel_g[y][l]·L̄(μ′_l, ·).
            for (group, slab) in [slab_r, slab_m].into_iter().enumerate() {
                if !model.groups.present(group) {
                    continue;
                }
                let mut acc = vec![0.0; row];
                for (y, o) in slab.chunks_exact_mut(row).enumerate() {
                    acc.iter_mut().for_each(|v| *v = 0.0);
                    let weights = &gather.view[group][(z * nmu + y) * count..][..count];
                    for (w, l) in weights.iter().zip(incident.chunks_exact(row)) {
                        for (a, v) in acc.iter_mut().zip(l) {
                            *a += w * v;
                        }
                    }
                    for (o, a) in o.iter_mut().zip(&acc) {
                        *o = a.max(0.0) as f32;
                    }
                }
            }
        });
    out
}

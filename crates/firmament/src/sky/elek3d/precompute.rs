//! The precomputation (Bruneton & Neyret 2008 Algorithm 4.1 in three dimensions):
//! transmittance (the 4D tables' pass), the sun's cone-averaged transmittance, single
//! scattering, then for each order n ≥ 2 the density J̄_n, the sky's irradiance ΔE_{n−1}
//! and the multiple scattering ΔS̄_n, and the geometric tail of the orders beyond the last.

use std::f64::consts::PI;

use super::config::Elek3dConfig;
use super::density::{compute_density, Field};
use super::irradiance::{direct_irradiance, indirect_irradiance};
use super::kernels::{Gather, PhaseKernels};
use super::multiple::compute_multiple_scattering;
use super::params::Params;
use super::ray::TableRays;
use super::single::compute_single_scattering;
use super::sun_cone::SunCone;
use super::table::Table3;
use crate::atmosphere::Model;
use crate::sky::bruneton4d::precompute::{compute_optical_depth_in, order_tail_factors};
use crate::sky::bruneton4d::{Lookup, Table2};

/// What [`precompute`] produces.
pub(super) struct Precomputed {
    pub optical_depth: Table2,
    pub single_rayleigh: Table3,
    pub single_mie: Table3,
    pub multiple: Table3,
    pub irradiance: Table2,
    pub order_means: Vec<Vec<f64>>,
}

/// Run every pass for `model` (config already validated).
pub(super) fn precompute(model: &Model, config: &Elek3dConfig) -> Precomputed {
    let n = model.channels();
    let sizes = config.table_sizes();
    let optical_depth = compute_optical_depth_in(model, &sizes, config.transmittance_segments);
    let lookup = Lookup::new(model, sizes, &optical_depth);
    let params = Params::new(model, config);
    let (cone_r, cone_alpha) = config.sun_cone;
    let cone = SunCone::new(&lookup, &params, cone_r, cone_alpha, config.azimuth_nodes);
    let rays = TableRays::new(model, &lookup, &params, config.ray_steps);
    let (single_rayleigh, single_mie) = compute_single_scattering(model, &params, &rays, &cone);
    let kernels = PhaseKernels::new(&model.groups);
    let mut order_means = vec![single_mean(
        &params,
        &kernels,
        &single_rayleigh,
        &single_mie,
    )];
    let mut multiple = single_rayleigh.like();
    let mut irradiance = Table2::new(config.irradiance.0, config.irradiance.1, n);
    if config.orders >= 2 {
        let gather = Gather::new(&params, &kernels, config.gather_nodes);
        let mut delta_irradiance = direct_irradiance(model, &lookup);
        let mut delta_multiple = single_rayleigh.like();
        for order in 2..=config.orders {
            let field = if order == 2 {
                Field::Single {
                    rayleigh: &single_rayleigh,
                    mie: &single_mie,
                }
            } else {
                Field::Multiple(&delta_multiple)
            };
            let density = compute_density(
                model,
                &lookup,
                &params,
                &gather,
                &field,
                &delta_irradiance,
                config.multiple_azimuth_nodes,
            );
            // The irradiance of the previous order lights the ground of the next density.
            delta_irradiance = indirect_irradiance(model, &lookup, &params, &kernels, &field);
            irradiance.add_assign(&delta_irradiance);
            delta_multiple = compute_multiple_scattering(
                model,
                &params,
                &rays,
                &density,
                config.multiple_azimuth_nodes,
            );
            order_means.push(delta_multiple.mean());
            multiple.add_assign(&delta_multiple);
        }
        if config.order_tail {
            if let Some(mut f) = order_tail_factors(&order_means) {
                cap_by_energy(
                    &mut f,
                    &irradiance,
                    &delta_irradiance,
                    &model.solar_irradiance,
                );
                add_scaled(&mut multiple.data, &delta_multiple.data, &f);
                add_scaled(&mut irradiance.data, &delta_irradiance.data, &f);
            }
        }
    }
    Precomputed {
        optical_depth,
        single_rayleigh,
        single_mie,
        multiple,
        irradiance,
        order_means,
    }
}

/// Mean over the texels of the single-scattering field's azimuthal mean,
/// Σ_g S₃,g·K_g(μ, μ_s)/(2π), per channel (the first of the order means).
fn single_mean(
    params: &Params,
    kernels: &PhaseKernels,
    rayleigh: &Table3,
    mie: &Table3,
) -> Vec<f64> {
    let n = rayleigh.channels;
    let mut sum = vec![0.0; n];
    for z in 0..params.nh {
        let r = params.texel_r(z);
        for y in 0..params.nmu {
            let (mu, _) = params.texel_mu(r, y);
            for x in 0..params.nmu_s {
                let mu_s = params.texel_mu_s(x);
                let (kr, km) = (kernels.eval(0, mu, mu_s), kernels.eval(1, mu, mu_s));
                let i = rayleigh.index(z, y, x);
                for k in 0..n {
                    sum[k] += (rayleigh.data[i + k] as f64 * kr + mie.data[i + k] as f64 * km)
                        / (2.0 * PI);
                }
            }
        }
    }
    let count = (params.nh * params.nmu * params.nmu_s) as f64;
    sum.iter().map(|s| s / count).collect()
}

/// Caps the tail factors so that no texel of the sky's irradiance passes the sun's outside
/// the air (the 4D tables' bound, `bruneton4d::precompute::order_tail`: no surface under a
/// sourceless sky receives more than the sun delivers to one facing it).
fn cap_by_energy(f: &mut [f64], irradiance: &Table2, last: &Table2, solar: &[f64]) {
    let n = f.len();
    for (sum, delta) in irradiance.data.chunks(n).zip(last.data.chunks(n)) {
        for k in 0..n {
            let room = (solar[k] - sum[k] as f64).max(0.0);
            if delta[k] > 0.0 {
                f[k] = f[k].min(room / delta[k] as f64);
            }
        }
    }
}

/// a += b·f[channel], channels innermost.
fn add_scaled(a: &mut [f32], b: &[f32], f: &[f64]) {
    let n = f.len();
    for (i, (a, b)) in a.iter_mut().zip(b).enumerate() {
        *a = (*a as f64 + *b as f64 * f[i % n]) as f32;
    }
}

//! The irradiance passes on the 4D tables' irradiance grid (linear in r and μ_s): the sun's
//! direct irradiance on a horizontal surface (the first ground bounce) and the sky's, ΔE_n
//! (Bruneton & Neyret 2008 eq. 15). The sky's is exact for the 3D table's field: a
//! horizontal surface sees the azimuthal mean of the radiance only,
//! E(r, μ_s) = 2π∫₀¹ L̄(r, μ′, μ_s)·μ′ dμ′.

use std::f64::consts::PI;

use rayon::prelude::*;

use super::density::Field;
use super::kernels::PhaseKernels;
use super::params::Params;
use crate::atmosphere::Model;
use crate::math::quadrature::GaussLegendreRule;
use crate::sky::bruneton4d::params::irradiance_texel;
use crate::sky::bruneton4d::{Lookup, Table2};

/// Gauss–Legendre nodes of μ′ over [0, 1] for the sky's irradiance.
const IRRADIANCE_NODES: usize = 32;

/// The sun's irradiance on a horizontal surface, E_sun·T·(mean cosine over the part of the
/// disk above the horizon) (Bruneton 2017 `ComputeDirectIrradiance`).
pub(super) fn direct_irradiance(model: &Model, lookup: &Lookup) -> Table2 {
    let s = &lookup.sizes;
    let n = model.channels();
    let mut e = Table2::new(s.irradiance_mu_s, s.irradiance_r, n);
    let alpha = model.sun_angular_radius_rad;
    let mut t = vec![0.0; n];
    for (i, o) in e.data.chunks_exact_mut(n).enumerate() {
        let (r, mu_s) = irradiance_texel(
            &lookup.radii,
            s,
            i % s.irradiance_mu_s,
            i / s.irradiance_mu_s,
        );
        let cosine = if mu_s < -alpha {
            0.0
        } else if mu_s > alpha {
            mu_s
        } else {
            (mu_s + alpha) * (mu_s + alpha) / (4.0 * alpha)
        };
        lookup.transmittance_to_top(r, mu_s, &mut t);
        for k in 0..n {
            o[k] = (model.solar_irradiance[k] * t[k] * cosine) as f32;
        }
    }
    e
}

/// The sky's irradiance ΔE on a horizontal surface from the radiance `field`.
pub(super) fn indirect_irradiance(
    model: &Model,
    lookup: &Lookup,
    params: &Params,
    kernels: &PhaseKernels,
    field: &Field,
) -> Table2 {
    let s = &lookup.sizes;
    let n = model.channels();
    let mut e = Table2::new(s.irradiance_mu_s, s.irradiance_r, n);
    let rule = GaussLegendreRule::new(IRRADIANCE_NODES);
    let nodes: Vec<(f64, f64)> = rule.on(0.0, 1.0).collect();
    e.data.par_chunks_mut(n).enumerate().for_each(|(i, o)| {
        let (r, mu_s) = irradiance_texel(
            &lookup.radii,
            s,
            i % s.irradiance_mu_s,
            i / s.irradiance_mu_s,
        );
        let mut a = vec![0.0; n];
        let mut b = vec![0.0; n];
        let mut acc = vec![0.0; n];
        for &(mu, w) in &nodes {
            let u = params.coords(r, mu, mu_s, false);
            match field {
                Field::Single { rayleigh, mie } => {
                    let taps = rayleigh.taps(u);
                    rayleigh.sample_taps_into(&taps, &mut a);
                    mie.sample_taps_into(&taps, &mut b);
                    let (kr, km) = (kernels.eval(0, mu, mu_s), kernels.eval(1, mu, mu_s));
                    for k in 0..n {
                        // 2π·L̄ = Σ_g S₃,g·K_g.
                        acc[k] += w * mu * (a[k] * kr + b[k] * km);
                    }
                }
                Field::Multiple(table) => {
                    table.sample_into(u, &mut a);
                    for k in 0..n {
                        acc[k] += w * mu * 2.0 * PI * a[k];
                    }
                }
            }
        }
        for k in 0..n {
            o[k] = acc[k].max(0.0) as f32;
        }
    });
    e
}

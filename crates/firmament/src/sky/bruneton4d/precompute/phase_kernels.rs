//! The phase functions' azimuthal harmonics, computed once for every order of the
//! scattering density.

use std::f64::consts::PI;

use rayon::prelude::*;

use super::ScatteringGrid;
use super::{DENSITY_THETA, HARMONICS, KERNEL_STEPS};
use crate::atmosphere::ScatteringGroups;
use crate::sky::bruneton4d::lookup::Lookup;

/// Azimuthal harmonics of each scattering group's phase function, for every table radius,
/// view zenith (table μ) and incident zenith: b_m with P(Δφ) = Σ b_m cos(mΔφ), times the
/// solid angle of the incident zenith band's quadrature (dθ·sin θ_l).
pub(super) struct PhaseKernels {
    /// `[((z·nmu + y)·THETA + l)·2 + group]·HARMONICS + m`.
    pub b: Vec<f64>,
}

impl PhaseKernels {
    pub fn new(lookup: &Lookup, grid: &ScatteringGrid, groups: &ScatteringGroups) -> PhaseKernels {
        let s = &lookup.sizes;
        let per_row = DENSITY_THETA * 2 * HARMONICS;
        let dtheta = PI / DENSITY_THETA as f64;
        // cos(Δφ_t) and cos(m·Δφ_t) on the trapezoid nodes, shared by every row.
        let cos_t: Vec<f64> = (0..=KERNEL_STEPS)
            .map(|t| (PI * t as f64 / KERNEL_STEPS as f64).cos())
            .collect();
        let cos_m: Vec<f64> = (0..=KERNEL_STEPS)
            .flat_map(|t| {
                let dphi = PI * t as f64 / KERNEL_STEPS as f64;
                (0..HARMONICS).map(move |m| (m as f64 * dphi).cos())
            })
            .collect();
        let mut b = vec![0.0; s.scattering_r * s.scattering_mu * per_row];
        b.par_chunks_mut(per_row)
            .enumerate()
            .for_each(|(row, out)| {
                let (z, y) = (row / s.scattering_mu, row % s.scattering_mu);
                let (_, mu_v, _, _, _) = grid.texel(0, y, z);
                let sin_v = (1.0 - mu_v * mu_v).max(0.0).sqrt();
                for l in 0..DENSITY_THETA {
                    let theta = (l as f64 + 0.5) * dtheta;
                    let (sin_i, cos_i) = theta.sin_cos();
                    let solid = dtheta * theta.sin();
                    for group in 0..2 {
                        if groups.members[group].is_empty() {
                            continue;
                        }
                        let o =
                            &mut out[(l * 2 + group) * HARMONICS..(l * 2 + group + 1) * HARMONICS];
                        for (t, &cos_dphi) in cos_t.iter().enumerate() {
                            let p = groups.phase[group]
                                .eval((mu_v * cos_i + sin_v * sin_i * cos_dphi).clamp(-1.0, 1.0));
                            let w = if t == 0 || t == KERNEL_STEPS {
                                0.5
                            } else {
                                1.0
                            };
                            let wp = w * p;
                            for (o, c) in o.iter_mut().zip(&cos_m[t * HARMONICS..][..HARMONICS]) {
                                *o += wp * c;
                            }
                        }
                        // Trapezoid over [0, π]: b_0 = (1/π)∫P, b_m = (2/π)∫P cos(mΔ).
                        let h = PI / KERNEL_STEPS as f64;
                        for m in 0..HARMONICS {
                            o[m] *= h / PI * if m == 0 { 1.0 } else { 2.0 };
                            o[m] *= solid;
                        }
                    }
                }
            });
        PhaseKernels { b }
    }
}

//! The phase functions' azimuthal harmonics, computed once for every order of the
//! scattering density.

use std::f64::consts::PI;

use std::ops::Range;

use rayon::prelude::*;

use super::ScatteringGrid;
use super::{DENSITY_THETA, HARMONICS, KERNEL_STEPS};
use crate::atmosphere::ScatteringGroups;
use crate::sky::bruneton4d::lookup::Lookup;
use crate::sky::bruneton4d::params::TableSizes;

/// Azimuthal harmonics of each scattering group's phase function, for every table radius,
/// view zenith (table μ) and incident zenith: b_m with P(Δφ) = Σ b_m cos(mΔφ), times the
/// solid angle of the incident zenith band's quadrature (dθ·sin θ_l).
pub(super) struct PhaseKernels {
    /// `[((z·nmu + y)·THETA + l)·2 + group]·HARMONICS + m`.
    pub b: Vec<f64>,
}

impl PhaseKernels {
    /// Floats per (r, μ) row of [`PhaseKernels::b`].
    const PER_ROW: usize = DENSITY_THETA * 2 * HARMONICS;

    /// All zero, to be filled slice by slice ([`PhaseKernels::compute_slices`]).
    pub fn zeroed(s: &TableSizes) -> PhaseKernels {
        PhaseKernels {
            b: vec![0.0; s.scattering_r * s.scattering_mu * Self::PER_ROW],
        }
    }

    /// The harmonics of the r slices `slices` (each (r, μ) row on its own, so slices
    /// computed apart equal the whole table).
    pub fn compute_slices(
        &mut self,
        lookup: &Lookup,
        grid: &ScatteringGrid,
        groups: &ScatteringGroups,
        slices: Range<usize>,
    ) {
        let s = &lookup.sizes;
        let per_row = Self::PER_ROW;
        let slab = s.scattering_mu * per_row;
        let first_row = slices.start * s.scattering_mu;
        let b = &mut self.b[slices.start * slab..slices.end * slab];
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
        b.par_chunks_mut(per_row).enumerate().for_each(|(i, out)| {
            let row = first_row + i;
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
                    let o = &mut out[(l * 2 + group) * HARMONICS..(l * 2 + group + 1) * HARMONICS];
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
    }
}

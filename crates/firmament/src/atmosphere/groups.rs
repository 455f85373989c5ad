//! The scattering groups the tables store apart (Bruneton & Neyret 2008 §4: Rayleigh and Mie
//! single scattering separately, so that each group's phase function is applied at render
//! time): molecules, and everything else that scatters (aerosols). Each group's phase
//! function is that of its first member.

use super::Model;
use crate::medium::{ConstituentKind, PhaseFunction, ResolvedConstituent};

/// Index of the molecular (Rayleigh) group.
pub const MOLECULES: usize = 0;
/// Index of the aerosol (Mie) group: every scattering constituent that is not molecular.
pub const AEROSOLS: usize = 1;

/// The constituents of each scattering group, with the group's phase function.
#[derive(Clone, Debug)]
pub struct ScatteringGroups {
    /// Per group ([`MOLECULES`], [`AEROSOLS`]): indices into the model's constituents.
    pub members: [Vec<usize>; 2],
    /// The phase function applied to each group at render time.
    pub phase: [PhaseFunction; 2],
    /// Group scattering coefficient at the ground per wavelength (m⁻¹), for the red-only Mie
    /// ratio rule.
    pub ground_scattering: [Vec<f64>; 2],
}

impl ScatteringGroups {
    /// The groups of these constituents (`channels` wavelengths).
    pub fn new(constituents: &[ResolvedConstituent], channels: usize) -> ScatteringGroups {
        let mut members: [Vec<usize>; 2] = [Vec::new(), Vec::new()];
        let mut phase = [
            PhaseFunction::Rayleigh {
                depolarization: 0.0,
            },
            PhaseFunction::HenyeyGreenstein { g: 0.0 },
        ];
        for (i, c) in constituents.iter().enumerate() {
            let Some(group) = Self::group_of(c) else {
                continue;
            };
            if members[group].is_empty() {
                phase[group] = c.phase.clone();
            }
            members[group].push(i);
        }
        let ground_scattering = [MOLECULES, AEROSOLS].map(|group| {
            let mut s = vec![0.0; channels];
            members_scattering(constituents, &members[group], 0.0, &mut s);
            s
        });
        ScatteringGroups {
            members,
            phase,
            ground_scattering,
        }
    }

    /// The group a constituent belongs to; None when it does not scatter (absorbers cannot
    /// scatter: validated).
    pub fn group_of(c: &ResolvedConstituent) -> Option<usize> {
        if c.scattering.iter().all(|&s| s == 0.0) {
            None
        } else if c.kind == ConstituentKind::Molecules {
            Some(MOLECULES)
        } else {
            Some(AEROSOLS)
        }
    }

    /// Whether group `group` has members.
    #[inline]
    pub fn present(&self, group: usize) -> bool {
        !self.members[group].is_empty()
    }

    /// Scattering coefficient (m⁻¹) of `group` at `altitude_m`, into `out`.
    #[inline]
    pub fn scattering_into(&self, model: &Model, group: usize, altitude_m: f64, out: &mut [f64]) {
        members_scattering(&model.constituents, &self.members[group], altitude_m, out);
    }

    /// The ratio-rule factors `(β_R[0]/β_M[0])·(β_M[k]/β_R[k])` at the ground, by which the
    /// red-only Mie storage extrapolates the other channels (Bruneton & Neyret 2008 §4;
    /// Bruneton 2017 `GetExtrapolatedSingleMieScattering`); 0 where undefined.
    pub fn mie_ratio(&self) -> Vec<f64> {
        let [r, m] = &self.ground_scattering;
        (0..r.len())
            .map(|k| {
                if r[k] > 0.0 && m[0] > 0.0 && r[0] > 0.0 {
                    (r[0] / m[0]) * (m[k] / r[k])
                } else {
                    0.0
                }
            })
            .collect()
    }
}

/// Σ ρ·β (m⁻¹) over the constituents `members` at `altitude_m`, into `out`.
#[inline]
fn members_scattering(
    constituents: &[ResolvedConstituent],
    members: &[usize],
    altitude_m: f64,
    out: &mut [f64],
) {
    out.iter_mut().for_each(|o| *o = 0.0);
    for &i in members {
        let c = &constituents[i];
        let rho = c.density.density(altitude_m);
        if rho > 0.0 {
            for (o, s) in out.iter_mut().zip(&c.scattering) {
                *o += rho * s;
            }
        }
    }
}

//! The phase functions integrated over azimuth, which is all the 3D table's scattering
//! density needs.
//!
//! For a field L(μ′, φ′) and J(ω) = ∫ P(ω·ω′) L(ω′) dω′, the mean of J over the view's
//! azimuth depends only on the mean of L over the incident azimuth (the m = 0 terms of
//! their cosine series; the addition theorem): J̄(μ) = ∫ K(μ, μ′) L̄(μ′) dμ′ with
//! K(μ, μ′) = ∫₀^{2π} P(μμ′ + √(1−μ²)√(1−μ′²)·cos φ) dφ, and ∫ K(μ, μ′) dμ′ = 1 for a phase
//! function normalised over the sphere. So the 3D method's orders are exact for the
//! azimuthal means, given the previous order's mean; the only approximation is the table
//! itself (the single-scattering field's azimuthal mean taken as the phase-free mean times
//! the mean of the phase function, and J's own azimuth dropped along the rays).
//!
//! K is tabulated once per group on a (θ, θ′) grid (midpoint rule in φ) and read
//! bilinearly; the gather matrices ([`Gather`]) hold it at each altitude's view-zenith
//! texels and incident nodes, with the nodes' Gauss–Legendre weights, rows normalised to 1
//! (energy conservation whatever the forward peak's resolution).

use std::f64::consts::PI;

use rayon::prelude::*;

use super::params::Params;
use crate::atmosphere::ScatteringGroups;
use crate::math::quadrature::GaussLegendreRule;
use crate::math::sphere::{horizon_mu, safe_sqrt};
use crate::sky::bruneton4d::table::lerp_weights;

/// Zenith-angle intervals of the kernel grid over [0, π] (1.4° apart; the aerosols' forward
/// peak at g = 0.76 is ≈ 14° wide).
const KERNEL_THETA: usize = 128;
/// Midpoint nodes in azimuth over [0, π] for each kernel value.
const KERNEL_PHI: usize = 64;

/// K_g(θ, θ′) of each scattering group on a (KERNEL_THETA + 1)² grid.
pub(super) struct PhaseKernels {
    values: [Vec<f64>; 2],
}

impl PhaseKernels {
    /// The kernels of `groups`' phase functions (zero for an empty group).
    pub fn new(groups: &ScatteringGroups) -> PhaseKernels {
        let m = KERNEL_THETA + 1;
        let values = [0, 1].map(|group| {
            let mut v = vec![0.0; m * m];
            if !groups.present(group) {
                return v;
            }
            let phase = &groups.phase[group];
            let cos_phi: Vec<f64> = (0..KERNEL_PHI)
                .map(|j| (PI * (j as f64 + 0.5) / KERNEL_PHI as f64).cos())
                .collect();
            v.par_chunks_mut(m).enumerate().for_each(|(a, row)| {
                let (sin_a, cos_a) = (PI * a as f64 / KERNEL_THETA as f64).sin_cos();
                for (b, o) in row.iter_mut().enumerate() {
                    let (sin_b, cos_b) = (PI * b as f64 / KERNEL_THETA as f64).sin_cos();
                    let sum: f64 = (cos_phi.iter())
                        .map(|c| phase.eval(cos_a * cos_b + sin_a * sin_b * c))
                        .sum();
                    // 2∫₀^π by the midpoint rule.
                    *o = 2.0 * PI / KERNEL_PHI as f64 * sum;
                }
            });
            v
        });
        PhaseKernels { values }
    }

    /// K_g(μ, μ′) (1/sr·rad: per unit μ′), bilinear in the zenith angles.
    #[inline]
    pub fn eval(&self, group: usize, mu: f64, mu2: f64) -> f64 {
        let m = KERNEL_THETA + 1;
        let pos = |mu: f64| {
            let x = mu.clamp(-1.0, 1.0).acos() / PI * KERNEL_THETA as f64;
            let i = (x as usize).min(KERNEL_THETA - 1);
            (i, x - i as f64)
        };
        let ((a, ta), (b, tb)) = (pos(mu), pos(mu2));
        let v = &self.values[group];
        let at = |a: usize, b: usize| v[a * m + b];
        (1.0 - ta) * ((1.0 - tb) * at(a, b) + tb * at(a, b + 1))
            + ta * ((1.0 - tb) * at(a + 1, b) + tb * at(a + 1, b + 1))
    }
}

/// The incident directions of the scattering density at each altitude texel and the
/// kernels there: Gauss–Legendre nodes in μ′ below the horizon ([−1, μ_h], first) and
/// above it ([μ_h, 1]), so that the field's jump at the horizon falls between nodes.
pub(super) struct Gather {
    /// Nodes per altitude texel (2 × the nodes per side).
    pub count: usize,
    /// μ′ of node l at altitude texel z: `[z·count + l]`.
    pub mu: Vec<f64>,
    /// Whether node l meets the ground.
    pub ground: Vec<bool>,
    /// Per group: w_l·K_g(μ_y, μ′_l) normalised over l, `[(z·nmu + y)·count + l]`.
    pub view: [Vec<f64>; 2],
    /// Per group: K_g(μ′_l, μ_s,x)/(2π), the mean over the incident azimuth of the phase
    /// function towards the sun, `[(z·count + l)·nmu_s + x]` (the single-scattering field's
    /// azimuthal mean is Σ_g S₃,g·K_g/(2π)).
    pub sun: [Vec<f64>; 2],
}

impl Gather {
    /// The nodes and matrices for `params`' texels, `per_side` nodes on each side of the
    /// horizon.
    pub fn new(params: &Params, kernels: &PhaseKernels, per_side: usize) -> Gather {
        let count = 2 * per_side;
        let rule = GaussLegendreRule::new(per_side);
        let (nh, nmu, nmu_s) = (params.nh, params.nmu, params.nmu_s);
        let mut mu = Vec::with_capacity(nh * count);
        let mut weight = Vec::with_capacity(nh * count);
        let mut ground = Vec::with_capacity(nh * count);
        for z in 0..nh {
            let mu_h = horizon_mu(params.texel_r(z), params.bottom);
            for (lo, hi, below) in [(-1.0, mu_h, true), (mu_h, 1.0, false)] {
                for (m, w) in rule.on(lo, hi) {
                    mu.push(m);
                    weight.push(w);
                    ground.push(below);
                }
            }
        }
        let view = [0, 1].map(|group| {
            let mut v = vec![0.0; nh * nmu * count];
            v.par_chunks_mut(count).enumerate().for_each(|(row, o)| {
                let z = row / nmu;
                let (mu_y, _) = params.texel_mu(params.texel_r(z), row % nmu);
                for (l, o) in o.iter_mut().enumerate() {
                    let i = z * count + l;
                    *o = weight[i] * kernels.eval(group, mu_y, mu[i]);
                }
                let sum: f64 = o.iter().sum();
                if sum > 0.0 {
                    o.iter_mut().for_each(|v| *v /= sum);
                }
            });
            v
        });
        let sun = [0, 1].map(|group| {
            let mut v = vec![0.0; nh * count * nmu_s];
            for (i, o) in v.chunks_exact_mut(nmu_s).enumerate() {
                for (x, o) in o.iter_mut().enumerate() {
                    *o = kernels.eval(group, mu[i], params.texel_mu_s(x)) / (2.0 * PI);
                }
            }
            v
        });
        Gather {
            count,
            mu,
            ground,
            view,
            sun,
        }
    }
}

/// The (z, y) column filter of node μ′ in the table at altitude texel z: (y0, y1, t).
#[inline]
pub(super) fn column_filter(params: &Params, r: f64, mu: f64, ground: bool) -> (usize, usize, f64) {
    lerp_weights(params.u_mu(r, mu, ground), params.nmu)
}

/// The zenith cosine's sine.
#[inline]
pub(super) fn sine(mu: f64) -> f64 {
    safe_sqrt(1.0 - mu * mu)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::atmosphere::Atmosphere;
    use crate::spectrum::Wavelengths;

    #[test]
    fn kernels_integrate_to_one_and_rayleigh_has_its_closed_form() {
        let model = Atmosphere::earth().resolve(&Wavelengths::rgb()).unwrap();
        let kernels = PhaseKernels::new(&model.groups);
        let rule = GaussLegendreRule::new(400);
        for &mu in &[-0.97, -0.4, 0.0, 0.33, 0.8, 1.0] {
            for group in 0..2 {
                let total: f64 = rule
                    .on(-1.0, 1.0)
                    .map(|(m, w)| w * kernels.eval(group, mu, m))
                    .sum();
                assert!((total - 1.0).abs() < 4e-3, "group {group} μ {mu}: {total}");
            }
        }
        // Rayleigh without depolarisation: K = (3/8)(1 + μ²μ′² + (1 − μ²)(1 − μ′²)/2).
        let mut plain = model.groups.clone();
        plain.phase[0] = crate::medium::PhaseFunction::Rayleigh {
            depolarization: 0.0,
        };
        let kernels = PhaseKernels::new(&plain);
        for &(a, b) in &[(0.3, -0.6), (0.9, 0.1), (-1.0, 0.5)] {
            let want = 0.375 * (1.0 + a * a * b * b + 0.5 * (1.0 - a * a) * (1.0 - b * b));
            let got = kernels.eval(0, a, b);
            assert!((got / want - 1.0).abs() < 1e-3, "{a} {b}: {got} {want}");
        }
    }
}

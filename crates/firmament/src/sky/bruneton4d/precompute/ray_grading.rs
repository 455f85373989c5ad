//! Where the samples of each view ray lie: pairs of intervals graded by the ray's optical
//! depth, computed once per (r, μ) row of the tables and shared by the CPU passes and the
//! GPU's (which read them from the atmosphere data buffer).
//!
//! Bruneton 2017 spaces the samples evenly along the ray. Through a 1.5 km haze that leaves
//! one sample in the haze for a ray 3° above the horizon (50 intervals of 12 km over its
//! 600 km to the top), while across one such step the sun's transmittance at 5° elevation
//! grows ×5 and the haze's density falls ×0.7: single scattering read −13.8 % looking 3° up
//! from the ground under a 5° sun, and under a zenith sun the second order read +4.5 %
//! 3° up, +2.8 % 10° up (`examples/order_by_order.rs` against the reference cut at one and
//! two events; 200 even intervals: −0.3 … +2.9 %). Here the ends of the pairs are even in
//!
//! m(d) = (1 − α)·d/L + α·τ(d)/τ(L),
//!
//! half the ray's length and half its optical depth τ (α = [`RAY_GRADING`]): a ray through
//! the haze gets ~25 samples where its optical depth is, a ray in clear air keeps nearly
//! even steps, and every pair is still two equal intervals, so the fitted Simpson rule of
//! `ray.rs` applies to each pair with its own step. With the same 50 intervals the two
//! views read +3.2 % (the rest is the μ_s interpolation, see `mu_s_blend.rs`) and −0.1 %.
//! τ is the extinction optical depth averaged over the channels (one placement for every
//! wavelength, so the ray's geometry is shared), integrated by the trapezoid rule on
//! [`FINE`] steps per pair of the extinction tabulated over altitude: the placement only
//! has to be the same on the CPU and the GPU, not exact, since any placement is a valid
//! quadrature (8 steps per pair and the exact profiles placed them within 0.05 % of the
//! same results). The GPU's passes read the CPU's placement (`pack_for_precompute`): all
//! rows of the default tables take 11 ms on this 2-core host, in parallel.

use rayon::prelude::*;

use super::grid::ScatteringGrid;
use super::RAY_INTERVALS;
use crate::atmosphere::density_table::DensityTable;
use crate::atmosphere::Model;
use crate::math::sphere::distance_to_nearest_atmosphere_boundary;
use crate::sky::bruneton4d::params::{Radii, TableSizes};

/// Pairs of intervals along a view ray (the fitted Simpson rule integrates pair by pair).
pub const RAY_PAIRS: usize = RAY_INTERVALS / 2;
/// The weight α of the optical depth in the placement of the pairs (the rest is length).
pub const RAY_GRADING: f64 = 0.5;
/// Trapezoid steps per pair for the optical depth that places the pairs.
const FINE: usize = 4;

/// The pairs' ends of every view ray of the tables, as fractions of the ray's length.
pub struct RayGrading {
    /// `RAY_PAIRS + 1` fractions per (r, μ) row (row = z·N_μ + y), from 0 to 1; one row
    /// for every ray when `even`.
    fractions: Vec<f64>,
    even: bool,
}

impl RayGrading {
    /// Even steps on every ray (Bruneton 2017's placement).
    pub fn even() -> RayGrading {
        RayGrading {
            fractions: (0..=RAY_PAIRS)
                .map(|p| p as f64 / RAY_PAIRS as f64)
                .collect(),
            even: true,
        }
    }

    /// The rows of tables of sizes `s` through `model`.
    pub fn for_tables(model: &Model, s: &TableSizes) -> RayGrading {
        let radii = Radii::of(model);
        RayGrading::new(model, &ScatteringGrid::new(&radii, s), s)
    }

    /// The rows of tables of sizes `s` (their (r, μ) from `grid`) through `model`.
    pub(crate) fn new(model: &Model, grid: &ScatteringGrid, s: &TableSizes) -> RayGrading {
        // The grid's own placement is not read here (only its (r, μ)).
        let extinction = Extinction::new(model);
        let rows = s.scattering_r * s.scattering_mu;
        let mut fractions = vec![0.0; rows * (RAY_PAIRS + 1)];
        fractions
            .par_chunks_exact_mut(RAY_PAIRS + 1)
            .enumerate()
            .for_each(|(row, out)| {
                let (r, mu, _, _, ground) =
                    grid.texel(0, row % s.scattering_mu, row / s.scattering_mu);
                pair_fractions(model, &extinction, r, mu, ground, out);
            });
        RayGrading {
            fractions,
            even: false,
        }
    }

    /// Row `row`'s `RAY_PAIRS + 1` fractions.
    #[inline]
    pub fn fractions(&self, row: usize) -> &[f64] {
        let row = if self.even { 0 } else { row };
        &self.fractions[row * (RAY_PAIRS + 1)..][..RAY_PAIRS + 1]
    }

    /// Every row's interior ends (1 to `RAY_PAIRS − 1`), row after row (of the rows
    /// given to [`RayGrading::new`]): what the GPU's passes read (`ray.wgsl`,
    /// `ray_pair_end_km`).
    pub fn interior(&self) -> impl Iterator<Item = f64> + '_ {
        self.fractions
            .chunks_exact(RAY_PAIRS + 1)
            .flat_map(|row| row[1..RAY_PAIRS].iter().copied())
    }
}

/// Altitudes at which [`Extinction`] tabulates the constituents' densities.
const EXTINCTION_SAMPLES: usize = 1024;

/// The extinction coefficient averaged over the channels (m⁻¹) from the densities
/// tabulated over altitude ([`DensityTable`], linear interpolation: the placement need not
/// be exact, and a lookup costs a few ns where the profiles cost an exponential each).
struct Extinction {
    densities: DensityTable,
    /// Each constituent's extinction per unit density averaged over the channels (m⁻¹).
    weights: Vec<f64>,
}

impl Extinction {
    fn new(model: &Model) -> Extinction {
        let n = model.channels().max(1) as f64;
        Extinction {
            densities: DensityTable::new(model, EXTINCTION_SAMPLES),
            weights: model
                .constituents
                .iter()
                .map(|c| c.extinction.iter().sum::<f64>() / n)
                .collect(),
        }
    }

    /// At radius `r` (m), clamped to the atmosphere; `rho` is scratch, one per constituent.
    #[inline]
    fn at(&self, r: f64, rho: &mut [f64]) -> f64 {
        rho.iter_mut().for_each(|v| *v = 0.0);
        self.densities.add_densities(r, 1.0, rho);
        rho.iter().zip(&self.weights).map(|(d, w)| d * w).sum()
    }
}

/// The `RAY_PAIRS + 1` ends of the pairs of the ray from radius `r` (m) at zenith cosine
/// `mu` to the ground (`ground`) or the top, as fractions of its length: even in m(d) (see
/// the module's text). A ray without optical depth gets even steps.
fn pair_fractions(
    model: &Model,
    extinction: &Extinction,
    r: f64,
    mu: f64,
    ground: bool,
    out: &mut [f64],
) {
    let (bottom, top) = (model.bottom_radius_m, model.top_radius_m);
    let length = distance_to_nearest_atmosphere_boundary(r, mu, bottom, top, ground);
    let steps = RAY_PAIRS * FINE;
    let mut rho = vec![0.0; extinction.weights.len()];
    let mut extinction = |j: usize| {
        let d = length * j as f64 / steps as f64;
        let r_d = crate::math::sphere::safe_sqrt(d * d + 2.0 * r * mu * d + r * r);
        extinction.at(r_d, &mut rho)
    };
    // Cumulative optical depth (in units of the fine step) at each fine point.
    let mut tau = Vec::with_capacity(steps + 1);
    tau.push(0.0);
    let mut previous = extinction(0);
    for j in 1..=steps {
        let e = extinction(j);
        tau.push(tau[j - 1] + 0.5 * (previous + e));
        previous = e;
    }
    let total = tau[steps];
    let alpha = if total > 0.0 && total.is_finite() {
        RAY_GRADING
    } else {
        0.0
    };
    let m = |j: usize| {
        let even = j as f64 / steps as f64;
        let graded = if alpha > 0.0 { tau[j] / total } else { even };
        (1.0 - alpha) * even + alpha * graded
    };
    out[0] = 0.0;
    out[RAY_PAIRS] = 1.0;
    // m rises strictly (its even part does), so each target lies in one fine step.
    let mut j = 0;
    for (p, o) in out.iter_mut().enumerate().take(RAY_PAIRS).skip(1) {
        let target = p as f64 / RAY_PAIRS as f64;
        while j + 1 < steps && m(j + 1) < target {
            j += 1;
        }
        let (m0, m1) = (m(j), m(j + 1));
        *o = (j as f64 + (target - m0) / (m1 - m0)) / steps as f64;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::atmosphere::Atmosphere;
    use crate::spectrum::Wavelengths;

    fn row(preset: &str, altitude: f64, elevation_deg: f64) -> Vec<f64> {
        let model = Atmosphere::preset(preset)
            .unwrap()
            .resolve(&Wavelengths::rgb())
            .unwrap();
        let w = Extinction::new(&model);
        let mut out = vec![0.0; RAY_PAIRS + 1];
        let r = model.bottom_radius_m + altitude;
        let mu = elevation_deg.to_radians().sin();
        pair_fractions(&model, &w, r, mu, mu < 0.0 && altitude < 1.0, &mut out);
        out
    }

    #[test]
    fn pairs_rise_from_zero_to_one() {
        for (preset, altitude, elevation) in [
            ("hazy", 0.0, 3.0),
            ("earth", 0.0, 90.0),
            ("earth", 10_000.0, -30.0),
            ("mars", 50_000.0, 0.0),
            ("earth", 60_000.0, 45.0),
        ] {
            let f = row(preset, altitude, elevation);
            assert_eq!((f[0], f[RAY_PAIRS]), (0.0, 1.0));
            assert!(
                f.windows(2).all(|w| w[1] > w[0]),
                "{preset} {altitude} m {elevation}°: {f:?}"
            );
        }
    }

    /// The haze (1.5 km scale height) holds most of a low ray's optical depth within its
    /// first ~30 km: about half the pairs go there, where even steps put one pair (24 km).
    #[test]
    fn a_low_ray_through_haze_is_graded_into_the_haze() {
        let f = row("hazy", 0.0, 3.0);
        let length = distance_to_nearest_atmosphere_boundary(
            6_360_000.0,
            3f64.to_radians().sin(),
            6_360_000.0,
            6_420_000.0,
            false,
        );
        let within = f.iter().filter(|&&x| x * length < 30_000.0).count();
        assert!(
            (8..=16).contains(&within),
            "{within} ends within 30 km: {f:?}"
        );
        // No pair longer than twice the even step.
        assert!(f
            .windows(2)
            .all(|w| w[1] - w[0] <= 2.0 / RAY_PAIRS as f64 + 1e-12));
    }
}

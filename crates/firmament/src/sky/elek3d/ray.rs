//! Quadrature along one view ray of the table, shared by the single- and
//! multiple-scattering passes: an even number of equal intervals, the geometry of each
//! sample (radius, zenith cosine, the central angle from the ray's origin, which turns the
//! sun as seen from the sample), and per scattering group the weights of
//! ∫ β_g(t)·T(0, t)·g(t) dt for a smooth g.
//!
//! The weights come from a product rule on each pair of intervals: β_g·T = F is written
//! F₀·e^{−a·s}·q(s) with the exponential through the pair's end values (s in steps), and
//! q·g is interpolated quadratically through the three samples, so that
//! ∫₀² F·g ds = Σ_j F_j·e^{a·j}·M_j(a)·g_j with M_j(a) = ∫₀² e^{−a·s}·L_j(s) ds over the
//! quadratic Lagrange basis: an exponentially fitted Simpson rule (a Filon-type product
//! rule), exact for an exponential F and a quadratic g, Simpson's as a → 0. It is the rule
//! of the 4D tables' ray quadrature (`bruneton4d/precompute/ray.rs`), so that the two
//! methods differ by the azimuth and not by their ray integrals: an exponential × linear
//! rule on 40 intervals read the horizon's single scattering 2.8 % above it (the
//! transmittance over one optically thick interval near the ground is no exponential).
//! For a steep decay (a > 1.43 per step) the end weight goes slightly negative; the passes
//! clamp their sums at 0.

use rayon::prelude::*;

use super::params::Params;
use crate::atmosphere::{Model, ScatteringGroups};
use crate::math::sphere::{distance_to_nearest_atmosphere_boundary, safe_sqrt};
use crate::sky::bruneton4d::Lookup;

/// The most memory the rays of every (altitude, view zenith) row may keep between passes;
/// beyond it (many channels) each pass builds its rays again.
const RAY_CACHE_BYTES: usize = 64 << 20;

/// The rays of the table's (altitude, view zenith) rows, which every pass integrates along:
/// built once and kept when they fit in [`RAY_CACHE_BYTES`] (the transmittance, scattering
/// coefficients and weights of a row are the same for the single scattering and every
/// order), else built per row and pass.
pub(super) struct TableRays<'a> {
    model: &'a Model,
    lookup: &'a Lookup<'a>,
    params: &'a Params,
    steps: usize,
    cached: Option<Vec<RaySamples>>,
}

impl<'a> TableRays<'a> {
    /// The rays of `params`' rows in `steps` intervals each.
    pub fn new(model: &'a Model, lookup: &'a Lookup<'a>, params: &'a Params, steps: usize) -> Self {
        let mut rays = TableRays {
            model,
            lookup,
            params,
            steps,
            cached: None,
        };
        let rows = params.nh * params.nmu;
        let per_row = (steps + 1) * (4 + 2 * model.channels()) * std::mem::size_of::<f64>();
        if rows * per_row <= RAY_CACHE_BYTES {
            rays.cached = Some(
                (0..rows)
                    .into_par_iter()
                    .map(|row| rays.build(row))
                    .collect(),
            );
        }
        rays
    }

    /// `f` of the rays of row `row` = z·nmu + y.
    #[inline]
    pub fn with_row<R>(&self, row: usize, f: impl FnOnce(&RaySamples) -> R) -> R {
        match &self.cached {
            Some(rays) => f(&rays[row]),
            None => f(&self.build(row)),
        }
    }

    fn build(&self, row: usize) -> RaySamples {
        let p = self.params;
        let r = p.texel_r(row / p.nmu);
        let (mu, ground) = p.texel_mu(r, row % p.nmu);
        let m = self.model;
        RaySamples::new(
            m,
            &m.groups,
            self.lookup,
            r,
            mu,
            ground,
            self.steps,
            m.channels(),
        )
    }
}

/// One ray's samples and weights.
pub(super) struct RaySamples {
    /// Whether the ray meets the ground.
    pub ground: bool,
    /// Radius (m) per sample, clamped to the atmosphere.
    pub r: Vec<f64>,
    /// The ray's zenith cosine at each sample.
    pub mu: Vec<f64>,
    /// cos and sin of the angle at the planet's centre between the origin and each sample:
    /// a sun at zenith cosine μ_s and azimuth φ from the ray's vertical plane at the origin
    /// has the zenith cosine μ_s·cos α + √(1 − μ_s²)·sin α·cos φ at the sample.
    pub cos_alpha: Vec<f64>,
    /// See `cos_alpha`.
    pub sin_alpha: Vec<f64>,
    /// Per group ([`crate::atmosphere::groups::MOLECULES`], `AEROSOLS`), per sample and
    /// channel: ∫ β_g·T·g dt ≈ Σ_i w[i·n + k]·g_i.
    pub weights: [Vec<f64>; 2],
}

impl RaySamples {
    /// The ray (r, μ) (meeting the ground or not) to its boundary in `steps` (even) equal
    /// intervals, for `n` channels.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        model: &Model,
        groups: &ScatteringGroups,
        lookup: &Lookup,
        r: f64,
        mu: f64,
        ground: bool,
        steps: usize,
        n: usize,
    ) -> RaySamples {
        let (bottom, top) = (lookup.radii.bottom, lookup.radii.top);
        let length = distance_to_nearest_atmosphere_boundary(r, mu, bottom, top, ground);
        let dx = length / steps as f64;
        let count = steps + 1;
        let sin_mu = safe_sqrt(1.0 - mu * mu);
        let mut rays = RaySamples {
            ground,
            r: Vec::with_capacity(count),
            mu: Vec::with_capacity(count),
            cos_alpha: Vec::with_capacity(count),
            sin_alpha: Vec::with_capacity(count),
            weights: [vec![0.0; count * n], vec![0.0; count * n]],
        };
        // β_g·T per sample and channel, into the weights' storage first.
        let mut t = vec![0.0; n];
        let mut beta = vec![0.0; n];
        for i in 0..count {
            let d = i as f64 * dx;
            let r_exact = safe_sqrt(d * d + 2.0 * r * mu * d + r * r).max(1.0);
            let r_d = r_exact.clamp(bottom, top);
            rays.r.push(r_d);
            rays.mu.push(((r * mu + d) / r_exact).clamp(-1.0, 1.0));
            rays.cos_alpha
                .push(((r + d * mu) / r_exact).clamp(-1.0, 1.0));
            rays.sin_alpha.push((d * sin_mu / r_exact).clamp(0.0, 1.0));
            lookup.transmittance(r, mu, d, ground, &mut t);
            for (group, w) in rays.weights.iter_mut().enumerate() {
                groups.scattering_into(model, group, r_d - bottom, &mut beta);
                for k in 0..n {
                    w[i * n + k] = beta[k] * t[k];
                }
            }
        }
        for w in rays.weights.iter_mut() {
            exponential_simpson_weights(w, dx, n);
        }
        rays
    }

    /// Number of samples.
    #[inline]
    pub fn len(&self) -> usize {
        self.r.len()
    }
}

/// Turns `f` (per sample and channel, the values of F = β·T at an odd number of samples
/// `dx` apart) into the weights of ∫ F·g dt (see the module documentation).
fn exponential_simpson_weights(f: &mut [f64], dx: f64, n: usize) {
    let count = f.len() / n;
    let mut w = vec![0.0; f.len()];
    for pair in 0..count.saturating_sub(1) / 2 {
        let i = 2 * pair;
        for k in 0..n {
            let v = [f[i * n + k], f[(i + 1) * n + k], f[(i + 2) * n + k]];
            let p = pair_weights(v);
            for (j, p) in p.iter().enumerate() {
                w[(i + j) * n + k] += dx * p;
            }
        }
    }
    f.copy_from_slice(&w);
}

/// The weights w_j of ∫₀² F(s)·g(s) ds ≈ Σ w_j·g_j for the values F_j = `f`[j] at s = j.
#[inline]
fn pair_weights(f: [f64; 3]) -> [f64; 3] {
    if f[0] <= 0.0 || f[2] <= 0.0 {
        // No exponential through a zero: Simpson's rule on F·g.
        return [f[0] / 3.0, 4.0 * f[1] / 3.0, f[2] / 3.0].map(|v| v.max(0.0));
    }
    if f[2] > f[0] {
        // A growing F: the mirror image s → 2 − s decays.
        let [a, b, c] = pair_weights([f[2], f[1], f[0]]);
        return [c, b, a];
    }
    // Decay per step, ≥ 0; F_j·e^{a·j} = F₀·q_j.
    let a = (0.5 * (f[0] / f[2]).ln()).min(300.0);
    let m = lagrange_exponential_moments(a);
    [
        f[0] * m[0],
        f[1] * a.exp() * m[1],
        f[2] * (2.0 * a).exp() * m[2],
    ]
}

/// M_j(a) = ∫₀² e^{−a·s}·L_j(s) ds for a ≥ 0 and the quadratic Lagrange basis on 0, 1, 2
/// (L₀ = (s−1)(s−2)/2, L₁ = s(2−s), L₂ = s(s−1)/2); (1/3, 4/3, 1/3) at a = 0.
fn lagrange_exponential_moments(a: f64) -> [f64; 3] {
    // I_m = ∫₀² s^m·e^{−a·s} ds.
    let (i0, i1, i2) = if a < 0.5 {
        // Σ_k (−2a)^k/k!·2^{m+1}/(m+k+1): the closed forms cancel for small a; 20 terms
        // leave < 10⁻¹⁷ at a = 0.5.
        const TERMS: usize = 20;
        let inv: [f64; TERMS + 2] = std::array::from_fn(|k| 1.0 / (k + 1) as f64);
        let (mut i0, mut i1, mut i2) = (0.0, 0.0, 0.0);
        let mut c = 1.0; // (−2a)^k/k!
        for k in 0..TERMS {
            i0 += c * 2.0 * inv[k];
            i1 += c * 4.0 * inv[k + 1];
            i2 += c * 8.0 * inv[k + 2];
            c *= -2.0 * a * inv[k];
        }
        (i0, i1, i2)
    } else {
        let e = (-2.0 * a).exp();
        (
            (1.0 - e) / a,
            (1.0 - e * (1.0 + 2.0 * a)) / (a * a),
            (2.0 - e * (2.0 + a * (4.0 + 4.0 * a))) / (a * a * a),
        )
    };
    [
        0.5 * (i2 - 3.0 * i1 + 2.0 * i0),
        2.0 * i1 - i2,
        0.5 * (i2 - i1),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_product_rule_is_exact_for_exponential_times_quadratic() {
        // ∫₀^L e^{−t/H}·(1 + t/L)² dt on 8 intervals, H = L/5.
        let (length, h, steps) = (1.0, 0.2, 8);
        let dx = length / steps as f64;
        let g = |t: f64| (1.0 + t / length).powi(2);
        let mut f: Vec<f64> = (0..=steps).map(|i| (-(i as f64 * dx) / h).exp()).collect();
        exponential_simpson_weights(&mut f, dx, 1);
        let got: f64 = (0..=steps).map(|i| f[i] * g(i as f64 * dx)).sum();
        let want =
            crate::math::quadrature::GL8.integrate(0.0, length, 64, |t| (-t / h).exp() * g(t));
        assert!((got / want - 1.0).abs() < 1e-12, "{got} {want}");
        // A growing exponential takes the mirrored form.
        let mut f: Vec<f64> = (0..=steps).map(|i| (i as f64 * dx / h).exp()).collect();
        exponential_simpson_weights(&mut f, dx, 1);
        let got: f64 = (0..=steps).map(|i| f[i] * g(i as f64 * dx)).sum();
        let want =
            crate::math::quadrature::GL8.integrate(0.0, length, 64, |t| (t / h).exp() * g(t));
        assert!((got / want - 1.0).abs() < 1e-12, "{got} {want}");
    }

    #[test]
    fn small_decays_are_simpsons_rule() {
        let m = lagrange_exponential_moments(0.0);
        assert!((m[0] - 1.0 / 3.0).abs() < 1e-15 && (m[1] - 4.0 / 3.0).abs() < 1e-15);
        // The series and the closed form meet at a = 0.5.
        let (below, above) = (
            lagrange_exponential_moments(0.5 - 1e-12),
            lagrange_exponential_moments(0.5),
        );
        for j in 0..3 {
            assert!(
                (below[j] - above[j]).abs() < 1e-12,
                "{j}: {below:?} {above:?}"
            );
        }
    }
}

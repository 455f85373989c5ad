//! The analytic phase functions' values, inverse CDFs and moments.

use std::f64::consts::PI;

use super::tabulated::solve_increasing;
use crate::math::quadrature::GL8;

/// 1/(4π), the isotropic phase function (1/sr).
pub(super) const INV_4PI: f64 = 1.0 / (4.0 * PI);

/// Henyey & Greenstein (1941).
#[inline]
pub(super) fn hg(g: f64, mu: f64) -> f64 {
    let d = 1.0 + g * g - 2.0 * g * mu;
    (1.0 - g * g) * INV_4PI / (d * d.sqrt())
}

/// Exact inverse CDF of HG in μ. The usual form μ = (1+g²−((1−g²)/(1−g+2gu))²)/(2g)
/// (e.g. Pharr, Jakob & Humphreys, PBRT 4th ed. §11.3.1) expanded with v = 2u−1 so that it
/// stays accurate for g → 0 (no division by g).
#[inline]
pub(super) fn hg_sample(g: f64, u: f64) -> f64 {
    let v = 2.0 * u - 1.0;
    let d = 1.0 + g * v;
    let num = v + 0.5 * g * (v * v + 3.0) + g * g * v + 0.5 * g * g * g * (v * v - 1.0);
    (num / (d * d)).clamp(-1.0, 1.0)
}

/// Largest |g| for which Schlick's k = 1.55g − 0.55g³ stays below 1 in magnitude: the root
/// of 0.55g² + 0.55g − 1 = 0, (√2.5025 − 0.55)/1.1 ≈ 0.93812.
pub const SCHLICK_G_MAX: f64 = 0.938_117_456_323_306_7;

/// Schlick's k from the HG asymmetry (Blasi, Le Saëc & Schlick 1993).
#[inline]
pub(super) fn schlick_k(g: f64) -> f64 {
    1.55 * g - 0.55 * g * g * g
}

/// Rayleigh coefficients (a, b) of p ∝ a + bμ², with γ = ρ/(2−ρ) (Chandrasekhar 1960).
#[inline]
pub(super) fn rayleigh_ab(rho: f64) -> (f64, f64) {
    let gamma = rho / (2.0 - rho);
    (1.0 + 3.0 * gamma, 1.0 - gamma)
}

/// Cornette & Shanks (1992); Bruneton & Neyret (2008) eq. 4.
#[inline]
pub(super) fn cornette_shanks(g: f64, mu: f64) -> f64 {
    let g2 = g * g;
    let d = 1.0 + g2 - 2.0 * g * mu;
    3.0 / (8.0 * PI) * (1.0 - g2) / (2.0 + g2) * (1.0 + mu * mu) / (d * d.sqrt())
}

/// Cumulative distribution in μ of Cornette–Shanks for g ≥ 0: P(cos θ ≤ μ).
pub(super) fn cs_cdf(g: f64, mu: f64) -> f64 {
    if g < 0.05 {
        // Smooth integrand (pole of (1+g²−2gμ)^{-3/2} at μ ≥ 9.5): Gauss–Legendre is exact
        // to rounding, and avoids the cancellation of the closed form below.
        return GL8.integrate(-1.0, mu, 2, |t| 2.0 * PI * cornette_shanks(g, t));
    }
    // With s = 1+g²−2gμ, (1+μ²) = (B − 2As + s²)/(4g²), A = 1+g², B = 4g²+A², dμ = −ds/(2g):
    // ∫(1+μ²)s^{-3/2}dμ = −1/(8g³) G(s), G(s) = −2B s^{-1/2} − 4A s^{1/2} + (2/3) s^{3/2}.
    let a = 1.0 + g * g;
    let b = 4.0 * g * g + a * a;
    let big_g = |s: f64| {
        let r = s.sqrt();
        -2.0 * b / r - 4.0 * a * r + 2.0 / 3.0 * s * r
    };
    let s_lo = (1.0 + g) * (1.0 + g);
    let s_hi = (1.0 - g) * (1.0 - g);
    let s = (a - 2.0 * g * mu).max(s_hi);
    let g_lo = big_g(s_lo);
    (g_lo - big_g(s)) / (g_lo - big_g(s_hi))
}

/// Exact inverse CDF of Cornette–Shanks (Newton on the closed-form CDF, started from HG).
pub(super) fn cs_sample(g: f64, u: f64) -> f64 {
    if g < 0.0 {
        // p_{−g}(μ) = p_g(−μ).
        return -cs_sample(-g, 1.0 - u);
    }
    solve_increasing(-1.0, 1.0, hg_sample(g, u), |mu| {
        (cs_cdf(g, mu) - u, 2.0 * PI * cornette_shanks(g, mu))
    })
}

/// Schlick mean cosine: 1/k − (1−k²)·atanh(k)/k², by its series Σ 2k^{2m+1}/((2m+1)(2m+3))
/// for small k to avoid cancellation.
pub(super) fn schlick_mean_cosine(k: f64) -> f64 {
    if k.abs() < 0.1 {
        let k2 = k * k;
        let mut term = k;
        let mut sum = 0.0;
        for m in 0..12 {
            let m = m as f64;
            sum += 2.0 * term / ((2.0 * m + 1.0) * (2.0 * m + 3.0));
            term *= k2;
        }
        sum
    } else {
        1.0 / k - (1.0 - k * k) * k.atanh() / (k * k)
    }
}

/// Legendre polynomials P_0 … P_{n−1} at x into `out`.
pub(super) fn legendre_into(x: f64, out: &mut [f64]) {
    for l in 0..out.len() {
        out[l] = match l {
            0 => 1.0,
            1 => x,
            _ => ((2 * l - 1) as f64 * x * out[l - 1] - (l - 1) as f64 * out[l - 2]) / l as f64,
        };
    }
}

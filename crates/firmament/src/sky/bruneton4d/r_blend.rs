//! Interpolation of the scattering tables along r: geometric in the altitude where the
//! radiance falls with altitude, Bruneton's linear blend where it rises.
//!
//! Bruneton's r rows are even in ρ = √(r² − R_g²): ~1.5 km apart at 10 km for `earth`'s
//! 32 rows, 4.7 km apart for a Titan-sized planet's (the `thick-shell` atmosphere). A sky
//! seen from inside the air falls with the observer's altitude as the air above thins,
//! L ≈ Σ A_i·e^{−h/H_i} (upward views: the scattering above the observer), and `hazy`'s
//! 1.5 km haze falls ×e from one row to the next, where a linear blend lies above it: single
//! scattering from 10 km looking 4–8° from a zenith sun read +3.1 to +3.6 % (128 rows
//! instead of 32: +0.6 %). The geometric blend a^{1−w}·b^w with w the fraction of the
//! altitude (not of ρ, in which e^{−h/H} is a Gaussian and the chord in log lies below
//! it: −2 % near the sun from 10 km over the thick shell) is exact for one exponential
//! and above a sum of them by far less than the chord (+0.4 to +0.5 % in the same views:
//! the air's 8 km and the haze's 1.5 km together).
//!
//! Where the radiance rises with altitude (downward views: the path to the ground below
//! lengthens, L ∝ h near the ground, then saturates) the geometric blend lies below the
//! linear one, which is itself below a concave L: there the blend stays linear in ρ
//! (Bruneton's; over the thick shell's coarse rows the geometric or a linear-in-altitude
//! blend read 4–7 % lower than it looking down from 1 km, against the reference). The two
//! rules meet where the rows are equal (both give the sample), so the blend is continuous.
//! Measured: docs/accuracy.md ("The r blend").
//!
//! Applied per (μ, ν) texel after the μ_s blend ([`super::mu_s_blend`]) and before the
//! linear filters in μ and ν, so that a [`super::Table4::slice`] at fixed (μ_s, r) equals
//! the 4D lookup.

use super::mu_s_blend::SAMPLE_SNAP;
use super::table::lerp_weights;
use crate::math::fast::{exp_in_range, ln_normal};

/// The filter along r at one texture coordinate: the two rows, the fraction of the way
/// in the table's coordinate (ρ) and in altitude.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RFilter {
    /// Lower row.
    pub z0: usize,
    /// Upper row.
    pub z1: usize,
    /// Fraction of the way from z0 to z1 in ρ (Bruneton's linear weight).
    pub t: f64,
    /// Fraction of the way in r (altitude): the geometric blend's weight.
    pub w: f64,
    /// Whether the rows take the geometric blend where the value falls: not into the top
    /// row, where the boundary cuts the radiance of upward views to 0 (a column that ends,
    /// not an exponential; there a value of 10⁻⁹ against 0 decided between the blends, and
    /// the CPU's exact 0 and the GPU's f32 crumbs read 25 % apart a few km below the top).
    pub log: bool,
}

impl RFilter {
    /// The filter at texture coordinate `u_r` over `n` rows, for a planet whose radius is
    /// `bottom_over_h` times H = √(R_t² − R_g²) (row i at ρ = H·i/(n − 1)).
    #[inline]
    pub fn new(u_r: f64, n: usize, bottom_over_h: f64) -> RFilter {
        let f = RFilter::altitude_rows(u_r, n);
        RFilter {
            w: altitude_fraction(f.z0, f.z1, f.t, n, bottom_over_h),
            ..f
        }
    }

    /// The filter at texture coordinate `v` over `n` rows even in altitude (the irradiance
    /// table's): the fraction in altitude is the linear weight.
    #[inline]
    pub fn altitude_rows(v: f64, n: usize) -> RFilter {
        let (z0, z1, t) = snapped(lerp_weights(v, n));
        RFilter {
            z0,
            z1,
            t,
            w: t,
            log: z1 + 1 < n,
        }
    }
}

/// (z0, z1, t) with t snapped to a row within [`SAMPLE_SNAP`] of it.
#[inline]
fn snapped((z0, z1, t): (usize, usize, f64)) -> (usize, usize, f64) {
    // At a row (the density pass reads the previous order at its texels' own r, t ≈
    // 10⁻¹³) the lookup is that row: no blend to make, as along μ_s.
    match t {
        t if t < SAMPLE_SNAP => (z0, z0, 0.0),
        t if t > 1.0 - SAMPLE_SNAP => (z1, z1, 0.0),
        t => (z0, z1, t),
    }
}

/// The fraction of the way in r from row z0 to row z1 at the fraction `t` in ρ, in units
/// of H: x = ρ/H, q = r/H = √(x² + k²), k = R_g/H; (q − q0)/(q1 − q0) written as
/// t·(x + x0)/(x1 + x0)·(q1 + q0)/(q + q0), free of the cancellation of r − r0 in f32
/// (the GPU's twin; 62 m between the lowest rows of a 6 360 km planet).
#[inline]
pub fn altitude_fraction(z0: usize, z1: usize, t: f64, n: usize, bottom_over_h: f64) -> f64 {
    if z1 == z0 || t == 0.0 {
        return t;
    }
    let step = 1.0 / (n - 1) as f64;
    let (x0, x1) = (z0 as f64 * step, z1 as f64 * step);
    let x = x0 + t * (x1 - x0);
    let k2 = bottom_over_h * bottom_over_h;
    let q = |x: f64| (x * x + k2).sqrt();
    t * (x + x0) / (x1 + x0) * (q(x1) + q(x0)) / (q(x) + q(x0))
}

/// The blend of the rows' values `a` (z0) and `b` (z1): a·(b/a)^w where the radiance falls
/// with altitude (0 < b < a) below the top row, a + t·(b − a) otherwise.
#[inline]
pub fn blend(a: f64, b: f64, f: &RFilter) -> f64 {
    let mut out = [0.0];
    add_blended(&[a], &[b], f, 1.0, &mut out);
    out[0]
}

/// Adds `weight` times [`blend`] of each channel's rows `a[k]`, `b[k]` to `out[k]`: one
/// texel's channels at once. The lookups of a cloudy frame spent 30 % of it here when each
/// channel took its own call and branches; now, per chunk of channels, the geometric blend
/// of every channel (ratio 1 where the linear one applies), then the choice, in loops free
/// of branches that the compiler vectorises.
#[inline]
pub fn add_blended(a: &[f64], b: &[f64], f: &RFilter, weight: f64, out: &mut [f64]) {
    const N: usize = 16;
    for ((out, a), b) in out.chunks_mut(N).zip(a.chunks(N)).zip(b.chunks(N)) {
        let n = out.len().min(a.len()).min(b.len());
        let (out, a, b) = (&mut out[..n], &a[..n], &b[..n]);
        let mut geometric = [false; N];
        let mut g = [0.0; N];
        for k in 0..n {
            geometric[k] = f.log & (b[k] < a[k]) & (b[k] > 0.0);
            // In range for the cores: the ratio is normal and ≤ 1 (rows are f32 values,
            // b/a ≥ 10⁻⁸³), its log times w ∈ [0, 1] ≥ −708.
            let ratio = if geometric[k] { b[k] / a[k] } else { 1.0 };
            g[k] = ln_normal(if ratio < f64::MIN_POSITIVE {
                f64::MIN_POSITIVE
            } else {
                ratio
            });
        }
        for k in 0..n {
            g[k] = a[k] * exp_in_range(f.w * g[k]);
        }
        for k in 0..n {
            let l = a[k] + f.t * (b[k] - a[k]);
            out[k] += weight * if geometric[k] { g[k] } else { l };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Earth's geometry: R_g = 6 360 km, R_t = 6 420 km.
    fn earth_k() -> f64 {
        6360.0 / (6420.0f64 * 6420.0 - 6360.0 * 6360.0).sqrt()
    }

    #[test]
    fn the_altitude_fraction_is_that_of_r_between_the_rows() {
        let (k, n) = (earth_k(), 32);
        let h = (6420.0f64 * 6420.0 - 6360.0 * 6360.0).sqrt();
        let r_of = |u: f64| {
            let x = ((u * n as f64 - 0.5) / (n - 1) as f64).clamp(0.0, 1.0);
            ((x * h).powi(2) + 6360.0f64.powi(2)).sqrt()
        };
        for u in [0.02, 0.031, 0.05, 0.2, 0.33, 0.5, 0.77, 0.97] {
            let f = RFilter::new(u, n, k);
            let row_r =
                |z: usize| ((z as f64 / (n - 1) as f64 * h).powi(2) + 6360.0f64.powi(2)).sqrt();
            let expected = (r_of(u) - row_r(f.z0)) / (row_r(f.z1) - row_r(f.z0));
            assert!(
                (f.w - expected).abs() < 1e-9,
                "u {u}: {} against {expected}",
                f.w
            );
        }
        // Between the two lowest rows r grows with ρ²: w = t² there.
        let f = RFilter::new(1.0 / n as f64, n, k);
        assert!((f.w - f.t * f.t).abs() < 1e-4, "{f:?}");
    }

    #[test]
    fn a_radiance_falling_exponentially_with_altitude_is_blended_exactly() {
        let (k, n) = (earth_k(), 32);
        let h = (6420.0f64 * 6420.0 - 6360.0 * 6360.0).sqrt();
        for u in [0.1, 0.3, 0.45, 0.6] {
            let f = RFilter::new(u, n, k);
            // 1.5 km scale height (hazy's haze): the chord in ρ is off by 0.4 % (low, where
            // e^{−h/H} is concave in ρ) to several % (high).
            let l = |alt_km: f64| 7.0 * (-alt_km / 1.5).exp();
            let alt_rows = |z: usize| {
                let x = z as f64 / (n - 1) as f64 * h;
                (x * x + 6360.0f64 * 6360.0).sqrt() - 6360.0
            };
            let (a, b) = (l(alt_rows(f.z0)), l(alt_rows(f.z1)));
            let x = ((u * n as f64 - 0.5) / (n - 1) as f64) * h;
            let truth = l((x * x + 6360.0f64 * 6360.0).sqrt() - 6360.0);
            let v = blend(a, b, &f);
            assert!((v / truth - 1.0).abs() < 1e-9, "u {u}: {v} against {truth}");
            let linear = a + f.t * (b - a);
            assert!(
                (linear / truth - 1.0).abs() > 3e-3,
                "u {u}: the chord {linear} vs {truth}"
            );
        }
    }

    #[test]
    fn a_rising_radiance_keeps_the_linear_blend_and_the_blend_is_continuous() {
        let f = RFilter {
            z0: 3,
            z1: 4,
            t: 0.4,
            w: 0.37,
            log: true,
        };
        assert_eq!(blend(2.0, 3.0, &f), 2.0 + 0.4 * 1.0);
        // Unlit rows: linear.
        assert_eq!(blend(2.0, 0.0, &f), 2.0 * 0.6);
        assert_eq!(blend(0.0, 0.0, &f), 0.0);
        // Either side of b = a the blends meet.
        let below = blend(2.0, 2.0 * (1.0 - 1e-9), &f);
        let above = blend(2.0, 2.0 * (1.0 + 1e-9), &f);
        assert!((below - 2.0).abs() < 1e-8 && (above - 2.0).abs() < 1e-8);
        // Into the top row: linear.
        let top = RFilter { log: false, ..f };
        assert_eq!(blend(2.0, 1e-9, &top), 2.0 + 0.4 * (1e-9 - 2.0));
        // At the rows themselves: the rows.
        for (t, want) in [(0.0, 5.0), (1.0, 1.0)] {
            let g = RFilter { t, w: t, ..f };
            assert!((blend(5.0, 1.0, &g) - want).abs() < 1e-12);
        }
    }
}

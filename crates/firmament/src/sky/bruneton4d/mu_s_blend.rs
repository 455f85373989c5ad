//! Interpolation of the scattering tables along μ_s: linear (Bruneton 2017) in daylight,
//! a monotone cubic in log L in the twilight cells and those of a low sun (≤ 20°).
//!
//! Below the horizon the light the sun sends into the air falls near-exponentially with its
//! depression (the shadow's height rises, the lit air above it thins: Rozenberg 1966,
//! *Twilight*, ch. 1–2, log brightness nearly linear in the depression). Bruneton's μ_s
//! samples lie 0.8–1.9° apart there, over which the sky falls by ×2–3, and a linear blend
//! of an exponential lies above it: between the samples at −6.0° and −4.99° the 40-sample
//! tables read +22 % (zenith, ground) and up to +38 % (10 km) against tables with four
//! times the μ_s samples, and +8 % to +11 % even towards the sun. In the precomputation the
//! same blend of the scattering density along each ray made the tables +7.6 % high at the
//! −6° sample itself against the reference.
//!
//! A geometric blend a^{1−t}·b^t (linear in log L) is exact for an exponential, but the log
//! brightness is concave in the depression (the shadow's height grows with its square), so
//! it read 2–6 % low mid-cell (−21 % at 10 km, −6.5°). [`blend`] is therefore a cubic
//! Hermite in log L through the cell's two samples with tangents from their outer
//! neighbours by the monotone (PCHIP) rule: within 1–3 % of a log brightness quadratic in
//! the texture coordinate where the chord is 6–17 % off. (A Catmull–Rom cubic, exact for
//! such a quadratic, overshoots where the brightness has a kink at a sample, as it has
//! where the shadow leaves the top of the air: 10 km, zenith, −7.2°.) Only the cells whose two
//! samples both have the sun at or below [`LOG_BLEND_MAX_SUN_ELEVATION_DEG`] use it: the
//! twilight's, and the low sun's, whose light falls exponentially with the slant optical
//! depth; above it every lookup is Bruneton's linear blend, bit for bit. It is continuous in
//! μ_s (it passes through the samples), and where a sample is 0 (no light) it falls back to
//! linear, where an outer neighbour is missing or 0 to the chord in log on that side.
//!
//! The blend is applied per texel of the other coordinates (r, μ, ν), before their linear
//! filter, so that a [`super::Table4::slice`] at fixed (μ_s, r) equals the 4D lookup.

use super::params::{x_mu_s, Radii};
use super::table::lerp_weights;
use crate::math::fast::{exp, ln};

/// The highest sun elevation (degrees) of the cells that [`blend`] interpolates: the
/// twilight and the low sun. Above the horizon a low sun's light falls exponentially with
/// its slant optical depth, ∝ 1/μ_s, and the linear blend lies above it: `hazy`, single
/// scattering from the ground under a 5° sun, read +3.2 % looking 3° up and +4.3 % 1° up
/// (40 μ_s samples; the same with 120 samples or this blend: −0.1 to −1.0 %), +0.3 % under a
/// 10° sun (−0.2 … +0.1 % with it). Under a 30° sun it changes nothing measurable (`earth`,
/// `hazy`, < 0.02 %), so the cells above 20° keep Bruneton's linear blend (and its cost).
/// `examples/order_by_order.rs`, docs/accuracy.md ("Haze: graded ray samples").
pub const LOG_BLEND_MAX_SUN_ELEVATION_DEG: f64 = 20.0;

/// The number of μ_s cells [i, i + 1], from i = 0, that [`blend`] interpolates for `n` μ_s
/// samples: those whose upper sample has the sun at or below
/// [`LOG_BLEND_MAX_SUN_ELEVATION_DEG`] at the ground (all the twilight cells, μ_s ≤ 0, and
/// the low sun's). The GPU's uniform holds it (`mu_s_twilight_cells`).
pub fn twilight_cells(radii: &Radii, n: usize) -> usize {
    // Sample i lies at x = i/(n − 1) (texcoord_from_unit); the last at or below the
    // elevation is the floor of x(μ_s)·(n − 1), and every cell below it has both ends there.
    let mu_s = LOG_BLEND_MAX_SUN_ELEVATION_DEG.to_radians().sin();
    let last = (x_mu_s(radii, mu_s) * (n - 1) as f64).floor();
    (last.max(0.0) as usize).min(n - 1)
}

/// [`twilight_cells`] of the irradiance table, whose `n` columns are linear in μ_s over
/// [−1, 1] (`params::irradiance_uv`): the cells below the last column with μ_s ≤ 0. The
/// sky's irradiance falls in twilight as the sky does, and its columns lie 1.8° apart
/// (64): their linear blend made the ground's light, and with it the air below 1 km lit
/// by the ground, +12 to +16 % too bright at −6° (against 4× the columns), the worst
/// downward views from 1 km against the reference.
pub fn irradiance_twilight_cells(n: usize) -> usize {
    (n - 1) / 2
}

/// Linear filter weights along μ_s at texture coordinate `u` over `n` samples, and whether
/// the cell is one of the `twilight_cells` that [`blend`] interpolates.
#[derive(Clone, Copy, Debug)]
pub struct MuSFilter {
    /// The sample below s0 (s0 itself at the first sample: no neighbour).
    pub below: usize,
    /// Lower sample.
    pub s0: usize,
    /// Upper sample.
    pub s1: usize,
    /// The sample above s1 (s1 itself at the last sample: no neighbour).
    pub above: usize,
    /// Fraction of the way from s0 to s1.
    pub t: f64,
    /// The cell takes the twilight blend ([`blend`]).
    pub geometric: bool,
}

impl MuSFilter {
    /// The filter at texture coordinate `u`.
    #[inline]
    pub fn new(u: f64, n: usize, twilight_cells: usize) -> MuSFilter {
        let (s0, s1, t) = lerp_weights(u, n);
        MuSFilter::from_weights(s0, s1, t, n, twilight_cells)
    }

    /// The filter of known linear weights (s0, s1, t) over `n` samples.
    #[inline]
    pub fn from_weights(
        s0: usize,
        s1: usize,
        t: f64,
        n: usize,
        twilight_cells: usize,
    ) -> MuSFilter {
        let geometric = s0 < twilight_cells;
        // In a twilight cell a lookup at a sample (the density pass reads the previous order
        // at its texels' own μ_s, t ≈ 10⁻¹³) is that sample: no blend to make.
        let (s0, t) = match geometric {
            true if t < SAMPLE_SNAP => (s0, 0.0),
            true if t > 1.0 - SAMPLE_SNAP => (s1, 0.0),
            _ => (s0, t),
        };
        let s1 = if t == 0.0 { s0 } else { s1 };
        MuSFilter {
            below: s0.saturating_sub(1),
            s0,
            s1,
            above: (s1 + 1).min(n - 1),
            t,
            // A cell whose blend is all one end is that end under either rule.
            geometric: geometric && t > 0.0,
        }
    }
}

/// How close to a sample (in the fraction of a cell) a twilight lookup reads the sample
/// (and a lookup along r its row, [`super::r_blend`]).
pub const SAMPLE_SNAP: f64 = 1e-5;

/// The twilight blend at `t` of the cell's samples `a` (t = 0) and `b` (t = 1), with the
/// outer neighbours `below` (of a) and `above` (of b), each `None` where the table has
/// none: the Catmull–Rom cubic in log L (tangents from the central differences of ln L,
/// from the cell's chord on a side whose neighbour is missing or unlit); linear where a or
/// b is not positive (an unlit sample), where a logarithm means nothing.
#[inline]
pub fn blend(below: Option<f64>, a: f64, b: f64, above: Option<f64>, t: f64) -> f64 {
    let ln_of = |v: Option<f64>| v.map_or(f64::NAN, ln);
    blend_logs(ln_of(below), ln(a), ln(b), ln_of(above), a, b, t)
}

/// [`blend`] from the samples' natural logarithms (`ln_below`, `ln_a`, `ln_b`, `ln_above`;
/// NaN or −∞ for a missing or unlit one), and `a`, `b` themselves for the linear fallback.
#[inline]
pub fn blend_logs(
    ln_below: f64,
    ln_a: f64,
    ln_b: f64,
    ln_above: f64,
    a: f64,
    b: f64,
    t: f64,
) -> f64 {
    if !(ln_a.is_finite() && ln_b.is_finite()) {
        return a + t * (b - a);
    }
    let m0 = tangent(ln_below, ln_a, ln_b);
    let m1 = tangent(ln_a, ln_b, ln_above);
    hermite_exp(ln_a, ln_b, m0, m1, t)
}

/// The tangent of ln L at a sample (per cell) from ln L there and at its neighbours: the
/// harmonic mean of the two secants where they agree in sign, 0 at an extremum (Fritsch &
/// Butland 1984, the PCHIP rule); the one finite secant where a neighbour is missing or
/// unlit (NaN or −∞). Depends on the sample only, so the blend is C¹ across the samples.
#[inline]
pub fn tangent(ln_prev: f64, ln_s: f64, ln_next: f64) -> f64 {
    let (d0, d1) = (ln_s - ln_prev, ln_next - ln_s);
    match (d0.is_finite(), d1.is_finite()) {
        (true, true) if d0 * d1 > 0.0 => 2.0 * d0 * d1 / (d0 + d1),
        (true, true) => 0.0,
        (true, false) => d0,
        (false, true) => d1,
        (false, false) => 0.0,
    }
}

/// e^h(t) of the cubic Hermite h with h(0) = l0, h(1) = l1, h′(0) = m0, h′(1) = m1
/// ([`hermite`]).
#[inline]
pub fn hermite_exp(l0: f64, l1: f64, m0: f64, m1: f64, t: f64) -> f64 {
    exp(hermite(l0, l1, m0, m1, t))
}

/// The cubic Hermite h(t) with h(0) = l0, h(1) = l1, h′(0) = m0, h′(1) = m1, in the form
/// l0 + t·(c + (1 − t)·((m0 − c)(1 − t) − (m1 − c)t)), c = l1 − l0. With [`tangent`]'s
/// tangents (at most twice the cell's chord, of its sign) it is monotone: between l0
/// and l1 (Fritsch & Carlson 1980).
#[inline]
pub fn hermite(l0: f64, l1: f64, m0: f64, m1: f64, t: f64) -> f64 {
    let chord = l1 - l0;
    let u = 1.0 - t;
    l0 + t * (chord + u * ((m0 - chord) * u - (m1 - chord) * t))
}

/// [`blend`] of the samples of `filter` in `data` at the offsets `base + sample·stride`.
#[inline]
pub fn blend_at<T: Copy + Into<f64>>(
    data: &[T],
    base: usize,
    stride: usize,
    filter: &MuSFilter,
) -> f64 {
    let at = |s: usize| data[base + s * stride].into();
    blend(
        (filter.below != filter.s0).then(|| at(filter.below)),
        at(filter.s0),
        at(filter.s1),
        (filter.above != filter.s1).then(|| at(filter.above)),
        filter.t,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sky::bruneton4d::params::mu_s_from_x;

    const EARTH: Radii = crate::sky::bruneton4d::params::EARTH_RADII;

    #[test]
    fn the_log_blend_cells_end_at_the_last_sample_below_the_low_sun() {
        let highest = LOG_BLEND_MAX_SUN_ELEVATION_DEG.to_radians().sin();
        for n in [20, 32, 40, 64] {
            let k = twilight_cells(&EARTH, n);
            let mu_s = |i: usize| mu_s_from_x(&EARTH, i as f64 / (n - 1) as f64);
            assert!(mu_s(k) <= highest, "n {n}: sample {k} at μ_s {}", mu_s(k));
            assert!(
                mu_s(k + 1) > highest,
                "n {n}: sample {} at μ_s {}",
                k + 1,
                mu_s(k + 1)
            );
        }
        // Earth's 40 samples: 26 cells, from −12° to 19.1° (the next sample is at 24.5°),
        // the first 11 (to −0.05°) in the twilight.
        assert_eq!(twilight_cells(&EARTH, 40), 26);
    }

    #[test]
    fn the_blend_follows_a_log_quadratic_and_passes_through_the_samples() {
        // ln f quadratic in the coordinate (a twilight brightness whose shadow rises with the
        // square of the depression): within 3 %, and a third of the chord's error or less.
        let f = |x: f64| 3.0 * (-2.3 * x - 0.7 * x * x).exp();
        for t in [0.1, 0.3, 0.5, 0.7, 0.9] {
            let v = blend(Some(f(-1.0)), f(0.0), f(1.0), Some(f(2.0)), t);
            let chord = f(0.0) * (f(1.0) / f(0.0)).powf(t);
            let (e, e_chord) = ((v / f(t) - 1.0).abs(), (chord / f(t) - 1.0).abs());
            assert!(
                e < 0.03 && e < e_chord / 3.0,
                "t {t}: {e} (chord {e_chord})"
            );
        }
        for t in [0.0, 1.0] {
            let v = blend(Some(f(-1.0)), f(0.0), f(1.0), Some(f(2.0)), t);
            assert!((v / f(t) - 1.0).abs() < 1e-9);
        }
        // Without neighbours: the chord in log, exact for an exponential.
        let g = |x: f64| 3.0 * (-2.3 * x).exp();
        for t in [0.1, 0.5, 0.9] {
            let v = blend(None, g(0.0), g(1.0), Some(0.0), t);
            assert!((v / g(t) - 1.0).abs() < 1e-12);
        }
        // Unlit samples: linear.
        assert_eq!(blend(None, 0.0, 2.0, None, 0.25), 0.5);
        assert_eq!(blend(Some(1.0), 2.0, 0.0, Some(1.0), 0.25), 1.5);
        assert!((blend(Some(9.0), 5.0, 7.0, Some(1.0), 0.0) - 5.0).abs() < 1e-12);
        assert!((blend(Some(9.0), 5.0, 7.0, Some(1.0), 1.0) - 7.0).abs() < 1e-12);
    }
}

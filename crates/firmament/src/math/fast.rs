//! Elementary functions several times cheaper than libm's, to the precision the f32 tables
//! and textures need, for the hottest loops: the tables' blends in r and μ_s (every sky
//! lookup of a cloudy frame: 16 channels × 4 texels × three tables), the noise lattices.
//!
//! Each comes as a checked form (`exp`, `ln`: libm's special values) over a branch-free
//! core valid on a stated range (`exp_in_range`, `ln_normal`), so that loops over a
//! texel's channels can call the core with an argument known to be in range and the
//! compiler keeps them free of branches (and vectorises them where it can).

use std::f64::consts::{LN_2, LOG2_E};

/// Round to nearest by the 1.5·2⁵² trick (`f64::round` is a libm call on baseline x86-64):
/// exact for |x| < 2⁵¹.
const ROUND: f64 = 6_755_399_441_055_744.0;

/// e^x to 10⁻¹³ relative (libm's 10⁻¹⁶; the tables it serves hold f32), several times
/// cheaper than libm's: the blends run in the precomputation's hottest loop. 0 below
/// e^{−708}, ∞ above e^{709}, NaN for NaN.
#[inline]
pub fn exp(x: f64) -> f64 {
    if !(-708.0..=709.0).contains(&x) {
        return if x > 0.0 {
            f64::INFINITY
        } else if x < 0.0 {
            0.0
        } else {
            f64::NAN
        };
    }
    exp_in_range(x)
}

/// [`exp`] without its checks: x must lie in [−708, 709] (else the result is garbage).
/// e^x = 2^i·2^{j/64}·e^f with 64·i + j = k = round(x·64/ln 2), |f| ≤ ln 2/128: 2^{j/64}
/// from a table, e^f by its Taylor series to degree 5 (remainder 0.0055⁶/6! < 4·10⁻¹⁷).
#[inline]
pub fn exp_in_range(x: f64) -> f64 {
    let shifted = x * (64.0 * LOG2_E) + ROUND;
    let k = shifted - ROUND;
    let f = x - k * (LN_2 / 64.0);
    let p = 1.0 + f * (1.0 + f * (0.5 + f * (1.0 / 6.0 + f * (1.0 / 24.0 + f * (1.0 / 120.0)))));
    // k's bits from the shifted sum's without an integer conversion (so that loops of it
    // vectorise): its low bits hold k (two's complement, |k| < 2⁵¹) above ROUND's, whose
    // low 12 bits are 0; j = k mod 64, and (k >> 6) + 1023 = i + 1023 ∈ [1, 2046] is 2^i's
    // exponent (the shift keeps only those 12 bits).
    let bits = shifted.to_bits();
    let two_i = f64::from_bits((bits >> 6).wrapping_add(1023) << 52);
    EXP2_SIXTY_FOURTHS[(bits & 63) as usize] * p * two_i
}

/// 2^{j/64}, j = 0 … 63, for [`exp_in_range`].
const EXP2_SIXTY_FOURTHS: [f64; 64] = {
    let mut t = [0.0; 64];
    let mut j = 0;
    while j < 64 {
        t[j] = series_exp(j as f64 * (LN_2 / 64.0));
        j += 1;
    }
    t
};

/// e^x for 0 ≤ x < 1 by its Taylor series to degree 25 (remainder < 10⁻²⁶), at compile time.
const fn series_exp(x: f64) -> f64 {
    let (mut sum, mut term, mut n) = (1.0, 1.0, 1);
    while n <= 25 {
        term = term * x / n as f64;
        sum += term;
        n += 1;
    }
    sum
}

/// ln y for ½ ≤ y ≤ 2 by 2 atanh((y − 1)/(y + 1)) to z⁸¹ (|z| ≤ ⅓: remainder < 10⁻⁴⁰), at
/// compile time.
const fn series_ln(y: f64) -> f64 {
    let z = (y - 1.0) / (y + 1.0);
    let (mut sum, mut power, mut n) = (0.0, z, 1);
    while n <= 81 {
        sum += power / n as f64;
        power *= z * z;
        n += 2;
    }
    2.0 * sum
}

/// ln x to 10⁻¹⁵ absolute over [½, 2], 10⁻¹³ (5 ulp of the result) far from it, for normal
/// positive x, several times cheaper than libm's; −∞
/// at 0 and NaN below (as `f64::ln`), also for subnormals (never a table's radiance).
#[inline]
pub fn ln(x: f64) -> f64 {
    if x.is_nan() || x < 0.0 {
        return f64::NAN;
    }
    if x < f64::MIN_POSITIVE {
        return f64::NEG_INFINITY;
    }
    if x == f64::INFINITY {
        return x;
    }
    ln_normal(x)
}

/// [`ln`] without its checks: x must be positive, normal and finite. x = 2^e·m, m ∈ [1, 2);
/// c_j ≈ 1 + j/128 with j the top 7 bits of m's fraction, ln m = ln c_j + ln(1 + r),
/// r = m/c_j − 1 ∈ [0, 1/128), by its series to r⁶ (remainder < 3·10⁻¹⁶); 1/c_j and ln c_j
/// from tables (c_j = 1/(1/c_j)'s stored value, so that the sum is exact to rounding, and
/// ln 1 = 0 exactly).
#[inline]
pub fn ln_normal(x: f64) -> f64 {
    let bits = x.to_bits();
    let m = f64::from_bits((bits & 0x000f_ffff_ffff_ffff) | 0x3ff0_0000_0000_0000);
    // The exponent as a float without an integer conversion: 2⁵² + e + 1023 built from
    // its bits.
    let e =
        f64::from_bits(0x4330_0000_0000_0000 | (bits >> 52)) - (4_503_599_627_370_496.0 + 1023.0);
    let j = ((bits >> 45) & 127) as usize;
    let (inverse, ln_c) = LN_TABLE[j];
    let r = m * inverse - 1.0;
    let p = r * (1.0 - r * (0.5 - r * (1.0 / 3.0 - r * (0.25 - r * (0.2 - r * (1.0 / 6.0))))));
    e * LN_2 + ln_c + p
}

/// (1/c_j, ln c_j) for c_j ≈ 1 + j/128, j = 0 … 127, for [`ln_normal`].
const LN_TABLE: [(f64, f64); 128] = {
    let mut t = [(0.0, 0.0); 128];
    let mut j = 0;
    while j < 128 {
        let inverse = 1.0 / (1.0 + j as f64 / 128.0);
        t[j] = (inverse, -series_ln(inverse));
        j += 1;
    }
    t
};

/// ⌊x⌋ for |x| < 2⁶³ without libm's call (`f64::floor` is one on baseline x86-64, 5 % of a
/// cloudy frame in the noise lattices); NaN gives 0.
#[inline]
pub fn floor(x: f64) -> f64 {
    let t = x as i64 as f64;
    if t > x {
        t - 1.0
    } else {
        t
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_fast_exponential_and_logarithm_match_libm() {
        let mut worst: f64 = 0.0;
        for j in -70_000..=70_000 {
            let x = j as f64 * 0.01;
            worst = worst.max((exp(x) / x.exp() - 1.0).abs());
        }
        assert!(worst < 2e-13, "exp: worst relative error {worst}");
        let mut worst: f64 = 0.0;
        for j in -3000..=3000 {
            let x = 10f64.powf(j as f64 * 0.1) * 1.2345;
            worst = worst.max((ln(x) - x.ln()).abs());
        }
        assert!(worst < 3e-13, "ln: worst absolute error {worst}");
        let mut worst: f64 = 0.0;
        for j in 0..=100_000 {
            let x = 0.5 + 1.5 * j as f64 / 100_000.0;
            worst = worst.max((ln(x) - x.ln()).abs());
        }
        assert!(
            worst < 1e-15,
            "ln over [½, 2]: worst absolute error {worst}"
        );
        // Either side of a table's cell edge and of powers of 2.
        let edge = 1.0 + 37.0 / 128.0;
        for x in [
            edge * (1.0 - 1e-16),
            edge,
            2.0,
            0.5,
            1.0 - 1e-16,
            1.0 + 1e-15,
        ] {
            assert!((ln(x) - x.ln()).abs() < 4e-16, "ln {x}");
        }
        assert!((ln(f64::MIN_POSITIVE) / f64::MIN_POSITIVE.ln() - 1.0).abs() < 1e-15);
        assert_eq!(exp(0.0), 1.0);
        assert_eq!(exp(-800.0), 0.0);
        assert_eq!(exp(800.0), f64::INFINITY);
        assert!(exp(f64::NAN).is_nan());
        assert_eq!(ln(0.0), f64::NEG_INFINITY);
        assert!(ln(-1.0).is_nan() && ln(f64::NAN).is_nan());
        assert_eq!(ln(1.0), 0.0);
    }

    #[test]
    fn the_fast_floor_is_the_floor() {
        for x in [
            -3.5,
            -3.0,
            -2.999,
            -1e-300,
            -0.0,
            0.0,
            1e-300,
            0.5,
            1.0,
            2.75,
            1e15 + 0.5,
            -1e15 - 0.5,
        ] {
            assert_eq!(floor(x), x.floor(), "{x}");
        }
        let mut s = 0.123_f64;
        for _ in 0..10_000 {
            s = (s * 9_301.0 + 49_297.0) % 233_280.0;
            let x = (s / 233_280.0 - 0.5) * 1e4;
            assert_eq!(floor(x), x.floor(), "{x}");
        }
    }
}

//! Tileable noise for the clouds' shapes: gradient (Perlin) noise and cellular (Worley)
//! noise on a periodic lattice, so that a volume made of them repeats without a seam, and
//! their fractal sums. Coordinates are in lattice cells; `period` cells make one tile.
//!
//! - Gradient noise: Perlin (2002), "Improving noise" (quintic fade 6t⁵ − 15t⁴ + 10t³,
//!   gradients towards the cube's 12 edge midpoints), the lattice taken modulo the period.
//! - Cellular noise: Worley (1996), "A cellular texture basis function" (one feature point
//!   per cell, the distance to the nearest over the 27 cells around), inverted (1 − F₁) as
//!   Schneider (2015, "The real-time volumetric cloudscapes of Horizon: Zero Dawn") uses it
//!   for billows.
//! - The Perlin–Worley mix of the base shape follows Schneider (2015) and Hillaire (2016,
//!   §5.4, seed `hillaire-2016…` "Cloud noise"): Perlin fBm remapped into the Worley fBm's
//!   range, so the cells round the gradient noise's wisps into puffs.

use crate::math::hash::lowbias32;

/// A hash of a 3D lattice point with a salt.
#[inline]
fn hash3(salt: u32, x: i32, y: i32, z: i32) -> u32 {
    lowbias32(x as u32 ^ lowbias32(y as u32 ^ lowbias32(z as u32 ^ lowbias32(salt))))
}

/// A uniform value in [0, 1) from a hash's top 24 bits.
#[inline]
fn unit(h: u32) -> f64 {
    (h >> 8) as f64 / (1u32 << 24) as f64
}

/// Perlin's quintic fade.
#[inline]
fn fade(t: f64) -> f64 {
    t * t * t * (t * (t * 6.0 - 15.0) + 10.0)
}

/// The lattice coordinate `i` modulo `period` (non-negative).
#[inline]
fn wrap(i: i64, period: u32) -> i32 {
    i.rem_euclid(period as i64) as i32
}

/// The dot product of the gradient hashed at a lattice corner with the offset (x, y, z)
/// (Perlin 2002: 12 edge directions, the hash's low 4 bits, 4 of them repeated).
#[inline]
fn grad(h: u32, x: f64, y: f64, z: f64) -> f64 {
    match h & 15 {
        0 | 12 => x + y,
        1 | 13 => -x + y,
        2 => x - y,
        3 => -x - y,
        4 => x + z,
        5 => -x + z,
        6 => x - z,
        7 => -x - z,
        8 => y + z,
        9 | 14 => -y + z,
        10 => y - z,
        _ => -y - z,
    }
}

/// Gradient noise at `p` (cells) with the lattice repeating every `period` cells; about
/// [−1, 1], 0 at the lattice points.
pub fn perlin(p: [f64; 3], period: u32, salt: u32) -> f64 {
    let cell = p.map(|v| v.floor());
    let f = [p[0] - cell[0], p[1] - cell[1], p[2] - cell[2]];
    let c = cell.map(|v| v as i64);
    let corner = |dx: i64, dy: i64, dz: i64| {
        let h = hash3(
            salt,
            wrap(c[0] + dx, period),
            wrap(c[1] + dy, period),
            wrap(c[2] + dz, period),
        );
        grad(h, f[0] - dx as f64, f[1] - dy as f64, f[2] - dz as f64)
    };
    let (u, v, w) = (fade(f[0]), fade(f[1]), fade(f[2]));
    let lerp = |a: f64, b: f64, t: f64| a + (b - a) * t;
    let x00 = lerp(corner(0, 0, 0), corner(1, 0, 0), u);
    let x10 = lerp(corner(0, 1, 0), corner(1, 1, 0), u);
    let x01 = lerp(corner(0, 0, 1), corner(1, 0, 1), u);
    let x11 = lerp(corner(0, 1, 1), corner(1, 1, 1), u);
    lerp(lerp(x00, x10, v), lerp(x01, x11, v), w)
}

/// Inverted cellular noise 1 − F₁ at `p` (cells), F₁ the distance (cells) to the nearest
/// feature point, one per cell, the cells repeating every `period`; in [0, 1] (F₁ ≤ √3 is
/// clamped at 1).
pub fn worley(p: [f64; 3], period: u32, salt: u32) -> f64 {
    let cell = p.map(|v| v.floor());
    let c = cell.map(|v| v as i64);
    let mut nearest2 = f64::INFINITY;
    for dz in -1..=1 {
        for dy in -1..=1 {
            for dx in -1..=1 {
                let (i, j, k) = (c[0] + dx, c[1] + dy, c[2] + dz);
                let h = hash3(salt, wrap(i, period), wrap(j, period), wrap(k, period));
                let (h1, h2) = (lowbias32(h), lowbias32(h ^ 0x9e37_79b9));
                let feature = [i as f64 + unit(h), j as f64 + unit(h1), k as f64 + unit(h2)];
                let d2 = (0..3).map(|a| (feature[a] - p[a]).powi(2)).sum::<f64>();
                nearest2 = nearest2.min(d2);
            }
        }
    }
    1.0 - nearest2.sqrt().min(1.0)
}

/// A fractal sum of `octaves` layers of `noise`, each at twice the frequency (and period)
/// of the one before and `gain` times its amplitude, normalised by the amplitudes' sum.
pub fn fbm(
    noise: fn([f64; 3], u32, u32) -> f64,
    p: [f64; 3],
    period: u32,
    salt: u32,
    octaves: u32,
    gain: f64,
) -> f64 {
    let (mut sum, mut norm, mut amplitude, mut scale) = (0.0, 0.0, 1.0, 1.0);
    for o in 0..octaves {
        let q = p.map(|v| v * scale);
        sum += amplitude * noise(q, period * scale as u32, salt.wrapping_add(o));
        norm += amplitude;
        amplitude *= gain;
        scale *= 2.0;
    }
    sum / norm
}

/// Remap `v` from [lo, hi] to [new_lo, new_hi] (Schneider 2015), unclamped.
#[inline]
pub fn remap(v: f64, lo: f64, hi: f64, new_lo: f64, new_hi: f64) -> f64 {
    new_lo + (v - lo) / (hi - lo) * (new_hi - new_lo)
}

/// The base shape at `p` (cells of the lowest frequency, `period` of them per tile): Perlin
/// fBm (3 octaves) in [0, 1] remapped into [W₁, 1], W₁ the Worley fBm at frequencies 1–4
/// (the cells round the gradient noise's wisps into puffs), then eroded from below by
/// 1 − W₂, W₂ the Worley fBm at frequencies 2–8 (Schneider 2015's low-frequency fBm:
/// `remap(pw, W₂ − 1, 1, 0, 1)`), so that the result has billows with gaps between them;
/// in [0, 1].
pub fn perlin_worley(p: [f64; 3], period: u32, salt: u32) -> f64 {
    let perlin01 = (0.5 + 0.7 * fbm(perlin, p, period, salt, 3, 0.5)).clamp(0.0, 1.0);
    let w1 = worley_fbm(p, period, salt ^ 0x5bd1_e995);
    let pw = remap(perlin01, 0.0, 1.0, w1, 1.0);
    let w2 = worley_fbm(p.map(|v| 2.0 * v), 2 * period, salt ^ 0x27d4_eb2f);
    remap(pw, w2 - 1.0, 1.0, 0.0, 1.0).clamp(0.0, 1.0)
}

/// Worley fBm of three octaves at frequencies 1, 2 and 4 with weights 0.625, 0.25 and 0.125
/// (Schneider 2015's erosion and dilation weights); in [0, 1].
pub fn worley_fbm(p: [f64; 3], period: u32, salt: u32) -> f64 {
    let at = |f: f64, o: u32| worley(p.map(|v| v * f), period * f as u32, salt.wrapping_add(o));
    0.625 * at(1.0, 0) + 0.25 * at(2.0, 1) + 0.125 * at(4.0, 2)
}

/// Tileable 2D gradient noise (the weather map's): [`perlin`] on the plane z = 0.5 of a
/// lattice repeating every `period` cells in x and y.
pub fn perlin2(x: f64, y: f64, period: u32, salt: u32) -> f64 {
    perlin([x, y, 0.5], period, salt)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn noises_tile_with_their_period() {
        for &(x, y, z) in &[(0.3, 1.7, 2.2), (3.9, 0.1, 0.5), (2.5, 2.5, 3.99)] {
            for period in [4u32, 5] {
                let p = [x, y, z];
                let shifted = [
                    x + period as f64,
                    y - period as f64,
                    z + 2.0 * period as f64,
                ];
                for f in [perlin, worley, perlin_worley, worley_fbm] {
                    assert!((f(p, period, 7) - f(shifted, period, 7)).abs() < 1e-12);
                }
            }
        }
    }

    #[test]
    fn noises_stay_in_their_ranges_and_vary() {
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        let (mut wlo, mut whi) = (f64::INFINITY, f64::NEG_INFINITY);
        for i in 0..4000 {
            let p = [
                (i % 17) as f64 * 0.23,
                (i / 17 % 13) as f64 * 0.31,
                (i / 221) as f64 * 0.29,
            ];
            let v = perlin(p, 8, 1);
            lo = lo.min(v);
            hi = hi.max(v);
            let w = worley(p, 8, 1);
            wlo = wlo.min(w);
            whi = whi.max(w);
            let pw = perlin_worley(p, 8, 1);
            assert!((0.0..=1.0).contains(&pw));
        }
        assert!(
            lo >= -1.05 && hi <= 1.05 && hi - lo > 1.0,
            "perlin [{lo}, {hi}]"
        );
        assert!(
            wlo >= 0.0 && whi <= 1.0 && whi - wlo > 0.6,
            "worley [{wlo}, {whi}]"
        );
    }

    #[test]
    fn perlin_vanishes_on_the_lattice() {
        assert_eq!(perlin([2.0, 3.0, 1.0], 4, 9), 0.0);
    }
}

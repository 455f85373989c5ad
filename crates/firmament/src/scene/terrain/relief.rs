//! The procedural relief: ridged multifractal mountains (Musgrave, in Ebert et al. 2003,
//! *Texturing and Modeling*, 3rd ed., ch. 16) with erosion-like detail (octaves damped where
//! the accumulated slope is steep, so slopes stay smooth and detail gathers in valleys and
//! on ridges: Quilez 2008, "Terrain raymarching", the "Elevated" demo), carved by a valley
//! through the observer and faded into the sphere at the edges.
//!
//! Noise: gradient noise (Perlin 2002, "Improving noise", SIGGRAPH) with the quintic fade
//! and its analytic derivative, seeded by hashing the lattice point with the seed.

use rayon::prelude::*;

use super::grid::Grid;
use crate::math::smoothstep;

/// The parameters of the procedural relief.
#[derive(Clone, Debug, PartialEq)]
pub struct ReliefParams {
    /// Seed of the noise.
    pub seed: u64,
    /// Side of the square grid (m).
    pub extent_m: f64,
    /// Vertices per side.
    pub resolution: usize,
    /// Height of the highest ridges above the valley floor (m, about).
    pub height_scale_m: f64,
    /// Wavelength of the largest mountains (m).
    pub feature_size_m: f64,
    /// Height of the valley floor above the sphere (m).
    pub floor_m: f64,
    /// Half-width of the valley carved through the grid's centre (m; 0: none).
    pub valley_width_m: f64,
    /// Heading of the valley's axis (degrees clockwise from north).
    pub valley_heading_deg: f64,
    /// Plane coordinates (east, north; m) of the grid's centre relative to the observer.
    pub centre_m: [f64; 2],
}

/// Octaves of the detail (down to about feature_size / 2^OCTAVES).
const OCTAVES: usize = 11;

/// The heights (m above the sphere) of the relief.
pub fn relief(p: &ReliefParams) -> Grid {
    let n = p.resolution;
    let spacing = p.extent_m / (n - 1) as f64;
    let half = 0.5 * p.extent_m;
    let origin = [p.centre_m[0] - half, p.centre_m[1] - half];
    let (hs, hc) = p.valley_heading_deg.to_radians().sin_cos();
    let mut values = vec![0.0f32; n * n];
    values.par_chunks_mut(n).enumerate().for_each(|(j, row)| {
        for (i, v) in row.iter_mut().enumerate() {
            let (x, y) = (
                origin[0] + i as f64 * spacing,
                origin[1] + j as f64 * spacing,
            );
            let m = mountains(p.seed, x / p.feature_size_m, y / p.feature_size_m);
            // The valley: distance from the axis through the observer along the heading.
            let across = (x * hc - y * hs).abs();
            let valley = if p.valley_width_m > 0.0 {
                0.12 + 0.88 * smoothstep(0.3 * p.valley_width_m, 2.2 * p.valley_width_m, across)
            } else {
                1.0
            };
            // Fade into the sphere over the outer 12 % of each side.
            let edge = |c: f64, o: f64| {
                let d = (c - o).abs() / half;
                1.0 - smoothstep(0.88, 1.0, d)
            };
            let fade = edge(x, p.centre_m[0]) * edge(y, p.centre_m[1]);
            *v = ((p.floor_m + p.height_scale_m * m * valley) * fade).max(0.0) as f32;
        }
    });
    Grid {
        nx: n,
        ny: n,
        origin,
        spacing_m: spacing,
        axis: [1.0, 0.0],
        values,
    }
}

/// Mountains at (x, y) in units of the feature size: 0 to about 1.
fn mountains(seed: u64, x: f64, y: f64) -> f64 {
    // Ridged multifractal: sharp crests from 1 − |n|, each octave weighted by the previous
    // one's signal (rough heights on top, smooth valleys).
    let (mut px, mut py) = (x, y);
    let mut sum = 0.0;
    let mut weight = 1.0;
    let mut amplitude = 1.0;
    let mut norm = 0.0;
    for o in 0..4 {
        let (n, _, _) = noise(seed.wrapping_add(o as u64 * 0x9e37), px, py);
        let ridge = (1.0 - n.abs() * 1.6).max(0.0);
        let signal = ridge * ridge * weight;
        weight = (signal * 1.8).clamp(0.0, 1.0);
        sum += signal * amplitude;
        norm += amplitude;
        amplitude *= 0.5;
        (px, py) = rotate2(px, py);
    }
    let ridges = sum / norm;
    // Erosion-like detail: octaves damped by the accumulated gradient.
    let (mut px, mut py) = (x * 4.0 + 17.3, y * 4.0 - 5.1);
    let (mut dx, mut dy) = (0.0, 0.0);
    let mut detail = 0.0;
    let mut amplitude = 0.5;
    for o in 0..OCTAVES - 4 {
        let (n, nx, ny) = noise(seed.wrapping_add(0x51 + o as u64 * 0x7f4a), px, py);
        dx += nx;
        dy += ny;
        detail += amplitude * n / (1.0 + dx * dx + dy * dy);
        amplitude *= 0.5;
        let (rx, ry) = rotate2(px, py);
        (px, py) = (rx, ry);
        (dx, dy) = rotate2(dx, dy);
    }
    // Detail grows with height (bare rock above, smooth meadows below).
    (ridges * (1.0 + 0.25 * detail) + 0.08 * detail).max(0.0)
}

/// Doubles the frequency and turns by about 37° (no lattice alignment between octaves).
#[inline]
fn rotate2(x: f64, y: f64) -> (f64, f64) {
    (1.6 * x - 1.2 * y, 1.2 * x + 1.6 * y)
}

/// Gradient noise in [−1, 1] and its derivatives at (x, y).
fn noise(seed: u64, x: f64, y: f64) -> (f64, f64, f64) {
    let (xi, yi) = (x.floor(), y.floor());
    let (fx, fy) = (x - xi, y - yi);
    let (ix, iy) = (xi as i64, yi as i64);
    let g = |dx: i64, dy: i64| {
        let h = hash(seed, ix + dx, iy + dy);
        let a = (h >> 11) as f64 * (std::f64::consts::TAU / (1u64 << 53) as f64);
        (a.cos(), a.sin())
    };
    let (g00, g10, g01, g11) = (g(0, 0), g(1, 0), g(0, 1), g(1, 1));
    let dot = |g: (f64, f64), x: f64, y: f64| g.0 * x + g.1 * y;
    let (v00, v10, v01, v11) = (
        dot(g00, fx, fy),
        dot(g10, fx - 1.0, fy),
        dot(g01, fx, fy - 1.0),
        dot(g11, fx - 1.0, fy - 1.0),
    );
    // Quintic fade 6t⁵ − 15t⁴ + 10t³ and its derivative.
    let fade = |t: f64| t * t * t * (t * (t * 6.0 - 15.0) + 10.0);
    let dfade = |t: f64| 30.0 * t * t * (t * (t - 2.0) + 1.0);
    let (u, v) = (fade(fx), fade(fy));
    let (du, dv) = (dfade(fx), dfade(fy));
    let k1 = v10 - v00;
    let k2 = v01 - v00;
    let k3 = v11 - v10 - v01 + v00;
    let value = v00 + k1 * u + k2 * v + k3 * u * v;
    let dx = g00.0
        + (g10.0 - g00.0) * u
        + (g01.0 - g00.0) * v
        + (g11.0 - g10.0 - g01.0 + g00.0) * u * v
        + du * (k1 + k3 * v);
    let dy = g00.1
        + (g10.1 - g00.1) * u
        + (g01.1 - g00.1) * v
        + (g11.1 - g10.1 - g01.1 + g00.1) * u * v
        + dv * (k2 + k3 * u);
    // Perlin's 2D gradient noise spans about ±0.7: scaled to ±1.
    (value * 1.41, dx * 1.41, dy * 1.41)
}

/// A 64-bit hash of a lattice point and the seed (SplitMix64 finaliser).
#[inline]
pub(crate) fn hash(seed: u64, x: i64, y: i64) -> u64 {
    let mut z = seed
        ^ (x as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15)
        ^ (y as u64).wrapping_mul(0xc2b2_ae3d_27d4_eb4f);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn noise_derivative_matches_finite_differences() {
        for k in 0..50 {
            let (x, y) = (k as f64 * 0.37 - 3.1, k as f64 * 0.71 + 0.2);
            let (_, dx, dy) = noise(3, x, y);
            let e = 1e-6;
            let fx = (noise(3, x + e, y).0 - noise(3, x - e, y).0) / (2.0 * e);
            let fy = (noise(3, x, y + e).0 - noise(3, x, y - e).0) / (2.0 * e);
            assert!((dx - fx).abs() < 1e-5 && (dy - fy).abs() < 1e-5, "{k}");
        }
    }
}

//! The 3D scattering table (f32, channels innermost, μ_s next): storage and trilinear
//! filtering with GPU semantics (texel i's centre at (i + 0.5)/n, clamp to edge), as the
//! 4D tables' [`crate::sky::bruneton4d::table`].

use crate::sky::bruneton4d::table::lerp_weights;

/// A table over (altitude z, view zenith y, sun zenith x) of `channels` f32 per texel.
#[derive(Clone, Debug, PartialEq)]
pub struct Table3 {
    /// Altitude texels.
    pub nh: usize,
    /// View-zenith texels.
    pub nmu: usize,
    /// Sun-zenith texels.
    pub nmu_s: usize,
    /// Values per texel.
    pub channels: usize,
    /// `data[((z·nmu + y)·nmu_s + x)·channels + c]`.
    pub data: Vec<f32>,
}

/// The eight taps of a trilinear filter at (u_h, u_μ, u_μs): texel indices and weights of
/// the upper ones, computed once for several tables of the same sizes.
#[derive(Clone, Copy, Debug)]
pub struct Taps {
    z: [usize; 2],
    tz: f64,
    y: [usize; 2],
    ty: f64,
    x: [usize; 2],
    tx: f64,
}

impl Table3 {
    /// A zero-filled table.
    pub fn new(nh: usize, nmu: usize, nmu_s: usize, channels: usize) -> Table3 {
        Table3 {
            nh,
            nmu,
            nmu_s,
            channels,
            data: vec![0.0; nh * nmu * nmu_s * channels],
        }
    }

    /// A zero-filled table of the same sizes.
    pub fn like(&self) -> Table3 {
        Table3::new(self.nh, self.nmu, self.nmu_s, self.channels)
    }

    /// Floats in one (z, y) row (every μ_s texel).
    #[inline]
    pub fn row_len(&self) -> usize {
        self.nmu_s * self.channels
    }

    /// Index of texel (z, y, x)'s first channel.
    #[inline]
    pub fn index(&self, z: usize, y: usize, x: usize) -> usize {
        ((z * self.nmu + y) * self.nmu_s + x) * self.channels
    }

    /// The filter taps at texture coordinates `u` = (u_h, u_μ, u_μs).
    #[inline]
    pub fn taps(&self, u: [f64; 3]) -> Taps {
        let (z0, z1, tz) = lerp_weights(u[0], self.nh);
        let (y0, y1, ty) = lerp_weights(u[1], self.nmu);
        let (x0, x1, tx) = lerp_weights(u[2], self.nmu_s);
        Taps {
            z: [z0, z1],
            tz,
            y: [y0, y1],
            ty,
            x: [x0, x1],
            tx,
        }
    }

    /// Trilinear sample at `taps` into `out` (overwritten).
    #[inline]
    pub fn sample_taps_into(&self, taps: &Taps, out: &mut [f64]) {
        let c = self.channels;
        out[..c].iter_mut().for_each(|o| *o = 0.0);
        let wz = [1.0 - taps.tz, taps.tz];
        let wy = [1.0 - taps.ty, taps.ty];
        let wx = [1.0 - taps.tx, taps.tx];
        for (a, &z) in taps.z.iter().enumerate() {
            for (b, &y) in taps.y.iter().enumerate() {
                let wzy = wz[a] * wy[b];
                if wzy == 0.0 {
                    continue;
                }
                for (e, &x) in taps.x.iter().enumerate() {
                    let w = wzy * wx[e];
                    if w == 0.0 {
                        continue;
                    }
                    let i = self.index(z, y, x);
                    for (o, v) in out[..c].iter_mut().zip(&self.data[i..i + c]) {
                        *o += w * *v as f64;
                    }
                }
            }
        }
    }

    /// Trilinear sample at `u` = (u_h, u_μ, u_μs) into `out` (overwritten).
    #[inline]
    pub fn sample_into(&self, u: [f64; 3], out: &mut [f64]) {
        self.sample_taps_into(&self.taps(u), out);
    }

    /// The table filtered at fixed (u_h, u_μs): a 1D slice over μ, `[y·channels + c]`.
    /// Sampling it with [`Table3::sample_slice_into`] equals [`Table3::sample_into`] at that
    /// (u_h, u_μs) (the filter is separable).
    pub fn slice(&self, u_h: f64, u_mu_s: f64) -> Vec<f64> {
        let (z0, z1, tz) = lerp_weights(u_h, self.nh);
        let (x0, x1, tx) = lerp_weights(u_mu_s, self.nmu_s);
        let c = self.channels;
        let mut out = vec![0.0; self.nmu * c];
        for (y, o) in out.chunks_exact_mut(c).enumerate() {
            for (z, wz) in [(z0, 1.0 - tz), (z1, tz)] {
                for (x, wx) in [(x0, 1.0 - tx), (x1, tx)] {
                    let w = wz * wx;
                    if w == 0.0 {
                        continue;
                    }
                    let i = self.index(z, y, x);
                    for (o, v) in o.iter_mut().zip(&self.data[i..i + c]) {
                        *o += w * *v as f64;
                    }
                }
            }
        }
        out
    }

    /// Sample a [`Table3::slice`] at u_μ into `out` (overwritten).
    #[inline]
    pub fn sample_slice_into(&self, slice: &[f64], u_mu: f64, out: &mut [f64]) {
        let c = self.channels;
        let (y0, y1, t) = lerp_weights(u_mu, self.nmu);
        let (a, b) = (&slice[y0 * c..][..c], &slice[y1 * c..][..c]);
        for ((o, a), b) in out[..c].iter_mut().zip(a).zip(b) {
            *o = (1.0 - t) * a + t * b;
        }
    }

    /// Element-wise a += b.
    pub fn add_assign(&mut self, other: &Table3) {
        for (a, b) in self.data.iter_mut().zip(&other.data) {
            *a += *b;
        }
    }

    /// Mean value per channel over the texels.
    pub fn mean(&self) -> Vec<f64> {
        let c = self.channels;
        let mut sum = vec![0.0; c];
        for texel in self.data.chunks_exact(c) {
            for (s, v) in sum.iter_mut().zip(texel) {
                *s += *v as f64;
            }
        }
        let count = (self.data.len() / c.max(1)).max(1) as f64;
        sum.iter().map(|s| s / count).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn texel_centres_read_their_texel_and_the_slice_matches_the_table() {
        let mut t = Table3::new(3, 4, 5, 2);
        for (i, v) in t.data.iter_mut().enumerate() {
            *v = (i as f32 * 0.37).sin();
        }
        let centre = |i: usize, n: usize| (i as f64 + 0.5) / n as f64;
        let mut out = [0.0; 2];
        t.sample_into([centre(1, 3), centre(2, 4), centre(3, 5)], &mut out);
        let i = t.index(1, 2, 3);
        assert_eq!(out, [t.data[i] as f64, t.data[i + 1] as f64]);
        let (u_h, u_mu, u_mu_s) = (0.41, 0.63, 0.27);
        let slice = t.slice(u_h, u_mu_s);
        let mut from_slice = [0.0; 2];
        t.sample_slice_into(&slice, u_mu, &mut from_slice);
        t.sample_into([u_h, u_mu, u_mu_s], &mut out);
        for k in 0..2 {
            assert!((out[k] - from_slice[k]).abs() < 1e-12);
        }
    }
}

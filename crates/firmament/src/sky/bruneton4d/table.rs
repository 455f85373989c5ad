//! Table storage (f32, channels innermost) and sampling with GPU semantics: texel i's centre
//! at (i + 0.5)/n, bilinear/trilinear filtering with clamp-to-edge, and for the 4D scattering
//! table the packing of Bruneton 2017 (ν and μ_s share the x axis; two 3D fetches and a
//! manual lerp along ν), so CPU and GPU tables compare texel by texel.

use super::mu_s_blend::{blend_at, MuSFilter};
use super::params::TableSizes;

/// Linear-filter weights for texture coordinate `u` over `n` texels: (i0, i1, t).
#[inline]
pub fn lerp_weights(u: f64, n: usize) -> (usize, usize, f64) {
    let x = (u * n as f64 - 0.5).clamp(0.0, (n - 1) as f64);
    // x ≥ 0, so truncation is floor (and avoids a libm call on baseline x86-64); x < 2³¹
    // (n ≤ 4096), so truncating through i32 gives the usize index with a cheaper conversion.
    let i0 = (x as i32 as usize).min(n - 1);
    let i1 = (i0 + 1).min(n - 1);
    (i0, i1, x - i0 as f64)
}

/// The largest optical depth a table holds, standing for a transmittance of 0 in f32 (−ln
/// of the smallest f32 subnormal, 1.4e-45, is 103.3).
pub const MAX_OPTICAL_DEPTH: f32 = 104.0;

/// A 2D table of `channels` f32 per texel, rows of `width` texels.
#[derive(Clone, Debug, PartialEq)]
pub struct Table2 {
    /// Texels along u.
    pub width: usize,
    /// Texels along v.
    pub height: usize,
    /// Values per texel.
    pub channels: usize,
    /// `data[(y·width + x)·channels + c]`.
    pub data: Vec<f32>,
}

impl Table2 {
    /// Zero-filled table.
    pub fn new(width: usize, height: usize, channels: usize) -> Self {
        Table2 {
            width,
            height,
            channels,
            data: vec![0.0; width * height * channels],
        }
    }

    /// The transmittance T = e^{−τ} of an optical-depth table, texel by texel (0 where τ
    /// is [`MAX_OPTICAL_DEPTH`]).
    ///
    /// The optical depth is what the tables keep and the lookups interpolate: near the
    /// horizon at high altitude neighbouring transmittance texels differ by up to 10⁵–10⁶
    /// in the blue (e^{−37} at the horizon column of the top row, e^{−25} one column up),
    /// where a bilinear T is both inaccurate (a linear blend of exponentials) and so
    /// ill-conditioned that one f32 ulp of μ changed the transmittance along a horizon ray
    /// ×10 (the GPU's horizon texels were 9.6 % off the CPU's); the blend of τ is smooth.
    pub fn transmittance_of_optical_depth(&self) -> Table2 {
        Table2 {
            width: self.width,
            height: self.height,
            channels: self.channels,
            data: self
                .data
                .iter()
                .map(|&tau| {
                    if tau < MAX_OPTICAL_DEPTH {
                        (-(tau as f64)).exp() as f32
                    } else {
                        0.0
                    }
                })
                .collect(),
        }
    }

    /// The texel (x, y).
    #[inline]
    pub fn texel(&self, x: usize, y: usize) -> &[f32] {
        let i = (y * self.width + x) * self.channels;
        &self.data[i..i + self.channels]
    }

    /// Bilinear sample at (u, v) into `out` (overwritten).
    #[inline]
    pub fn sample_into(&self, u: f64, v: f64, out: &mut [f64]) {
        let (x0, x1, tx) = lerp_weights(u, self.width);
        let (y0, y1, ty) = lerp_weights(v, self.height);
        let c = self.channels;
        let w = self.width;
        let d = &self.data;
        let (i00, i10, i01, i11) = (
            (y0 * w + x0) * c,
            (y0 * w + x1) * c,
            (y1 * w + x0) * c,
            (y1 * w + x1) * c,
        );
        let (w00, w10, w01, w11) = (
            (1.0 - tx) * (1.0 - ty),
            tx * (1.0 - ty),
            (1.0 - tx) * ty,
            tx * ty,
        );
        for k in 0..c {
            out[k] = w00 * d[i00 + k] as f64
                + w10 * d[i10 + k] as f64
                + w01 * d[i01 + k] as f64
                + w11 * d[i11 + k] as f64;
        }
    }

    /// As [`Table2::sample_into`] for a table whose x axis is μ_s: the first
    /// `twilight_cells` cells along x take the twilight blend ([`super::mu_s_blend`]) per
    /// row, then the rows are blended linearly.
    #[inline]
    pub fn sample_twilight_into(&self, u: f64, v: f64, twilight_cells: usize, out: &mut [f64]) {
        let s = MuSFilter::new(u, self.width, twilight_cells);
        if !s.geometric {
            return self.sample_into(u, v, out);
        }
        let (y0, y1, ty) = lerp_weights(v, self.height);
        let c = self.channels;
        for k in 0..c {
            let row = |y: usize| blend_at(&self.data, y * self.width * c + k, c, &s);
            out[k] = (1.0 - ty) * row(y0) + ty * row(y1);
        }
    }

    /// Element-wise a += b.
    pub fn add_assign(&mut self, other: &Table2) {
        for (a, b) in self.data.iter_mut().zip(&other.data) {
            *a += *b;
        }
    }
}

/// The 4D scattering table packed as a 3D texture: x = ν·N_μs + μ_s, y = μ, z = r.
#[derive(Clone, Debug, PartialEq)]
pub struct Table4 {
    /// r size.
    pub nr: usize,
    /// μ size.
    pub nmu: usize,
    /// μ_s size.
    pub nmu_s: usize,
    /// ν size.
    pub nnu: usize,
    /// Values per texel.
    pub channels: usize,
    /// `data[((z·nmu + y)·(nnu·nmu_s) + x)·channels + c]`.
    pub data: Vec<f32>,
}

impl Table4 {
    /// A zero-filled scattering table of these sizes.
    pub fn for_sizes(sizes: &TableSizes, channels: usize) -> Self {
        Table4::new(
            sizes.scattering_r,
            sizes.scattering_mu,
            sizes.scattering_mu_s,
            sizes.scattering_nu,
            channels,
        )
    }

    /// Zero-filled table.
    pub fn new(nr: usize, nmu: usize, nmu_s: usize, nnu: usize, channels: usize) -> Self {
        Table4 {
            nr,
            nmu,
            nmu_s,
            nnu,
            channels,
            data: vec![0.0; nr * nmu * nmu_s * nnu * channels],
        }
    }

    /// Width of the packed x axis.
    #[inline]
    pub fn width(&self) -> usize {
        self.nnu * self.nmu_s
    }

    /// Floats in one (r, μ) row.
    #[inline]
    pub fn row_len(&self) -> usize {
        self.width() * self.channels
    }

    /// Index of texel (x, y, z).
    #[inline]
    pub fn index(&self, x: usize, y: usize, z: usize) -> usize {
        ((z * self.nmu + y) * self.width() + x) * self.channels
    }

    /// Sample at (u_ν, u_μs, u_μ, u_r) into `out` (overwritten), Bruneton 2017's
    /// `GetScattering`: trilinear in (μ_s, μ, r) at the two nearest ν slices, then a lerp;
    /// the first `twilight_cells` cells along μ_s blend as twilight ([`mu_s_blend`]).
    #[inline]
    pub fn sample_into(&self, uvwz: [f64; 4], twilight_cells: usize, out: &mut [f64]) {
        let (y0, y1, ty) = lerp_weights(uvwz[2], self.nmu);
        let (z0, z1, tz) = lerp_weights(uvwz[3], self.nr);
        let s = MuSFilter::new(uvwz[1], self.nmu_s, twilight_cells);
        self.sample_rows_into(uvwz[0], s, [y0, y1], ty, [z0, z1], tz, out);
    }

    /// As [`Table4::sample_into`] with the μ_s filter and the (μ, r) filter weights already
    /// known (rays whose samples share them).
    #[inline]
    pub fn sample_rows_into(
        &self,
        u_nu: f64,
        s: MuSFilter,
        y: [usize; 2],
        ty: f64,
        z: [usize; 2],
        tz: f64,
        out: &mut [f64],
    ) {
        let tex_x = u_nu * (self.nnu - 1) as f64;
        let nu0 = (tex_x.max(0.0) as usize).min(self.nnu - 1);
        let nu1 = (nu0 + 1).min(self.nnu - 1);
        let tnu = tex_x - nu0 as f64;
        let (s0, s1, ts) = (s.s0, s.s1, s.t);
        let c = self.channels;
        out[..c].iter_mut().for_each(|o| *o = 0.0);
        let wy = [1.0 - ty, ty];
        let wz = [1.0 - tz, tz];
        let wn = [1.0 - tnu, tnu];
        let ws = [1.0 - ts, ts];
        for (a, &zz) in z.iter().enumerate() {
            if wz[a] == 0.0 {
                continue;
            }
            for (b, &yy) in y.iter().enumerate() {
                let wzy = wz[a] * wy[b];
                if wzy == 0.0 {
                    continue;
                }
                let row = (zz * self.nmu + yy) * self.width();
                for (e, &nn) in [nu0, nu1].iter().enumerate() {
                    if s.geometric {
                        let w = wzy * wn[e];
                        if w == 0.0 {
                            continue;
                        }
                        let base = (row + nn * self.nmu_s) * c;
                        for k in 0..c {
                            out[k] += w * blend_at(&self.data, base + k, c, &s);
                        }
                        continue;
                    }
                    for (f, &ss) in [s0, s1].iter().enumerate() {
                        let w = wzy * wn[e] * ws[f];
                        if w == 0.0 {
                            continue;
                        }
                        let i = (row + nn * self.nmu_s + ss) * c;
                        for k in 0..c {
                            out[k] += w * self.data[i + k] as f64;
                        }
                    }
                }
            }
        }
    }

    /// The table filtered at fixed (u_μs, u_r): a 2D (μ, ν) slice, `[(y·nnu + ν)·channels + c]`.
    /// Sampling the slice with [`Table4::sample_slice_into`] equals [`Table4::sample_into`]
    /// at that (u_μs, u_r): the filter is separable, and the twilight cells' blend
    /// ([`super::mu_s_blend`]) is made per texel before the linear filters in both. Used for every pixel of a
    /// frame whose camera and sun are fixed.
    pub fn slice(&self, u_mu_s: f64, u_r: f64, twilight_cells: usize) -> Vec<f64> {
        let s = MuSFilter::new(u_mu_s, self.nmu_s, twilight_cells);
        let (s0, s1, ts) = (s.s0, s.s1, s.t);
        let (z0, z1, tz) = lerp_weights(u_r, self.nr);
        let c = self.channels;
        let mut out = vec![0.0; self.nmu * self.nnu * c];
        for y in 0..self.nmu {
            for nu in 0..self.nnu {
                let o = &mut out[(y * self.nnu + nu) * c..(y * self.nnu + nu + 1) * c];
                for (z, wz) in [(z0, 1.0 - tz), (z1, tz)] {
                    if s.geometric {
                        if wz == 0.0 {
                            continue;
                        }
                        let base = self.index(nu * self.nmu_s, y, z);
                        for k in 0..c {
                            o[k] += wz * blend_at(&self.data, base + k, c, &s);
                        }
                        continue;
                    }
                    for (sx, wsx) in [(s0, 1.0 - ts), (s1, ts)] {
                        let w = wz * wsx;
                        if w == 0.0 {
                            continue;
                        }
                        let i = self.index(nu * self.nmu_s + sx, y, z);
                        for k in 0..c {
                            o[k] += w * self.data[i + k] as f64;
                        }
                    }
                }
            }
        }
        out
    }

    /// Sample a [`Table4::slice`] at (u_ν, u_μ) into `out`.
    #[inline]
    pub fn sample_slice_into(&self, slice: &[f64], u_nu: f64, u_mu: f64, out: &mut [f64]) {
        self.sample_slice_channels_into(slice, self.channels, u_nu, u_mu, out)
    }

    /// As [`Table4::sample_slice_into`] for a slice of this table's layout holding `c`
    /// values per texel (several tables' slices interleaved).
    #[inline]
    pub fn sample_slice_channels_into(
        &self,
        slice: &[f64],
        c: usize,
        u_nu: f64,
        u_mu: f64,
        out: &mut [f64],
    ) {
        let tex_x = u_nu * (self.nnu - 1) as f64;
        let nu0 = (tex_x.max(0.0) as usize).min(self.nnu - 1);
        let nu1 = (nu0 + 1).min(self.nnu - 1);
        let tnu = tex_x - nu0 as f64;
        let (y0, y1, ty) = lerp_weights(u_mu, self.nmu);
        let (a, b, d, e) = (
            (y0 * self.nnu + nu0) * c,
            (y0 * self.nnu + nu1) * c,
            (y1 * self.nnu + nu0) * c,
            (y1 * self.nnu + nu1) * c,
        );
        let (wa, wb, wd, we) = (
            (1.0 - ty) * (1.0 - tnu),
            (1.0 - ty) * tnu,
            ty * (1.0 - tnu),
            ty * tnu,
        );
        for k in 0..c {
            out[k] = wa * slice[a + k] + wb * slice[b + k] + wd * slice[d + k] + we * slice[e + k];
        }
    }

    /// Element-wise a += b.
    pub fn add_assign(&mut self, other: &Table4) {
        for (a, b) in self.data.iter_mut().zip(&other.data) {
            *a += *b;
        }
    }
}

//! Table storage (f32, channels innermost) and sampling with GPU semantics: texel i's centre
//! at (i + 0.5)/n, bilinear/trilinear filtering with clamp-to-edge, and for the 4D scattering
//! table the packing of Bruneton 2017 (ν and μ_s share the x axis; two 3D fetches and a
//! manual lerp along ν), so CPU and GPU tables compare texel by texel.

use super::mu_s_blend::{blend_at, MuSFilter};
use super::mu_s_logs::{CellLogs, MuSLogs};
use super::params::TableSizes;
use super::r_blend::{self, RFilter};

/// What a 4D lookup needs beyond its texture coordinates: the μ_s cells that take the
/// log blend ([`super::mu_s_blend::twilight_cells`]) and the planet's radius over H =
/// √(R_t² − R_g²) for the blend along r ([`super::r_blend`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LookupBlend {
    /// The μ_s cells, from the first, of [`super::mu_s_blend`]'s blend.
    pub twilight_cells: usize,
    /// R_g / H.
    pub bottom_over_h: f64,
}

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

    /// Sample of the irradiance table (x = μ_s, y = altitude, rows even in it) at (u, v)
    /// into `out`: along x the twilight blend ([`super::mu_s_blend`]) in the first
    /// `twilight_cells` cells, else linear; then along y [`super::r_blend`]'s rule
    /// (geometric where the irradiance falls with altitude, whose fraction is the rows'
    /// linear weight here).
    #[inline]
    pub fn sample_irradiance_into(&self, u: f64, v: f64, twilight_cells: usize, out: &mut [f64]) {
        let s = MuSFilter::new(u, self.width, twilight_cells);
        let r = RFilter::altitude_rows(v, self.height);
        let c = self.channels;
        let row = |y: usize, k: usize| {
            let base = y * self.width * c + k;
            if s.geometric {
                return blend_at(&self.data, base, c, &s);
            }
            let a = self.data[base + s.s0 * c] as f64;
            a + s.t * (self.data[base + s.s1 * c] as f64 - a)
        };
        for (k, o) in out[..c].iter_mut().enumerate() {
            *o = if r.t == 0.0 {
                row(r.z0, k)
            } else {
                r_blend::blend(row(r.z0, k), row(r.z1, k), &r)
            };
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
    /// `GetScattering` with two blends of firmament's: per (μ, ν) texel, along μ_s (linear,
    /// or in the first `blend.twilight_cells` cells [`mu_s_blend`]'s), then along r
    /// ([`r_blend`]), then bilinear in (μ, ν).
    #[inline]
    pub fn sample_into(&self, uvwz: [f64; 4], blend: &LookupBlend, out: &mut [f64]) {
        self.sample_logs_into(uvwz, blend, None, out)
    }

    /// [`Table4::sample_into`] with the log blend's logarithms and tangents read from
    /// `logs` ([`MuSLogs`], made for this table) where it has them: the same values to
    /// ~10⁻⁷, at one exp per value instead of four logarithms and an exp.
    #[inline]
    pub fn sample_logs_into(
        &self,
        uvwz: [f64; 4],
        blend: &LookupBlend,
        logs: Option<&MuSLogs>,
        out: &mut [f64],
    ) {
        let (y0, y1, ty) = lerp_weights(uvwz[2], self.nmu);
        let r = RFilter::new(uvwz[3], self.nr, blend.bottom_over_h);
        let s = MuSFilter::new(uvwz[1], self.nmu_s, blend.twilight_cells);
        let cell = logs.and_then(|l| l.cell(self, &s));
        self.sample_rows_into(uvwz[0], s, [y0, y1], ty, &r, cell, out);
    }

    /// As [`Table4::sample_logs_into`] with the μ_s, μ and r filters already known, and
    /// the μ_s cell's logarithms where made.
    #[inline]
    #[allow(clippy::too_many_arguments)]
    pub fn sample_rows_into(
        &self,
        u_nu: f64,
        s: MuSFilter,
        y: [usize; 2],
        ty: f64,
        r: &RFilter,
        cell: Option<CellLogs>,
        out: &mut [f64],
    ) {
        let tex_x = u_nu * (self.nnu - 1) as f64;
        let nu0 = (tex_x.max(0.0) as usize).min(self.nnu - 1);
        let nu1 = (nu0 + 1).min(self.nnu - 1);
        let tnu = tex_x - nu0 as f64;
        let c = self.channels;
        out[..c].iter_mut().for_each(|o| *o = 0.0);
        let wy = [1.0 - ty, ty];
        let wn = [1.0 - tnu, tnu];
        for (b, &yy) in y.iter().enumerate() {
            for (e, &nn) in [nu0, nu1].iter().enumerate() {
                let w = wy[b] * wn[e];
                if w != 0.0 {
                    self.add_texel(yy, nn, &s, r, cell, w, &mut out[..c]);
                }
            }
        }
    }

    /// Adds `w` times the (μ, ν) texel (`y`, `nu`), every channel, blended along μ_s by
    /// `s` (with `cell`'s logarithms where given), then along r by `r`, to `out`.
    #[inline]
    #[allow(clippy::too_many_arguments)]
    fn add_texel(
        &self,
        y: usize,
        nu: usize,
        s: &MuSFilter,
        r: &RFilter,
        cell: Option<CellLogs>,
        w: f64,
        out: &mut [f64],
    ) {
        // A value's index in the table and in the cell's logarithms, for row z.
        let at = |z: usize| {
            (
                self.index(nu * self.nmu_s, y, z),
                ((z * self.nmu + y) * self.nnu + nu) * self.channels,
            )
        };
        const CHUNK: usize = 16;
        let lower = at(r.z0);
        if r.t == 0.0 {
            let mut a = [0.0; CHUNK];
            for (start, out) in (0..out.len()).step_by(CHUNK).zip(out.chunks_mut(CHUNK)) {
                let a = &mut a[..out.len()];
                self.mu_s_values(lower.0 + start, lower.1 + start, s, cell, a);
                for (o, a) in out.iter_mut().zip(a.iter()) {
                    *o += w * a;
                }
            }
            return;
        }
        let upper = at(r.z1);
        // The rows' values a chunk of channels at a time, then blended together.
        let (mut a, mut b) = ([0.0; CHUNK], [0.0; CHUNK]);
        for (start, out) in (0..out.len()).step_by(CHUNK).zip(out.chunks_mut(CHUNK)) {
            let n = out.len();
            self.mu_s_values(lower.0 + start, lower.1 + start, s, cell, &mut a[..n]);
            self.mu_s_values(upper.0 + start, upper.1 + start, s, cell, &mut b[..n]);
            r_blend::add_blended(&a[..n], &b[..n], r, w, out);
        }
    }

    /// The values blended along μ_s by `s` of the consecutive channels whose μ_s columns
    /// start at `base` (their index in `cell`'s logarithms: `column`), into `out`.
    #[inline]
    fn mu_s_values(
        &self,
        base: usize,
        column: usize,
        s: &MuSFilter,
        cell: Option<CellLogs>,
        out: &mut [f64],
    ) {
        match cell {
            Some(cell) => cell.values(self, base, column, s, out),
            None => {
                for (k, o) in out.iter_mut().enumerate() {
                    *o = self.mu_s_value(base + k, s);
                }
            }
        }
    }

    /// The value blended along μ_s by `s` of the μ_s column whose first sample is at
    /// `base` (one channel).
    #[inline]
    fn mu_s_value(&self, base: usize, s: &MuSFilter) -> f64 {
        let c = self.channels;
        if s.geometric {
            return blend_at(&self.data, base, c, s);
        }
        self.mu_s_linear(base, s)
    }

    /// Bruneton's linear blend along μ_s of the μ_s column whose first sample is at `base`.
    #[inline]
    pub(super) fn mu_s_linear(&self, base: usize, s: &MuSFilter) -> f64 {
        let c = self.channels;
        let a = self.data[base + s.s0 * c] as f64;
        if s.t == 0.0 {
            return a;
        }
        a + s.t * (self.data[base + s.s1 * c] as f64 - a)
    }

    /// The table filtered at fixed (u_μs, u_r): a 2D (μ, ν) slice, `[(y·nnu + ν)·channels + c]`.
    /// Sampling the slice with [`Table4::sample_slice_into`] equals [`Table4::sample_into`]
    /// at that (u_μs, u_r): the blends along μ_s and r are made per texel before the
    /// linear filters in both. Used for every pixel of a frame whose camera and sun are
    /// fixed.
    pub fn slice(
        &self,
        u_mu_s: f64,
        u_r: f64,
        blend: &LookupBlend,
        logs: Option<&MuSLogs>,
    ) -> Vec<f64> {
        let s = MuSFilter::new(u_mu_s, self.nmu_s, blend.twilight_cells);
        let r = RFilter::new(u_r, self.nr, blend.bottom_over_h);
        let cell = logs.and_then(|l| l.cell(self, &s));
        let c = self.channels;
        let mut out = vec![0.0; self.nmu * self.nnu * c];
        for (i, o) in out.chunks_exact_mut(c).enumerate() {
            self.add_texel(i / self.nnu, i % self.nnu, &s, &r, cell, 1.0, o);
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A table whose texels rise or fall along r and μ_s by texel (a hash), all positive
    /// but a few unlit texels.
    fn table() -> Table4 {
        let mut t = Table4::new(6, 5, 7, 4, 2);
        for (i, v) in t.data.iter_mut().enumerate() {
            let h = (i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 40;
            *v = if h.is_multiple_of(17) {
                0.0
            } else {
                0.1 + (h % 1000) as f32 / 100.0
            };
        }
        t
    }

    #[test]
    fn a_slice_sampled_equals_the_4d_lookup() {
        let t = table();
        let c = t.channels;
        for twilight_cells in [0, 3] {
            let blend = LookupBlend {
                twilight_cells,
                bottom_over_h: 7.3,
            };
            for (j, &(u_mu_s, u_r)) in [(0.13, 0.41), (0.5, 0.08), (0.33, 0.97), (0.9, 0.5)]
                .iter()
                .enumerate()
            {
                let slice = t.slice(u_mu_s, u_r, &blend, None);
                for (u_nu, u_mu) in [(0.0, 0.5), (0.37, 0.21), (0.8, 0.66), (1.0, 0.93)] {
                    let (mut a, mut b) = (vec![0.0; c], vec![0.0; c]);
                    t.sample_into([u_nu, u_mu_s, u_mu, u_r], &blend, &mut a);
                    t.sample_slice_into(&slice, u_nu, u_mu, &mut b);
                    for k in 0..c {
                        assert!(
                            (a[k] - b[k]).abs() <= 1e-12 * a[k].abs().max(1.0),
                            "case {j}, twilight {twilight_cells}: {} vs {}",
                            a[k],
                            b[k]
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn the_lookup_blends_each_texel_along_r_by_its_trend() {
        // One (μ, ν, μ_s) texel column, three r rows: halfway between the lower two,
        // falling 8 → 2 (geometric in r), rising 2 → 8 (linear in ρ); between the upper
        // two (into the top row) linear either way.
        let mut t = Table4::new(3, 1, 1, 1, 2);
        t.data = vec![8.0, 2.0, 2.0, 8.0, 1.0, 9.0];
        let blend = LookupBlend {
            twilight_cells: 0,
            bottom_over_h: 7.3,
        };
        let mut out = [0.0; 2];
        t.sample_into([0.0, 0.5, 0.5, 0.5 / 1.5], &blend, &mut out);
        let f = RFilter::new(0.5 / 1.5, 3, 7.3);
        assert!((f.t - 0.5).abs() < 1e-12 && f.w < 0.5 && f.log, "{f:?}");
        assert!((out[0] - 8.0 * 0.25f64.powf(f.w)).abs() < 1e-9, "{out:?}");
        assert!((out[1] - 5.0).abs() < 1e-12, "{out:?}");
        t.sample_into([0.0, 0.5, 0.5, 2.0 / 3.0], &blend, &mut out);
        assert!(
            (out[0] - 1.5).abs() < 1e-9 && (out[1] - 8.5).abs() < 1e-9,
            "{out:?}"
        );
    }
}

//! A ray profile's steps as the lanes' march reads them ([`super::lanes`]), and the lookup
//! coordinates of a block of steps for one light direction computed together.
//!
//! Per light direction a step needs the light's zenith cosine there, the sun's visible
//! fraction, the transmittance table's column (a distance to the top, Bruneton's mapping)
//! and Ψ_ms's column (an asinh). Step by step in f64 these were short chains of a square
//! root, a division, a logarithm and a float-to-index conversion whose latencies each step
//! paid alone, half of a table build's time. Here the light-independent parts are kept per
//! step in f32 arrays (structure of arrays, padded to whole blocks of [`BLOCK`] steps) and a
//! block's coordinates are computed stage by stage over whole arrays, which the compiler
//! turns into SIMD. f32 is enough: the light's zenith cosine is within ~1e-7 (r·μ_s of
//! ~6.4e6 m to 0.5 m), the distance to the top within ~3e-7 relative (computed without
//! cancellation), a column within ~1e-4 of a texel; measured against the f64 general path
//! by `lanes::tests::the_lanes_agree_with_the_general_path`.

use super::params::MU_S_HORIZON_STRETCH;

/// Steps per block of coordinates.
pub(crate) const BLOCK: usize = 32;

/// A table's two texels and the weight of the second, per step of a block.
pub(crate) struct Columns {
    pub i0: [u32; BLOCK],
    pub i1: [u32; BLOCK],
    pub t: [f32; BLOCK],
}

impl Columns {
    const ZERO: Columns = Columns {
        i0: [0; BLOCK],
        i1: [0; BLOCK],
        t: [0.0; BLOCK],
    };

    /// Step j's (texel, next texel, weight of the next).
    #[inline(always)]
    pub fn at(&self, j: usize) -> (usize, usize, f32) {
        (self.i0[j] as usize, self.i1[j] as usize, self.t[j])
    }

    /// The columns of coordinates `x` ∈ [0, 1] over `n` texels, texel-centre exact (as
    /// `lanes::weights`: texel coordinate x·(n − 1)).
    #[inline(always)]
    fn fill(&mut self, x: &[f32; BLOCK], n: usize) {
        let last = (n - 1) as f32;
        let top = (n - 1) as i32;
        for j in 0..BLOCK {
            let t = (x[j] * last).clamp(0.0, last);
            // t ≥ 0: truncation is floor.
            let i = t as i32;
            self.i0[j] = i as u32;
            self.i1[j] = (i + 1).min(top) as u32;
            self.t[j] = t - i as f32;
        }
    }
}

/// One block's lookup coordinates for one light direction.
pub(crate) struct BlockCoordinates {
    /// The sun's visible fraction at each step.
    pub fraction: [f32; BLOCK],
    /// The transmittance table's columns (when single scattering is marched).
    pub transmittance: Columns,
    /// Ψ_ms's columns (when the march has a field).
    pub field: Columns,
}

impl Default for BlockCoordinates {
    fn default() -> Self {
        BlockCoordinates {
            fraction: [0.0; BLOCK],
            transmittance: Columns::ZERO,
            field: Columns::ZERO,
        }
    }
}

/// What one step's lookups need from its radius (see [`StepLanes::push`]).
pub(crate) struct StepGeometry {
    /// The step's middle (m from the ray's start) and its radius (m).
    pub t_mid: f64,
    pub r: f64,
    /// 1/r (1/m).
    pub inv_r: f64,
    /// top² − r² (m²).
    pub top_minus_r2: f64,
    /// The transmittance mapping's shortest and 1/(longest − shortest) distance to the top.
    pub d_min: f64,
    pub inv_span: f64,
    /// The sun's visible fraction there (Lookup::sun_visible_fraction): a smoothstep over
    /// μ_s − cos(the horizon's zenith angle) ∈ [−e, e], e = sin(that angle)·the sun's
    /// angular radius; e and 1/(2e) (0 for a point light).
    pub half_band: f64,
    pub inv_band: f64,
    pub cos_horizon: f64,
    /// The transmittance table's and Ψ_ms's rows.
    pub transmittance_row: (usize, usize, f32),
    pub field_row: (usize, usize, f32),
}

/// A profile's steps for the lanes' march: the light-independent geometry per step in f32
/// arrays padded to whole blocks, and the steps' weights.
#[derive(Default)]
pub(crate) struct StepLanes {
    t_mid: Vec<f32>,
    r: Vec<f32>,
    inv_r: Vec<f32>,
    top_minus_r2: Vec<f32>,
    d_min: Vec<f32>,
    inv_span: Vec<f32>,
    half_band: Vec<f32>,
    inv_band: Vec<f32>,
    cos_horizon: Vec<f32>,
    /// Per step (not padded): the tables' rows.
    pub transmittance_row: Vec<(usize, usize, f32)>,
    pub field_row: Vec<(usize, usize, f32)>,
    /// A point light (no band around the horizon).
    point_light: bool,
    /// Per step, constituent and lane group: T·ℓ·ρ_c·β_c.
    pub single: Vec<super::lanes::Lane>,
    /// Per step and lane group: T·ℓ·Σ_c ρ_c·β_c·k₀·Y₀₀.
    pub multiple: Vec<super::lanes::Lane>,
}

#[inline(always)]
fn block(v: &[f32], b: usize) -> &[f32; BLOCK] {
    v[b * BLOCK..(b + 1) * BLOCK].try_into().unwrap()
}

impl StepLanes {
    /// The per-step geometry's arrays.
    fn geometry_mut(&mut self) -> [&mut Vec<f32>; 9] {
        [
            &mut self.t_mid,
            &mut self.r,
            &mut self.inv_r,
            &mut self.top_minus_r2,
            &mut self.d_min,
            &mut self.inv_span,
            &mut self.half_band,
            &mut self.inv_band,
            &mut self.cos_horizon,
        ]
    }

    /// Empty, with room for `steps` steps of `constituents` × `groups` lanes of weights,
    /// for a light of angular radius `sun_radius` (rad).
    pub fn clear(&mut self, steps: usize, constituents: usize, groups: usize, sun_radius: f64) {
        let padded = steps.div_ceil(BLOCK) * BLOCK;
        for v in self.geometry_mut() {
            v.clear();
            v.reserve(padded);
        }
        self.transmittance_row.clear();
        self.transmittance_row.reserve(steps);
        self.field_row.clear();
        self.field_row.reserve(steps);
        self.single.clear();
        self.single.reserve(steps * constituents * groups);
        self.multiple.clear();
        self.multiple.reserve(steps * groups);
        self.point_light = sun_radius <= 0.0;
    }

    /// The steps (not counting the padding).
    pub fn len(&self) -> usize {
        self.transmittance_row.len()
    }

    /// Append a step.
    pub fn push(&mut self, g: StepGeometry) {
        self.t_mid.push(g.t_mid as f32);
        self.r.push(g.r as f32);
        self.inv_r.push(g.inv_r as f32);
        self.top_minus_r2.push(g.top_minus_r2 as f32);
        self.d_min.push(g.d_min as f32);
        self.inv_span.push(g.inv_span as f32);
        self.half_band.push(g.half_band as f32);
        self.inv_band.push(g.inv_band as f32);
        self.cos_horizon.push(g.cos_horizon as f32);
        self.transmittance_row.push(g.transmittance_row);
        self.field_row.push(g.field_row);
    }

    /// Pad the arrays to whole blocks with copies of the last step (finite values whose
    /// coordinates are computed and not read).
    pub fn pad(&mut self) {
        let padded = self.len().div_ceil(BLOCK) * BLOCK;
        for v in self.geometry_mut() {
            let last = v.last().copied().unwrap_or(1.0);
            v.resize(padded, last);
        }
    }

    /// Block `b`'s coordinates for the light at r·μ_s = `r_mu_s` (m) at the ray's start and
    /// ν = `nu` from it: the transmittance table's columns over `transmittance_width`
    /// texels when `single`, Ψ_ms's over `field_width` texels when that is not 0.
    pub fn coordinates(
        &self,
        b: usize,
        r_mu_s: f64,
        nu: f64,
        single: bool,
        transmittance_width: usize,
        field_width: usize,
        out: &mut BlockCoordinates,
    ) {
        let (r_mu_s, nu) = (r_mu_s as f32, nu as f32);
        let (t_mid, inv_r) = (block(&self.t_mid, b), block(&self.inv_r, b));
        let mut mu_s = [0.0f32; BLOCK];
        for j in 0..BLOCK {
            mu_s[j] = ((r_mu_s + t_mid[j] * nu) * inv_r[j]).clamp(-1.0, 1.0);
        }
        let cos_horizon = block(&self.cos_horizon, b);
        if self.point_light {
            for j in 0..BLOCK {
                out.fraction[j] = if mu_s[j] >= cos_horizon[j] { 1.0 } else { 0.0 };
            }
        } else {
            let (half, inv) = (block(&self.half_band, b), block(&self.inv_band, b));
            for j in 0..BLOCK {
                let t = ((mu_s[j] - cos_horizon[j] + half[j]) * inv[j]).clamp(0.0, 1.0);
                out.fraction[j] = t * t * (3.0 - 2.0 * t);
            }
        }
        let mut x = [0.0f32; BLOCK];
        if single {
            let (r, top_minus_r2) = (block(&self.r, b), block(&self.top_minus_r2, b));
            let (d_min, inv_span) = (block(&self.d_min, b), block(&self.inv_span, b));
            for j in 0..BLOCK {
                // The distance to the top, −rμ + √(r²μ² + top² − r²), without the
                // cancellation of the two terms when the ray rises (rμ > 0).
                let r_mu = r[j] * mu_s[j];
                let root = (r_mu * r_mu + top_minus_r2[j]).max(0.0).sqrt();
                let d = if r_mu > 0.0 {
                    top_minus_r2[j] / (r_mu + root)
                } else {
                    root - r_mu
                };
                x[j] = (d.max(0.0) - d_min[j]) * inv_span[j];
            }
            out.transmittance.fill(&x, transmittance_width);
        }
        if field_width > 0 {
            for j in 0..BLOCK {
                x[j] = mu_s_unit_half(mu_s[j]);
            }
            out.field.fill(&x, field_width);
        }
    }
}

/// The Ψ_ms table's column coordinate of μ_s (as params::altitude_mu_s_uv): x =
/// asinh(μ_s·sinh k)/k mapped to [0, 1], in f32 (its absolute error, ~1e-7 of a column, is
/// far below the table's f32 values' own rounding).
#[inline(always)]
pub(crate) fn mu_s_unit_half(mu_s: f32) -> f32 {
    let k = MU_S_HORIZON_STRETCH;
    let y = mu_s * k.sinh() as f32;
    let a = y.abs();
    let asinh = ln_f32(a + (a * a + 1.0).sqrt());
    (y.signum() * asinh * (0.5 / k) as f32 + 0.5).clamp(0.0, 1.0)
}

/// ln x for x ≥ 1 (f32): x = m·2^e with m ∈ [√½, √2), ln m = 2·atanh(s), s = (m − 1)/(m + 1),
/// |s| ≤ 0.172, by its series to s⁹ (remainder ≤ 2·s¹¹/11 = 7e-10). Branch-free, so that
/// a loop over it vectorises.
#[inline(always)]
pub(crate) fn ln_f32(x: f32) -> f32 {
    let bits = x.to_bits();
    let e = ((bits >> 23) & 0xff) as i32 - 127;
    let m = f32::from_bits((bits & 0x007f_ffff) | 0x3f80_0000);
    let big = m > std::f32::consts::SQRT_2;
    let m = if big { m * 0.5 } else { m };
    let e = e + big as i32;
    let s = (m - 1.0) / (m + 1.0);
    let s2 = s * s;
    let series =
        2.0 * s * (1.0 + s2 * (1.0 / 3.0 + s2 * (1.0 / 5.0 + s2 * (1.0 / 7.0 + s2 / 9.0))));
    e as f32 * std::f32::consts::LN_2 + series
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ln_is_the_logarithm() {
        for i in 0..20000 {
            let x = 1.0 + i as f32 * 0.013;
            let want = (x as f64).ln();
            assert!(
                (ln_f32(x) as f64 - want).abs() < 2e-7 * want.max(1.0),
                "ln {x}"
            );
        }
    }

    #[test]
    fn the_column_mapping_is_the_tables() {
        for i in -1000..=1000 {
            let mu_s = i as f64 / 1000.0;
            let want = super::super::params::mu_s_unit(mu_s) * 0.5 + 0.5;
            assert!(
                (mu_s_unit_half(mu_s as f32) as f64 - want).abs() < 3e-7,
                "μ_s {mu_s}"
            );
        }
    }
}

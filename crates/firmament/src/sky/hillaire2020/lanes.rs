//! The light's part of Hillaire 2020's marches in f32 channel lanes: what the table builds
//! (sky view, Ψ_ms, sky irradiance) and the per-pixel marches pay per step and light
//! direction, once the ray's geometry is known ([`super::march::RayProfile`]).
//!
//! The same sums as [`super::march::Marcher::march_profile`]'s general path, rearranged so
//! that the per-direction work is a few scalar operations and short loops over lanes of
//! four f32 channels (the tables' values are f32 already):
//! - the single scattering's phase-weighted scattering Σ_c ρ_c·β_c·p_c(ν), times the
//!   step's throughput and analytic length, is Σ_c p_c(ν)·W_c with W_c = T·ℓ·ρ_c·β_c
//!   folded per step into the profile (it does not depend on the light);
//! - the multiple scattering σ_s·Ψ_ms of the isotropic field is Ψ_ms·M with
//!   M = T·ℓ·Σ_c ρ_c·β_c·k₀·Y₀₀ per step;
//! - the sun's transmittance e^{−τ} of the bilinear optical depth, as the general path,
//!   with a polynomial exponential ([`exp_neg`], relative error < 3e-7).
//!
//! Only the light-independent parts move; what is looked up where is unchanged, so the
//! lanes agree with the general path to f32 rounding (`tests::the_lanes_agree_with_the_general_path`).
//! Harmonic fields (degree > 0) and partly lit rays take the general path.

use super::march::RayProfile;
use super::multiple_scattering::MultipleScattering;
use crate::math::sphere::safe_sqrt;
use crate::sky::bruneton4d::{Lookup, Table2};

use super::harmonics;
use super::march::Medium;
use super::params::MU_S_HORIZON_STRETCH;

/// Channels per lane group.
pub(crate) const LANES: usize = 4;

/// Four channels.
pub(crate) type Lane = [f32; LANES];

// 1.5·2²³: adding and subtracting it rounds an f32 of magnitude < 2²² to the nearest
// integer (IEEE 754 round-to-nearest), and the sum's low bits hold that integer.
const ROUND: f32 = 12_582_912.0;
// ln 2 = LN2_HI + LN2_LO, LN2_HI = 355/512 with 9 significant bits (n·LN2_HI exact for
// |n| < 2¹⁵).
const LN2_HI: f32 = 355.0 / 512.0;
const LN2_LO: f32 = -2.121_944_4e-4;
/// e^f's Taylor coefficients 1/k!, k = 6 … 2.
const EXP_TAYLOR: [f32; 5] = [1.0 / 720.0, 1.0 / 120.0, 1.0 / 24.0, 1.0 / 6.0, 1.0 / 2.0];

/// e^{−x} per lane for optical depths x ≥ 0 (Cody & Waite's reduction, as Cephes' expf):
/// e^{−x} = 2ⁿ·e^f with n the integer nearest −x·log₂e and f = −x − n·ln 2 ∈ [−½ ln 2, ½ ln 2]
/// (ln 2 split in two parts so that n·ln 2 is exact); e^f by its degree-6 Taylor polynomial
/// (remainder ≤ (½ ln 2)⁷/7! = 1.2e-7), 2ⁿ from the float's exponent bits; 0 below 2^−126.
///
/// Written stage by stage over whole lanes, which the compiler turns into SIMD (SSE2 on any
/// x86-64): lane by lane in one loop it stayed scalar.
#[inline(always)]
pub(crate) fn exp_neg(x: Lane) -> Lane {
    use std::array::from_fn;
    let y: Lane = from_fn(|i| (-x[i] * std::f32::consts::LOG2_E).max(-126.0));
    let shifted: Lane = from_fn(|i| y[i] + ROUND);
    let n: Lane = from_fn(|i| shifted[i] - ROUND);
    let f: Lane = from_fn(|i| (-x[i] - n[i] * LN2_HI) - n[i] * LN2_LO);
    let p: Lane = from_fn(|i| {
        let f = f[i];
        let mut p = EXP_TAYLOR[0];
        for c in &EXP_TAYLOR[1..] {
            p = p * f + c;
        }
        (p * f + 1.0) * f + 1.0
    });
    // 2ⁿ: n from the shifted float's low bits, moved into the exponent field.
    let exponent: [u32; LANES] = from_fn(|i| {
        (shifted[i]
            .to_bits()
            .wrapping_sub(ROUND.to_bits())
            .wrapping_add(127))
            << 23
    });
    from_fn(|i| p[i] * f32::from_bits(exponent[i]) * ((y[i] > -126.0) as u32 as f32))
}

/// ln x for x ≥ 1 (f32): x = m·2^e with m ∈ [√½, √2), ln m = 2·atanh(s), s = (m − 1)/(m + 1),
/// |s| ≤ 0.172, by its series to s⁹ (remainder ≤ 2·s¹¹/11 = 7e-10).
#[inline(always)]
fn ln_f32(x: f32) -> f32 {
    let bits = x.to_bits();
    let mut e = ((bits >> 23) & 0xff) as i32 - 127;
    let mut m = f32::from_bits((bits & 0x007f_ffff) | 0x3f80_0000);
    if m > std::f32::consts::SQRT_2 {
        m *= 0.5;
        e += 1;
    }
    let s = (m - 1.0) / (m + 1.0);
    let s2 = s * s;
    let series =
        2.0 * s * (1.0 + s2 * (1.0 / 3.0 + s2 * (1.0 / 5.0 + s2 * (1.0 / 7.0 + s2 / 9.0))));
    e as f32 * std::f32::consts::LN_2 + series
}

/// A table's texels as lane groups: `groups` lanes per texel, channels past the model's 0.
struct LaneTable {
    width: usize,
    height: usize,
    groups: usize,
    data: Vec<Lane>,
}

impl LaneTable {
    /// The first `channels` values of each texel of `table` (the rest are other
    /// coefficients) in lanes.
    fn new(table: &Table2, channels: usize) -> LaneTable {
        let groups = channels.div_ceil(LANES);
        let mut data = vec![[0.0; LANES]; table.width * table.height * groups];
        for (texel, lanes) in table
            .data
            .chunks(table.channels)
            .zip(data.chunks_mut(groups))
        {
            for (k, v) in texel[..channels].iter().enumerate() {
                lanes[k / LANES][k % LANES] = *v;
            }
        }
        LaneTable {
            width: table.width,
            height: table.height,
            groups,
            data,
        }
    }

    /// Bilinear at columns (x0, x1, tx) of the rows (y0, y1, ty), lane group g.
    #[inline(always)]
    fn sample(&self, x: (usize, usize, f32), y: (usize, usize, f32), g: usize) -> Lane {
        let (x0, x1, tx) = x;
        let (y0, y1, ty) = y;
        let at = |yy: usize, xx: usize| &self.data[(yy * self.width + xx) * self.groups + g];
        let (a, b, c, d) = (at(y0, x0), at(y0, x1), at(y1, x0), at(y1, x1));
        let (w00, w10, w01, w11) = (
            (1.0 - tx) * (1.0 - ty),
            tx * (1.0 - ty),
            (1.0 - tx) * ty,
            tx * ty,
        );
        std::array::from_fn(|i| w00 * a[i] + w10 * b[i] + w01 * c[i] + w11 * d[i])
    }
}

/// The two texels and the weight of the second for a table coordinate `x` ∈ [0, 1] over
/// `n` texels, texel-centre exact: `table::lerp_weights` of `params::texcoord_from_unit(x, n)`, whose
/// texel coordinate u·n − ½ is x·(n − 1).
#[inline(always)]
fn weights(x: f64, n: usize) -> (usize, usize, f32) {
    let last = (n - 1) as f64;
    let t = (x * last).clamp(0.0, last);
    // t ≥ 0: truncation is floor.
    let i0 = t as u32 as usize;
    let i1 = (i0 + 1).min(n - 1);
    (i0, i1, (t - i0 as f64) as f32)
}

/// The tables a march reads, in lanes, and what the steps' weights need from the medium.
pub(crate) struct LightLanes {
    channels: usize,
    groups: usize,
    optical_depth: LaneTable,
    /// Ψ_ms's degree-0 coefficient (None: no multiple-scattering term).
    multiple: Option<LaneTable>,
    /// Per constituent, its scattering coefficient (m⁻¹ at unit density) in lanes, 0 for
    /// the absorbers.
    scattering: Vec<Lane>,
    /// Per constituent, the weight of the isotropic field through its phase function:
    /// k₀·Y₀₀ (0 for the absorbers and without a field).
    field_weight: Vec<f32>,
    bottom: f64,
    top: f64,
    /// √(top² − bottom²) (m).
    h: f64,
}

impl LightLanes {
    /// The lanes of `lookup`'s optical depth and of `multiple`'s field when it is isotropic
    /// (degree 0); None for a harmonic field (the general path takes it).
    pub fn new(
        medium: &Medium,
        lookup: &Lookup,
        multiple: Option<&MultipleScattering>,
    ) -> Option<LightLanes> {
        if multiple.is_some_and(|ms| ms.degree > 0) {
            return None;
        }
        let model = medium.model;
        let n = model.channels();
        let groups = n.div_ceil(LANES);
        let mut scattering = vec![[0.0; LANES]; model.constituents.len() * groups];
        let mut field_weight = vec![0.0; model.constituents.len()];
        for (ci, c) in model.constituents.iter().enumerate() {
            if !medium.scatters(ci) {
                continue;
            }
            for (k, b) in c.scattering.iter().enumerate() {
                scattering[ci * groups + k / LANES][k % LANES] = *b as f32;
            }
            if let Some(k0) = multiple.and_then(|ms| ms.moments[ci].first()) {
                field_weight[ci] = (k0 * harmonics::Y00) as f32;
            }
        }
        let (bottom, top) = (lookup.radii.bottom, lookup.radii.top);
        Some(LightLanes {
            channels: n,
            groups,
            optical_depth: LaneTable::new(lookup.optical_depth, n),
            multiple: multiple.map(|ms| LaneTable::new(&ms.table, n)),
            scattering,
            field_weight,
            bottom,
            top,
            h: safe_sqrt(top * top - bottom * bottom),
        })
    }

    /// Lane groups per channel set.
    pub fn groups(&self) -> usize {
        self.groups
    }

    /// The per-step geometry and weights of `profile` (its steps, densities, throughputs and
    /// lengths filled) into its `lanes`, for a light of angular radius `sun_radius` (rad).
    pub fn fill_steps(&self, profile: &mut RayProfile, sun_radius: f64) {
        let constituents = self.field_weight.len();
        let (n, g_count) = (self.channels, self.groups);
        let lanes = &mut profile.lanes;
        lanes.geometry.clear();
        lanes.single.clear();
        lanes.multiple.clear();
        let t = &self.optical_depth;
        // The sun's band around the horizon is sin(horizon angle)·radius = bottom/r·radius:
        // its 1/(2e) is r times this.
        let inv_band_per_r = if sun_radius > 0.0 {
            0.5 / (self.bottom * sun_radius)
        } else {
            0.0
        };
        for (i, &[_, _, t_mid, r]) in profile.steps.iter().enumerate() {
            // Bruneton's transmittance mapping (bruneton4d::params::transmittance_uv) with
            // what depends on r alone taken out.
            let rho = safe_sqrt(r * r - self.bottom * self.bottom);
            let (d_min, d_max) = (self.top - r, rho + self.h);
            let inv_r = 1.0 / r.max(1.0);
            let sin_h = self.bottom * inv_r;
            lanes.geometry.push(StepGeometry {
                t_mid,
                r,
                inv_r,
                top_minus_r2: self.top * self.top - r * r,
                d_min,
                inv_span: if d_max > d_min {
                    1.0 / (d_max - d_min)
                } else {
                    0.0
                },
                transmittance_row: weights(rho / self.h, t.height),
                half_band: sin_h * sun_radius,
                inv_band: r * inv_band_per_r,
                // −cos of the horizon's zenith angle = √(r² − bottom²)/r.
                cos_horizon: -rho * inv_r,
                field_row: self.multiple.as_ref().map_or((0, 0, 0.0), |m| {
                    let x_r = ((r - self.bottom) / (self.top - self.bottom)).clamp(0.0, 1.0);
                    weights(x_r.sqrt(), m.height)
                }),
            });
            let densities = &profile.densities[i * constituents..(i + 1) * constituents];
            let (through, lengths) = (
                &profile.throughput[i * n..(i + 1) * n],
                &profile.lengths[i * n..(i + 1) * n],
            );
            let mut multiple = [[0.0f32; LANES]; crate::spectrum::MAX_CHANNELS / LANES];
            let multiple = &mut multiple[..g_count];
            for (ci, &rho_c) in densities.iter().enumerate() {
                let beta = &self.scattering[ci * g_count..(ci + 1) * g_count];
                for (g, m) in multiple.iter_mut().enumerate() {
                    let mut w = [0.0f32; LANES];
                    for l in 0..LANES {
                        let k = g * LANES + l;
                        if k < n && rho_c > 0.0 {
                            w[l] = (through[k] * lengths[k] * rho_c * beta[g][l] as f64) as f32;
                        }
                        m[l] += w[l] * self.field_weight[ci];
                    }
                    lanes.single.push(w);
                }
            }
            lanes.multiple.extend_from_slice(multiple);
        }
    }

    /// The light's part of a march over `lanes` (from a profile filled by
    /// [`LightLanes::fill_steps`]): the light at r·μ_s = `r_mu_s` (m) at the ray's start
    /// and ν = `nu` from it; `phases` each constituent's phase function at ν (empty: no
    /// single scattering). Sums into `acc`
    /// (`groups` lanes, overwritten), calling `at_end(i, acc)` after step i.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    pub fn march(
        &self,
        lanes: &StepLanes,
        r_mu_s: f64,
        nu: f64,
        phases: &[f32],
        acc: &mut [Lane],
        mut at_end: impl FnMut(usize, &[Lane]),
    ) {
        let groups = self.groups;
        let constituents = self.field_weight.len();
        acc.iter_mut().for_each(|a| *a = [0.0; LANES]);
        let tau = &self.optical_depth;
        let single = !phases.is_empty();
        // Steps in blocks, each in two passes: first every step's lookup coordinates (short,
        // independent computations whose square roots and divisions overlap), then the
        // lookups and sums. In one pass each step's chain of latencies ran alone.
        const BLOCK: usize = 32;
        let mut fraction = [0.0f32; BLOCK];
        let mut t_col = [(0usize, 0usize, 0.0f32); BLOCK];
        let mut f_col = [(0usize, 0usize, 0.0f32); BLOCK];
        for (b, block) in lanes.geometry.chunks(BLOCK).enumerate() {
            for (j, s) in block.iter().enumerate() {
                let mu_s = ((r_mu_s + s.t_mid * nu) * s.inv_r).clamp(-1.0, 1.0);
                let above = mu_s - s.cos_horizon;
                fraction[j] = if above >= s.half_band {
                    1.0
                } else if above <= -s.half_band {
                    0.0
                } else {
                    let t = ((above + s.half_band) * s.inv_band) as f32;
                    t * t * (3.0 - 2.0 * t)
                };
                if single {
                    let r_mu = s.r * mu_s;
                    let d = (-r_mu + safe_sqrt(r_mu * r_mu + s.top_minus_r2)).max(0.0);
                    t_col[j] = weights((d - s.d_min) * s.inv_span, tau.width);
                }
                if let Some(field) = &self.multiple {
                    f_col[j] = weights(mu_s_unit_half(mu_s), field.width);
                }
            }
            for (j, s) in block.iter().enumerate() {
                let i = b * BLOCK + j;
                if single && fraction[j] > 0.0 {
                    let weights =
                        &lanes.single[i * constituents * groups..(i + 1) * constituents * groups];
                    for (g, a) in acc.iter_mut().enumerate() {
                        let t_sun = exp_neg(tau.sample(t_col[j], s.transmittance_row, g));
                        let mut phased = [0.0f32; LANES];
                        for (c, p) in phases.iter().enumerate() {
                            let w = &weights[c * groups + g];
                            for l in 0..LANES {
                                phased[l] += p * w[l];
                            }
                        }
                        for l in 0..LANES {
                            a[l] += fraction[j] * phased[l] * t_sun[l];
                        }
                    }
                }
                if let Some(field) = &self.multiple {
                    let m = &lanes.multiple[i * groups..(i + 1) * groups];
                    for (g, a) in acc.iter_mut().enumerate() {
                        let psi = field.sample(f_col[j], s.field_row, g);
                        for l in 0..LANES {
                            a[l] += m[g][l] * psi[l];
                        }
                    }
                }
                at_end(i, acc);
            }
        }
    }

    /// The first `channels` of `acc` into `out` (f64).
    #[inline]
    pub fn unpack(&self, acc: &[Lane], out: &mut [f64]) {
        for (k, o) in out.iter_mut().enumerate().take(self.channels) {
            *o = acc[k / LANES][k % LANES] as f64;
        }
    }
}

/// The Ψ_ms table's column coordinate of μ_s (as params::altitude_mu_s_uv): x =
/// asinh(μ_s·sinh k)/k mapped to [0, 1], the logarithm in f32 (its absolute error, ~1e-7
/// of a column, is far below the table's f32 values' own rounding).
#[inline(always)]
fn mu_s_unit_half(mu_s: f64) -> f64 {
    let k = MU_S_HORIZON_STRETCH;
    let y = (mu_s * k.sinh()) as f32;
    let a = y.abs();
    let asinh = ln_f32(a + (a * a + 1.0).sqrt());
    ((y.signum() * asinh * (0.5 / k) as f32) as f64 + 0.5).clamp(0.0, 1.0)
}

/// What a step's lookups need from its radius.
#[derive(Clone, Copy, Debug)]
pub(crate) struct StepGeometry {
    /// The step's middle (m from the ray's start) and its radius (m).
    t_mid: f64,
    r: f64,
    inv_r: f64,
    /// top² − r² (m²).
    top_minus_r2: f64,
    /// The transmittance mapping's shortest and 1/(longest − shortest) distance to the top.
    d_min: f64,
    inv_span: f64,
    transmittance_row: (usize, usize, f32),
    /// The sun's visible fraction there (Lookup::sun_visible_fraction): a smoothstep over
    /// μ_s − cos(the horizon's zenith angle) ∈ [−e, e], e = sin(that angle)·the sun's
    /// angular radius; e and 1/(2e) (0 for a point light).
    half_band: f64,
    inv_band: f64,
    cos_horizon: f64,
    field_row: (usize, usize, f32),
}

/// A profile's steps for [`LightLanes::march`].
#[derive(Default)]
pub(crate) struct StepLanes {
    geometry: Vec<StepGeometry>,
    /// Per step, constituent and lane group: T·ℓ·ρ_c·β_c.
    single: Vec<Lane>,
    /// Per step and lane group: T·ℓ·Σ_c ρ_c·β_c·k₀·Y₀₀.
    multiple: Vec<Lane>,
}

#[cfg(test)]
mod tests {
    use super::super::march::Marcher;
    use super::*;
    use crate::atmosphere::Atmosphere;
    use crate::sky::hillaire2020::{multiple_scattering, sky_view, Hillaire2020, HillaireConfig};
    use crate::spectrum::Wavelengths;

    /// The largest difference between two tables relative to the larger table's largest
    /// value in the same channel.
    fn worst_difference(a: &Table2, b: &Table2) -> f64 {
        let c = a.channels;
        let mut peak = vec![0.0f64; c];
        for (i, v) in b.data.iter().enumerate() {
            peak[i % c] = peak[i % c].max(v.abs() as f64);
        }
        a.data
            .iter()
            .zip(&b.data)
            .enumerate()
            .map(|(i, (x, y))| (*x as f64 - *y as f64).abs() / peak[i % c].max(1e-30))
            .fold(0.0, f64::max)
    }

    #[test]
    fn the_lanes_agree_with_the_general_path() {
        // RGB (one lane group, padded) and 7 wavelengths (two groups, the second partly
        // padded); day, a low sun and twilight, from the ground and from 30 km.
        for wavelengths in [
            Wavelengths::rgb(),
            Wavelengths::from_list(&[400.0, 450.0, 500.0, 550.0, 600.0, 650.0, 700.0]).unwrap(),
        ] {
            let model = Atmosphere::earth().resolve(&wavelengths).unwrap();
            let config = HillaireConfig {
                multiple_scattering: (16, 16),
                ..HillaireConfig::default()
            };
            let sky = Hillaire2020::compute(model, &config).unwrap();
            let (lanes, general) = (sky.marcher(), sky.marcher().without_lanes());
            assert!(lanes.lanes.is_some());
            let bottom = sky.model.bottom_radius_m;
            for (altitude, mu_s) in [(2.0, 0.8), (2.0, 0.05), (30e3, -0.08)] {
                let r = bottom + altitude;
                let a = sky_view::compute(&lanes, r, mu_s, 48, 27, 30);
                let b = sky_view::compute(&general, r, mu_s, 48, 27, 30);
                let worst = worst_difference(&a, &b);
                assert!(
                    worst < 5e-6,
                    "sky view at {altitude} m, μ_s {mu_s}: {worst:e}"
                );
            }
            // The multiple-scattering pass (its first order marched without a field).
            let gather = |marcher: &Marcher| {
                multiple_scattering::compute(
                    marcher,
                    config.multiple_scattering_model,
                    16,
                    16,
                    config.multiple_scattering_directions,
                    config.multiple_scattering_steps,
                    2,
                )
                .table
            };
            let first = || Marcher::new(Medium::new(&sky.model), lanes.lookup, None);
            let worst = worst_difference(&gather(&first()), &gather(&first().without_lanes()));
            assert!(worst < 5e-6, "Ψ_ms: {worst:e}");
        }
    }

    #[test]
    fn exp_neg_is_the_exponential() {
        let mut worst: f64 = 0.0;
        let mut x = 0.0f32;
        while x < 80.0 {
            let got = exp_neg([x, x * 0.5, x + 0.37, 0.0]);
            for (g, v) in got.iter().zip([x, x * 0.5, x + 0.37, 0.0]) {
                let want = (-(v as f64)).exp();
                worst = worst.max(((*g as f64) - want).abs() / want);
            }
            x += 0.0137;
        }
        assert!(worst < 3e-7, "worst relative error {worst:e}");
        assert_eq!(exp_neg([90.0, 104.0, 200.0, 87.0])[..3], [0.0; 3]);
    }

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
            assert!((mu_s_unit_half(mu_s) - want).abs() < 2e-7, "μ_s {mu_s}");
        }
    }
}

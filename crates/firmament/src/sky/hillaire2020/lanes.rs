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
use super::step_lanes::{BlockCoordinates, StepGeometry, StepLanes, BLOCK};

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
    // Estrin's scheme: the same polynomial in three dependent levels instead of Horner's
    // seven (a step's exponential was the march's longest chain of latencies).
    let [c6, c5, c4, c3, c2] = EXP_TAYLOR;
    let p: Lane = from_fn(|i| {
        let f = f[i];
        let f2 = f * f;
        let f4 = f2 * f2;
        (1.0 + f) + f2 * (c2 + c3 * f) + f4 * ((c4 + c5 * f) + f2 * c6)
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
    fn sample<const G: usize>(
        &self,
        x: (usize, usize, f32),
        y: (usize, usize, f32),
        g: usize,
    ) -> Lane {
        let (x0, x1, tx) = x;
        let (y0, y1, ty) = y;
        // G lane groups per texel (0: the table's count).
        let groups = if G > 0 { G } else { self.groups };
        let at = |yy: usize, xx: usize| &self.data[(yy * self.width + xx) * groups + g];
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
        lanes.clear(profile.steps.len(), constituents, g_count, sun_radius);
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
            lanes.push(StepGeometry {
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
        lanes.pad();
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
        at_end: impl FnMut(usize, &[Lane]),
    ) {
        // One lane group (RGB) compiled on its own: its loops over groups unrolled.
        if self.groups == 1 {
            self.march_groups::<1>(lanes, r_mu_s, nu, phases, acc, at_end)
        } else {
            self.march_groups::<0>(lanes, r_mu_s, nu, phases, acc, at_end)
        }
    }

    /// [`LightLanes::march`] over `G` lane groups (0: the model's count).
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn march_groups<const G: usize>(
        &self,
        lanes: &StepLanes,
        r_mu_s: f64,
        nu: f64,
        phases: &[f32],
        acc: &mut [Lane],
        mut at_end: impl FnMut(usize, &[Lane]),
    ) {
        let groups = if G > 0 { G } else { self.groups };
        let acc = &mut acc[..groups];
        let constituents = self.field_weight.len();
        acc.iter_mut().for_each(|a| *a = [0.0; LANES]);
        let tau = &self.optical_depth;
        let single = !phases.is_empty();
        // Steps in blocks, each in two passes: first every step's lookup coordinates, over
        // whole arrays (step_lanes.rs: SIMD), then the lookups and sums.
        let field_width = self.multiple.as_ref().map_or(0, |f| f.width);
        let mut at = BlockCoordinates::default();
        for b in 0..lanes.len().div_ceil(BLOCK) {
            lanes.coordinates(b, r_mu_s, nu, single, tau.width, field_width, &mut at);
            for j in 0..BLOCK.min(lanes.len() - b * BLOCK) {
                let i = b * BLOCK + j;
                let fraction = at.fraction[j];
                if single && fraction > 0.0 {
                    let weights =
                        &lanes.single[i * constituents * groups..(i + 1) * constituents * groups];
                    let (column, row) = (at.transmittance.at(j), lanes.transmittance_row[i]);
                    for (g, a) in acc.iter_mut().enumerate() {
                        let t_sun = exp_neg(tau.sample::<G>(column, row, g));
                        let mut phased = [0.0f32; LANES];
                        for (c, p) in phases.iter().enumerate() {
                            let w = &weights[c * groups + g];
                            for l in 0..LANES {
                                phased[l] += p * w[l];
                            }
                        }
                        for l in 0..LANES {
                            a[l] += fraction * phased[l] * t_sun[l];
                        }
                    }
                }
                if let Some(field) = &self.multiple {
                    let m = &lanes.multiple[i * groups..(i + 1) * groups];
                    let (column, row) = (at.field.at(j), lanes.field_row[i]);
                    for (g, a) in acc.iter_mut().enumerate() {
                        let psi = field.sample::<G>(column, row, g);
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
                eprintln!("sky view at {altitude} m, μ_s {mu_s}: {worst:.2e}");
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
            eprintln!("Ψ_ms: {worst:.2e}");
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
}

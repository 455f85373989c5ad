//! The logarithms and tangents of [`super::mu_s_blend`]'s log-Hermite blend, made once per
//! μ_s sample instead of at every lookup.
//!
//! The blend of a cell [s0, s1] reads ln L at s0 and s1 and the PCHIP tangents there, which
//! depend on the sample and its two neighbours only ([`super::mu_s_blend::tangent`]). Made
//! at each lookup that is four logarithms and two tangents per value, for each of the 8
//! (μ, ν, r) texels of the 3 scattering tables: since the blend covers the cells of a sun
//! up to 20° ([`super::mu_s_blend::LOG_BLEND_MAX_SUN_ELEVATION_DEG`], 2026-12-07), every
//! lookup of a golden-hour frame takes it, and the default scene's spectral 1080p frame went
//! from 6.3 s to 28.6 s on 2 cores (its lookups were 34 % of the RGB frame's time, in
//! `blend_at`). Here each sample's ln L and tangent, for every (r, μ, ν, channel), are made
//! the first time a lookup needs that sample and kept: a lookup then costs one exp per
//! value. A frame needs the few samples around its sun's μ_s (the scene's points span
//! fractions of a degree of it), so the store holds a few samples of the table's 40, in f32
//! (ln L to ~10⁻⁷ of itself: the blend's value to ~10⁻⁷ relative; 4 MiB a sample of a
//! spectral default table). The default scene's spectral frame: 28.2 → 11.2 s
//! (BENCHMARKS.md, "The low sun's μ_s log blend made once per sample").

use std::sync::OnceLock;

use super::mu_s_blend::{hermite, tangent, MuSFilter};
use super::table::Table4;
use crate::math::fast::{exp_in_range, ln};

/// [ln L, dlnL/ds] per (r, μ, ν, channel) value of one μ_s sample, in the order
/// `((z·nmu + y)·nnu + ν)·channels + c`.
type SampleLogs = Vec<[f32; 2]>;

/// The blend's logarithms and tangents of one [`Table4`], per μ_s sample of its log-blend
/// cells, each made on first use. Belongs to the table it was made for, which must not
/// change afterwards.
#[derive(Debug, Default)]
pub struct MuSLogs {
    samples: Vec<OnceLock<SampleLogs>>,
}

/// The made logarithms of one lookup's μ_s cell: its lower (s0) and upper (s1) samples.
#[derive(Clone, Copy)]
pub struct CellLogs<'a> {
    /// s0's [ln L, tangent] per value.
    pub lower: &'a [[f32; 2]],
    /// s1's.
    pub upper: &'a [[f32; 2]],
}

impl MuSLogs {
    /// The (empty) store for a table of `nmu_s` samples whose first `twilight_cells` cells
    /// take the blend ([`super::mu_s_blend::twilight_cells`]).
    pub fn new(twilight_cells: usize, nmu_s: usize) -> MuSLogs {
        let n = (twilight_cells + 1).min(nmu_s);
        MuSLogs {
            samples: (0..n).map(|_| OnceLock::new()).collect(),
        }
    }

    /// The logarithms of `filter`'s cell in `table`, made now if not yet; None where the
    /// cell is not blended in log ([`MuSFilter::geometric`] false) or lies beyond the store.
    #[inline]
    pub fn cell<'a>(&'a self, table: &Table4, filter: &MuSFilter) -> Option<CellLogs<'a>> {
        if !filter.geometric || filter.s1 >= self.samples.len() {
            return None;
        }
        Some(CellLogs {
            lower: self.sample(table, filter.s0),
            upper: self.sample(table, filter.s1),
        })
    }

    fn sample(&self, table: &Table4, s: usize) -> &[[f32; 2]] {
        self.samples[s].get_or_init(|| sample_logs(table, s))
    }
}

impl CellLogs<'_> {
    /// The values blended along μ_s by `s` (this cell's filter) of the `out.len()`
    /// consecutive channels of `table` whose μ_s columns start at `base`, `column` their
    /// index in the logarithms, into `out`: [`super::mu_s_blend::blend_logs`]'s rule, the
    /// Hermite in ln L where both samples are lit (monotone, so between the samples' f32
    /// logs and within exp's range), linear where not.
    #[inline]
    pub fn values(
        &self,
        table: &Table4,
        base: usize,
        column: usize,
        s: &MuSFilter,
        out: &mut [f64],
    ) {
        for (k, o) in out.iter_mut().enumerate() {
            let ([la, ma], [lb, mb]) = (self.lower[column + k], self.upper[column + k]);
            let (la, lb) = (la as f64, lb as f64);
            *o = if la.is_finite() && lb.is_finite() {
                exp_in_range(hermite(la, lb, ma as f64, mb as f64, s.t))
            } else {
                table.mu_s_linear(base + k, s)
            };
        }
    }
}

/// ln L at sample `s` of every (r, μ, ν, channel) column of `t` with its tangent from the
/// neighbours s − 1 and s + 1 (NaN where the table has none, as [`super::mu_s_blend::blend`]
/// takes them).
fn sample_logs(t: &Table4, s: usize) -> SampleLogs {
    let c = t.channels;
    let ln_at = |base: usize, i: usize| ln(t.data[base + i * c] as f64);
    let mut out = Vec::with_capacity(t.nr * t.nmu * t.nnu * c);
    for z in 0..t.nr {
        for y in 0..t.nmu {
            for nu in 0..t.nnu {
                let column = t.index(nu * t.nmu_s, y, z);
                for k in 0..c {
                    let base = column + k;
                    let l = ln_at(base, s);
                    let below = if s > 0 { ln_at(base, s - 1) } else { f64::NAN };
                    let above = if s + 1 < t.nmu_s {
                        ln_at(base, s + 1)
                    } else {
                        f64::NAN
                    };
                    out.push([l as f32, tangent(below, l, above) as f32]);
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sky::bruneton4d::table::LookupBlend;

    /// A table with 3 channels whose values fall near-exponentially along μ_s with a
    /// texel-wise jitter, a few unlit (0) texels and a column unlit at its first samples
    /// (the twilight's shadow).
    fn table() -> Table4 {
        let (nr, nmu, nmu_s, nnu, c) = (5, 6, 9, 3, 3);
        let mut t = Table4::new(nr, nmu, nmu_s, nnu, c);
        for z in 0..nr {
            for y in 0..nmu {
                for nu in 0..nnu {
                    for s in 0..nmu_s {
                        for k in 0..c {
                            let i = t.index(nu * nmu_s + s, y, z) + k;
                            let h = (i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 44;
                            let unlit = h.is_multiple_of(23) || (y == 2 && s < 2);
                            t.data[i] = if unlit {
                                0.0
                            } else {
                                let jitter = 1.0 + (h % 100) as f64 / 400.0;
                                (jitter * (0.9 * s as f64 - 0.2 * z as f64).exp()) as f32
                            };
                        }
                    }
                }
            }
        }
        t
    }

    #[test]
    fn lookups_with_the_made_logs_equal_the_blend_made_at_each_lookup() {
        let t = table();
        let blend = LookupBlend {
            twilight_cells: 6,
            bottom_over_h: 7.3,
        };
        let logs = MuSLogs::new(blend.twilight_cells, t.nmu_s);
        let (mut worst, mut cells) = (0.0f64, 0);
        for i in 0..4000 {
            // Halton points over the 4 coordinates: every cell, log-blended or not.
            let u = [2u64, 3, 5, 7].map(|b| {
                let (mut f, mut x, mut n) = (1.0, 0.0, i + 1);
                while n > 0 {
                    f /= b as f64;
                    x += f * (n % b) as f64;
                    n /= b;
                }
                x
            });
            let s = MuSFilter::new(u[1], t.nmu_s, blend.twilight_cells);
            cells += usize::from(logs.cell(&t, &s).is_some());
            let (mut a, mut b) = ([0.0; 3], [0.0; 3]);
            t.sample_into(u, &blend, &mut a);
            t.sample_logs_into(u, &blend, Some(&logs), &mut b);
            for k in 0..3 {
                let e = (b[k] - a[k]).abs() / a[k].abs().max(1e-30);
                assert!(e < 1e-6, "{u:?} channel {k}: {} vs {}", b[k], a[k]);
                worst = worst.max(e);
            }
        }
        // Most lookups fell in the log cells (μ_s < 6/8 of the way), and made a difference
        // of f32's rounding of ln L, not 0: the made logs were read.
        assert!(cells > 2500, "{cells} lookups in log cells");
        assert!(worst > 0.0, "no lookup read the made logs");
    }

    #[test]
    fn a_sample_is_made_once_and_only_when_a_lookup_needs_it() {
        let t = table();
        let logs = MuSLogs::new(6, t.nmu_s);
        let made = |logs: &MuSLogs| logs.samples.iter().filter(|s| s.get().is_some()).count();
        assert_eq!(logs.samples.len(), 7);
        assert_eq!(made(&logs), 0);
        let s = MuSFilter::new(3.4 / 9.0, t.nmu_s, 6);
        let first = logs.cell(&t, &s).map(|c| c.lower.as_ptr());
        assert_eq!(made(&logs), 2);
        assert_eq!(logs.cell(&t, &s).map(|c| c.lower.as_ptr()), first);
        // A linear cell (beyond the log cells) makes nothing.
        assert!(logs.cell(&t, &MuSFilter::new(0.95, t.nmu_s, 6)).is_none());
        assert_eq!(made(&logs), 2);
    }
}

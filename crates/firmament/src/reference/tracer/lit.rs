//! Twilight sampling: next-event estimation along each flight rather than at its collision.
//!
//! The sunlight scattered once more towards the path from a flight of length L along d,
//! ∫₀ᴸ T(0,t) Σᵢ σ_s,ᵢ(t) pᵢ(d·l) T_sun(t) E dt, is estimated with a distance t drawn from
//! its own pdf, ∝ an estimate of that integrand (Kulla & Fajardo 2012, "Importance sampling
//! techniques for path tracing in participating media", §4, sample the distance for the
//! light, not for the medium; Novák et al. 2018, "Monte Carlo methods for volumetric light
//! transport simulation", §5.2 on distance sampling ∝ the product with the incident
//! light). The path itself goes on by delta tracking as before, without NEE at its
//! collisions: the flight's estimate replaces it (the same expectation: a collision drawn
//! ∝ T σ_t with weight σ_s/σ_t, NEE there, integrates the same function). Unbiased for any
//! pdf that is positive wherever the integrand is.
//!
//! The pdf is piecewise constant over graded nodes along the flight (`LINE_INTERVALS` per
//! monotone piece): at each node T(0,t) (trapezoids of σ_t), Σ σ_s,ᵢ pᵢ towards the sun's
//! centre and T_sun from a coarse table (`sun_table`; 0 in the planet's shadow); each
//! interval takes the larger of its ends. A defensive mixture (Hesterberg 1995) keeps a
//! fraction `DEFENSIVE` of the samples ∝ T σ_s p alone, with a uniform floor, so that no
//! lit stretch the nodes miss gets zero probability. At twilight most of the air a flight
//! crosses is in the planet's shadow, where NEE at a collision returns 0: this is what
//! made the reference's −6° views 20× noisier per path than daylight (docs/accuracy.md,
//! "The reference in twilight").

use super::geometry::{advance, Frame};
use super::{Channel, Primary, Scratch};
use crate::math::quadrature::GL4;
use crate::math::Vec3;
use crate::reference::rng::Rng;

/// Graded intervals per monotone piece of a flight for its distance pdf.
const LINE_INTERVALS: usize = 16;
/// The fraction of samples drawn without the sun's transmittance (defensive mixture).
const DEFENSIVE: f64 = 0.1;
/// The uniform floor of the defensive part, relative to its mean.
const FLOOR: f64 = 0.05;

/// A piecewise-constant distance pdf along a flight: nodes `t` and the cumulative
/// probability `cum` at each node (0 at the first, 1 at the last).
#[derive(Clone, Debug, Default)]
pub(crate) struct LitLine {
    t: Vec<f64>,
    cum: Vec<f64>,
    /// Per node: T(0,t) Σ σ_s p (scratch while building).
    plain: Vec<f64>,
    /// Per node: the same times T_sun.
    lit: Vec<f64>,
    /// Per constituent: σ_s p towards the sun's centre per unit density.
    phase: Vec<f64>,
}

impl LitLine {
    /// A distance drawn from the pdf with `u` ∈ [0, 1), and its pdf (per metre).
    fn sample(&self, u: f64) -> Option<(f64, f64)> {
        let n = self.cum.len();
        if n < 2 {
            return None;
        }
        let i = self.cum.partition_point(|&c| c <= u).clamp(1, n - 1) - 1;
        let (p, dt) = (self.cum[i + 1] - self.cum[i], self.t[i + 1] - self.t[i]);
        if p <= 0.0 || dt <= 0.0 {
            return None;
        }
        let f = ((u - self.cum[i]) / p).clamp(0.0, 1.0);
        Some((self.t[i] + f * dt, p / dt))
    }
}

/// Nodes along [0, t_end] of a ray with b = rμ, `n` graded intervals per monotone piece
/// (split at the closest approach), denser towards each piece's low end (u = s² there),
/// where the density changes fastest. Starts with 0 and ends with t_end.
fn graded_nodes(b: f64, t_end: f64, n: usize, out: &mut Vec<f64>) {
    out.clear();
    out.push(0.0);
    let ts = -b;
    let pieces: [(f64, f64); 2] = if ts > 0.0 && ts < t_end {
        [(0.0, ts), (ts, t_end)]
    } else {
        [(0.0, t_end), (0.0, 0.0)]
    };
    let n = n.max(1);
    for (a, z) in pieces {
        if z <= a {
            continue;
        }
        let low_at_a = a == ts || (a == 0.0 && b >= 0.0);
        for i in 0..n {
            let s1 = (i + 1) as f64 / n as f64;
            let u1 = if low_at_a {
                s1 * s1
            } else {
                1.0 - (1.0 - s1) * (1.0 - s1)
            };
            out.push(if i + 1 == n { z } else { a + (z - a) * u1 });
        }
    }
}

impl Channel<'_> {
    /// Whether paths use twilight sampling (the setting, and no volumes: their extinction
    /// is not in the flights' pdfs).
    #[inline]
    pub(super) fn lit(&self) -> bool {
        self.lit_sampling && !self.has_volumes()
    }

    /// The distance pdf along the flight from `o` along `d` over [0, t_end] on `line`,
    /// with nodes already in `line.t` (see the module documentation).
    fn build_line(&self, frame: &Frame, o: Vec3, d: Vec3, sun: Vec3, line: &mut LitLine) {
        let table = self.sun_table();
        let (x0, b) = (frame.x(o), frame.b(o, d));
        let (bs0, cos) = (frame.b(o, sun), d.dot(sun));
        let n = line.t.len();
        line.plain.clear();
        line.lit.clear();
        // σ_s,ᵢ pᵢ(d·sun) per unit density: the angle is the same all along the flight.
        line.phase.clear();
        line.phase
            .extend(self.parts.iter().map(|p| p.scattering * p.phase.eval(cos)));
        let (mut tau, mut prev_t, mut prev_sigma) = (0.0, 0.0, 0.0);
        for k in 0..n {
            let t = line.t[k];
            let h = self.alt(x0, b, t);
            let (mut sigma_t, mut sp) = (0.0, 0.0);
            for (p, sp_unit) in self.parts.iter().zip(&line.phase) {
                let rho = p.density.density(h);
                sigma_t += rho * p.extinction;
                sp += rho * sp_unit;
            }
            if k > 0 {
                tau += 0.5 * (sigma_t + prev_sigma) * (t - prev_t);
            }
            (prev_t, prev_sigma) = (t, sigma_t);
            let plain = (-tau).exp() * sp;
            let x = x0 + t * (2.0 * b + t);
            line.plain.push(plain);
            line.lit.push(plain * table.transmittance(x, bs0 + t * cos));
        }
        line.cum.clear();
        line.cum.push(0.0);
        if n < 2 {
            return;
        }
        let t_end = line.t[n - 1];
        let (mut lit_sum, mut plain_sum) = (0.0, 0.0);
        for k in 0..n - 1 {
            let dt = line.t[k + 1] - line.t[k];
            lit_sum += line.lit[k].max(line.lit[k + 1]) * dt;
            plain_sum += line.plain[k].max(line.plain[k + 1]) * dt;
        }
        let floor = if plain_sum > 0.0 {
            FLOOR * plain_sum / t_end
        } else {
            1.0
        };
        let plain_total = plain_sum + floor * t_end;
        let lit_share = if lit_sum > 0.0 { 1.0 - DEFENSIVE } else { 0.0 };
        let mut c = 0.0;
        for k in 0..n - 1 {
            let dt = line.t[k + 1] - line.t[k];
            let plain = (line.plain[k].max(line.plain[k + 1]) + floor) * dt / plain_total;
            let lit = if lit_sum > 0.0 {
                line.lit[k].max(line.lit[k + 1]) * dt / lit_sum
            } else {
                0.0
            };
            c += lit_share * lit + (1.0 - lit_share) * plain;
            line.cum.push(c);
        }
        for v in &mut line.cum {
            *v /= c;
        }
    }

    /// The optical depth from a camera ray's start to `t`: its tabulated depth at the node
    /// below, and Gauss–Legendre from there (the same rule as the table's intervals).
    fn primary_depth(&self, primary: &Primary, x0: f64, b: f64, t: f64) -> f64 {
        let i = primary
            .t
            .partition_point(|&v| v <= t)
            .clamp(1, primary.t.len())
            - 1;
        let mut tau = primary.tau[i];
        if t > primary.t[i] {
            for (s, w) in GL4.composite(primary.t[i], t, 1) {
                tau += w * self.extinction(self.alt(x0, b, s));
            }
        }
        tau
    }

    /// The sunlight scattered towards −d from the flight from `o` along `d`, one point
    /// drawn from `line` (W·m⁻²·sr⁻¹·nm⁻¹ per unit path weight); `primary` the camera ray
    /// when the flight is one, for its tabulated optical depth.
    #[allow(clippy::too_many_arguments)]
    fn line_estimate(
        &self,
        frame: &Frame,
        o: Vec3,
        d: Vec3,
        line: &LitLine,
        primary: Option<&Primary>,
        sun: Vec3,
        rng: &mut Rng,
        scratch: &mut Scratch,
    ) -> f64 {
        let Some((t, pdf)) = line.sample(rng.next_f64()) else {
            return 0.0;
        };
        let (ls, e) = self.sample_sun(sun, rng);
        let p = advance(o, t, d);
        let tr_sun = self.transmittance(frame, p, ls);
        if tr_sun <= 0.0 {
            return 0.0;
        }
        let (x0, b) = (frame.x(o), frame.b(o, d));
        let (_, ss) = self.coefficients(frame, p, self.alt(x0, b, t), scratch);
        if ss <= 0.0 {
            return 0.0;
        }
        let tau = match primary {
            Some(primary) => self.primary_depth(primary, x0, b, t),
            None => self.optical_depth(x0, b, t),
        };
        let tr = (-tau).exp();
        tr * ss * self.phase(scratch, ss, d.dot(ls)) * tr_sun * e / pdf
    }

    /// The flight from `o` along `d` to `t_end`: its pdf on the scratch line, then one
    /// estimate.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn flight_estimate(
        &self,
        frame: &Frame,
        o: Vec3,
        d: Vec3,
        t_end: f64,
        sun: Vec3,
        rng: &mut Rng,
        scratch: &mut Scratch,
    ) -> f64 {
        if t_end <= 0.0 {
            return 0.0;
        }
        let mut line = std::mem::take(&mut scratch.line);
        graded_nodes(frame.b(o, d), t_end, LINE_INTERVALS, &mut line.t);
        self.build_line(frame, o, d, sun, &mut line);
        let v = self.line_estimate(frame, o, d, &line, None, sun, rng, scratch);
        scratch.line = line;
        v
    }

    /// The camera ray's distance pdf, built once per ray and wavelength on its own nodes.
    pub(crate) fn primary_line(&self, frame: &Frame, primary: &mut Primary, sun: Vec3) {
        if !self.lit() || primary.t_end <= 0.0 {
            return;
        }
        let mut line = LitLine {
            t: primary.t.clone(),
            ..Default::default()
        };
        self.build_line(frame, primary.o, primary.d, sun, &mut line);
        primary.lit = Some(line);
    }

    /// The camera ray's line estimate (its pdf built here when the ray has none).
    pub(super) fn primary_estimate(
        &self,
        frame: &Frame,
        primary: &Primary,
        sun: Vec3,
        rng: &mut Rng,
        scratch: &mut Scratch,
    ) -> f64 {
        match &primary.lit {
            Some(line) => self.line_estimate(
                frame,
                primary.o,
                primary.d,
                line,
                Some(primary),
                sun,
                rng,
                scratch,
            ),
            None => self.flight_estimate(
                frame,
                primary.o,
                primary.d,
                primary.t_end,
                sun,
                rng,
                scratch,
            ),
        }
    }
}

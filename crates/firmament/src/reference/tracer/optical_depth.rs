//! Deterministic optical depths: towards the sun for next-event estimation (split at the
//! closest approach and the profiles' kinks, composite Gauss–Legendre on each smooth piece),
//! and cumulatively along camera rays for forced first collisions.

use super::geometry::Frame;
use super::{Channel, Primary};
use crate::math::quadrature::GL4;
use crate::math::Vec3;

impl Channel<'_> {
    /// Deterministic transmittance from offset `o` along unit `d` to the top of the
    /// atmosphere, through the volumes too; 0 if the ray meets the ground or a surface.
    pub(crate) fn transmittance(&self, frame: &Frame, o: Vec3, d: Vec3) -> f64 {
        let x0 = frame.x(o);
        let b = frame.b(o, d);
        let (t_end, ground) = self.boundary(x0, b);
        if ground || self.surfaces_block(frame, o, d, t_end) {
            return 0.0;
        }
        let mut tau = self.optical_depth(x0, b, t_end);
        if self.has_volumes() {
            tau += self.volume_optical_depth(frame, o, d);
        }
        (-tau).exp()
    }

    /// Optical depth along [0, t_end] (composite Gauss–Legendre). The ray is cut where its
    /// altitude is monotone (at the closest approach to the planet centre) and where it
    /// crosses an altitude at which a density profile has a kink (layer boundaries, the
    /// ends of a tent), so every piece has a smooth integrand and Gauss–Legendre converges
    /// fast: max relative error of τ ≈ 1e-6 with the default 8 segments (`earth`, 20 000
    /// random rays against 512 segments; it was 1.3e-5 with 24 unsplit segments).
    pub(crate) fn optical_depth(&self, x0: f64, b: f64, t_end: f64) -> f64 {
        if t_end <= 0.0 || self.parts.is_empty() {
            return 0.0;
        }
        let ts = -b;
        let mut tau = 0.0;
        if ts > 0.0 {
            // Descending towards the closest approach: lowest at the far end.
            tau += self.monotone_depth(x0, b, 0.0, ts.min(t_end), false);
        }
        let a = ts.max(0.0);
        if t_end > a {
            tau += self.monotone_depth(x0, b, a, t_end, true);
        }
        tau
    }

    /// Optical depth over [a, z] where the altitude is monotone (rising with t when
    /// `rising`), split at the profile kinks crossed.
    pub(super) fn monotone_depth(&self, x0: f64, b: f64, a: f64, z: f64, rising: bool) -> f64 {
        const MAX_CUTS: usize = 16;
        // Crossings of x(t) = x0 + 2bt + t² = x_k: t = −b ± √(b² + x_k − x0), written
        // without cancellation.
        let mut cuts = [0.0f64; MAX_CUTS + 2];
        let mut n_cuts = 0;
        cuts[n_cuts] = a;
        n_cuts += 1;
        for &xk in &self.kinks_x {
            if n_cuts > MAX_CUTS {
                break;
            }
            let c = xk - x0;
            let disc = b * b + c;
            if disc < 0.0 {
                continue;
            }
            let q = disc.sqrt();
            let t = if rising {
                if b >= 0.0 {
                    c / (b + q)
                } else {
                    q - b
                }
            } else if b < 0.0 {
                -c / (q - b)
            } else {
                continue;
            };
            if t > a && t < z {
                cuts[n_cuts] = t;
                n_cuts += 1;
            }
        }
        cuts[n_cuts] = z;
        n_cuts += 1;
        cuts[..n_cuts].sort_unstable_by(f64::total_cmp);
        let n = self.segments;
        let mut tau = 0.0;
        for j in 0..n_cuts - 1 {
            let (p, q) = (cuts[j], cuts[j + 1]);
            if q <= p {
                continue;
            }
            // Grade towards the low end of the piece, where the density changes fastest
            // (e^{-h/H} near the closest approach or the start of an upward ray).
            let graded_low_at_p = rising && j == 0;
            let graded_low_at_q = !rising && j + 2 == n_cuts;
            let n = if graded_low_at_p || graded_low_at_q {
                n
            } else {
                n.div_ceil(2).max(2)
            };
            let mut sum = 0.0;
            for i in 0..n {
                let (s0, s1) = (i as f64 / n as f64, (i + 1) as f64 / n as f64);
                let (u0, u1) = if graded_low_at_p {
                    (s0 * s0, s1 * s1)
                } else if graded_low_at_q {
                    (1.0 - (1.0 - s0) * (1.0 - s0), 1.0 - (1.0 - s1) * (1.0 - s1))
                } else {
                    (s0, s1)
                };
                let (p0, p1) = (p + (q - p) * u0, p + (q - p) * u1);
                for (t, w) in GL4.composite(p0, p1, 1) {
                    sum += w * self.extinction(self.alt(x0, b, t));
                }
            }
            tau += sum;
        }
        tau
    }

    /// The cumulative optical depth along a camera ray up to where it ends (the ground, a
    /// surface or the top), for forced first collisions.
    pub(crate) fn primary(&self, frame: &Frame, o: Vec3, d: Vec3, intervals: usize) -> Primary {
        let x0 = frame.x(o);
        let b = frame.b(o, d);
        let (t_end, end) = self.flight(frame, o, d, x0, b);
        let mut t = vec![0.0];
        let mut tau = vec![0.0];
        let ts = -b;
        let pieces: [(f64, f64); 2] = if ts > 0.0 && ts < t_end {
            [(0.0, ts), (ts, t_end)]
        } else {
            [(0.0, t_end), (0.0, 0.0)]
        };
        let n = intervals.max(1);
        for (a, z) in pieces {
            if z <= a {
                continue;
            }
            let low_at_a = a == ts || (a == 0.0 && b >= 0.0);
            for i in 0..n {
                let (s0, s1) = (i as f64 / n as f64, (i + 1) as f64 / n as f64);
                let (u0, u1) = if low_at_a {
                    (s0 * s0, s1 * s1)
                } else {
                    (1.0 - (1.0 - s0) * (1.0 - s0), 1.0 - (1.0 - s1) * (1.0 - s1))
                };
                let (p0, p1) = (
                    a + (z - a) * u0,
                    if i + 1 == n { z } else { a + (z - a) * u1 },
                );
                let mut sum = 0.0;
                for (t, w) in GL4.composite(p0, p1, 1) {
                    sum += w * self.extinction(self.alt(x0, b, t));
                }
                t.push(p1);
                tau.push(tau.last().unwrap() + sum);
            }
        }
        Primary {
            o,
            d,
            t,
            tau,
            t_end,
            end,
            lit: None,
        }
    }
}

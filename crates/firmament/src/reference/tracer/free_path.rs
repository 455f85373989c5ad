//! Free paths: delta (Woodcock) tracking with a piecewise-constant majorant over chunks of
//! the ray whose altitude changes by a bounded amount.

use super::geometry::Frame;
use super::{Channel, Scratch};
use crate::math::Vec3;
use crate::medium::DensityProfile;
use crate::reference::rng::Rng;

/// Upper bound of a layered profile's density over altitudes [hmin, hmax] (hmin ≥ 0).
pub(super) fn profile_bound(p: &DensityProfile, hmin: f64, hmax: f64) -> f64 {
    let n = p.layers.len();
    let mut base = 0.0;
    let mut best = 0.0f64;
    for (i, l) in p.layers.iter().enumerate() {
        let last = i + 1 == n;
        let lo = base;
        let hi = if last {
            f64::INFINITY
        } else {
            base + l.width_m
        };
        let a = hmin.max(lo);
        let b = hmax.min(hi);
        if a <= b {
            let e = if l.exp_term > 0.0 {
                l.exp_term * (-a / l.scale_height_m).exp()
            } else if l.exp_term < 0.0 {
                l.exp_term * (-b / l.scale_height_m).exp()
            } else {
                0.0
            };
            let lin = if l.linear_term_per_m > 0.0 {
                l.linear_term_per_m * b
            } else {
                l.linear_term_per_m * a
            };
            best = best.max(e + lin + l.constant_term);
        }
        if !last {
            base += l.width_m;
        }
    }
    best.max(0.0)
}

impl Channel<'_> {
    /// Altitude after `t` metres along a ray with x₀, b.
    #[inline]
    pub(super) fn alt(&self, x0: f64, b: f64, t: f64) -> f64 {
        let x = x0 + t * (2.0 * b + t);
        let r = (self.bottom * self.bottom + x).max(0.0).sqrt();
        (x / (r + self.bottom)).max(0.0)
    }

    #[inline]
    pub(super) fn extinction(&self, h: f64) -> f64 {
        let mut s = 0.0;
        for p in &self.parts {
            s += p.density.density(h) * p.extinction;
        }
        s
    }

    /// Distance to where the ray leaves the atmosphere, and whether that is the ground.
    #[inline]
    pub(super) fn boundary(&self, x0: f64, b: f64) -> (f64, bool) {
        if b < 0.0 {
            let disc = b * b - x0;
            if disc >= 0.0 {
                let t = if x0 <= 0.0 {
                    0.0
                } else {
                    x0 / (-b + disc.sqrt())
                };
                return (t, true);
            }
        }
        let c = x0 - self.x_top;
        let s = (b * b - c).max(0.0).sqrt();
        let t = if b <= 0.0 {
            s - b
        } else if s + b > 0.0 {
            -c / (s + b)
        } else {
            0.0
        };
        (t.max(0.0), false)
    }

    /// (min, max) altitude over [t0, t1] of a ray.
    #[inline]
    pub(super) fn alt_range(&self, x0: f64, b: f64, t0: f64, t1: f64) -> (f64, f64, f64, f64) {
        let h0 = self.alt(x0, b, t0);
        let h1 = self.alt(x0, b, t1);
        let ts = (-b).clamp(t0, t1);
        let hs = self.alt(x0, b, ts);
        (hs.min(h0).min(h1), h0.max(h1), h0, h1)
    }

    /// Next chunk [t0, t1] and its majorant.
    pub(super) fn chunk(&self, x0: f64, b: f64, t0: f64, t_end: f64) -> (f64, f64) {
        let remaining = t_end - t0;
        let xt = x0 + t0 * (2.0 * b + t0);
        let r = (self.bottom * self.bottom + xt).max(1.0).sqrt();
        let mu = ((b + t0) / r).clamp(-1.0, 1.0);
        let mut dh = self.height;
        loop {
            let ell = if dh >= self.height {
                remaining
            } else {
                (2.0 * dh / (mu.abs() + (mu * mu + 2.0 * dh / r).sqrt())).min(remaining)
            };
            let t1 = t0 + ell;
            let (hmin, hmax, h0, h1) = self.alt_range(x0, b, t0, t1);
            let mut maj = 0.0;
            for p in &self.parts {
                maj += profile_bound(p.density, hmin, hmax) * p.extinction;
            }
            maj *= 1.0 + 1e-9;
            if dh <= self.min_dh || maj * ell <= 0.5 {
                return (t1, maj);
            }
            let low = self.extinction(h0).min(self.extinction(h1));
            if (maj - low) * ell <= 0.5 {
                return (t1, maj);
            }
            dh *= 0.25;
        }
    }

    /// Delta tracking along [0, t_end] of the flight from offset `o` along `d` (x₀, b its
    /// invariants): the distance of the first real collision, if any. The volumes'
    /// extinction joins the atmosphere's where there are any.
    pub(super) fn collide(
        &self,
        frame: &Frame,
        o: Vec3,
        d: Vec3,
        t_end: f64,
        rng: &mut Rng,
        scratch: &mut Scratch,
    ) -> Option<f64> {
        let (x0, b) = (frame.x(o), frame.b(o, d));
        let volumes = self.has_volumes();
        let mut t0 = 0.0;
        while t0 < t_end {
            let (t1, mut maj) = self.chunk(x0, b, t0, t_end);
            if volumes {
                maj += self.volume_majorant(frame, o, d, t0, t1);
            }
            if maj > 0.0 {
                let mut t = t0;
                loop {
                    t += rng.exponential() / maj;
                    if t >= t1 {
                        break;
                    }
                    let mut sigma = self.extinction(self.alt(x0, b, t));
                    if volumes {
                        sigma += self.volume_extinction(frame.point(o + t * d), scratch);
                    }
                    if rng.next_f64() * maj < sigma {
                        return Some(t);
                    }
                }
            }
            if t1 <= t0 {
                break;
            }
            t0 = t1;
        }
        None
    }
}

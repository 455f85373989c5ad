//! Twilight guiding: where the sun is below a collision's horizontal, the light that reaches
//! it comes mostly from the twilight arch, the sunlit air low over the horizon towards
//! the sun, a few % of the sphere that phase sampling rarely finds. There the new direction
//! is drawn from a one-sample mixture (Veach & Guibas 1995, balance heuristic) of the
//! phase function and a von Mises–Fisher lobe about the horizon towards the sun, lifted
//! by `LIFT_RAD` (sampled as in Jakob 2012, "Numerically stable sampling of the von
//! Mises–Fisher distribution on S²"); the path's weight takes p/(mixture pdf), so the
//! estimate stays unbiased and only its variance changes.

use std::f64::consts::PI;

use super::geometry::{rotate, Frame};
use super::{Channel, Scratch};
use crate::math::Vec3;
use crate::reference::rng::Rng;

/// The share of directions drawn from the lobe where the sun is below the horizon.
const LOBE_SHARE: f64 = 0.5;
/// The lobe's concentration κ (its angular spread is about 1/√κ rad, 18°).
const KAPPA: f64 = 10.0;
/// The lobe's axis above the horizon (rad; the horizon dips by arccos(R_g/r) at a
/// collision of radius r).
const LIFT_RAD: f64 = 0.1;

/// The lobe's axis at a collision with local vertical `up` whose horizon dips by `dip`
/// (rad), when the sun is below the horizontal.
fn lobe_axis(up: Vec3, sun: Vec3, dip: f64) -> Option<Vec3> {
    let s_up = sun.dot(up);
    if s_up >= 0.0 {
        return None;
    }
    let flat = (sun - s_up * up).normalize_or_zero();
    if flat == Vec3::ZERO {
        return None;
    }
    let e = LIFT_RAD - dip;
    Some((flat * e.cos() + up * e.sin()).normalize_or_zero())
}

/// The vMF density (per steradian) of `d` about unit `axis`.
#[inline]
fn lobe_pdf(axis: Vec3, d: Vec3) -> f64 {
    KAPPA * (KAPPA * (axis.dot(d) - 1.0)).exp() / (2.0 * PI * (1.0 - (-2.0 * KAPPA).exp()))
}

impl Channel<'_> {
    /// The new direction after a collision at `o` (its scatterers in `scratch`, σ_s =
    /// `ss`) coming along `d`, with the path weight `w` scaled by p/(sampling pdf).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn guided_scatter(
        &self,
        frame: &Frame,
        o: Vec3,
        d: Vec3,
        scratch: &Scratch,
        ss: f64,
        sun: Vec3,
        w: &mut f64,
        rng: &mut Rng,
    ) -> Vec3 {
        let x = frame.x(o).max(0.0);
        let dip = (x.sqrt() / (self.bottom * self.bottom + x).sqrt()).asin();
        let Some(axis) = lobe_axis(frame.up(o), sun, dip) else {
            return self.scatter(d, scratch, ss, rng);
        };
        let next = if rng.next_f64() < LOBE_SHARE {
            let u = rng.next_f64();
            let cos = 1.0 + (u + (1.0 - u) * (-2.0 * KAPPA).exp()).ln() / KAPPA;
            rotate(axis, cos, 2.0 * PI * rng.next_f64())
        } else {
            self.scatter(d, scratch, ss, rng)
        };
        let p = self.phase(scratch, ss, d.dot(next));
        let pdf = (1.0 - LOBE_SHARE) * p + LOBE_SHARE * lobe_pdf(axis, next);
        if pdf > 0.0 {
            *w *= p / pdf;
        } else {
            *w = 0.0;
        }
        next
    }
}

//! Positions relative to an anchor on the ground sphere, so altitudes are computed without
//! cancellation at any planet radius, and direction sampling around an axis.

use std::f64::consts::PI;

use crate::math::Vec3;
use crate::reference::rng::Rng;

/// Positions relative to an anchor on the ground sphere.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Frame {
    anchor: Vec3,
    c0: f64,
}

impl Frame {
    /// Anchor on the ground sphere below `point` (planet-centred).
    pub(crate) fn below(point: Vec3, bottom_m: f64) -> Frame {
        let n = point.normalize_or_zero();
        let n = if n == Vec3::ZERO { Vec3::Z } else { n };
        let anchor = n * bottom_m;
        let c0 = anchor.dot(anchor) - bottom_m * bottom_m;
        Frame { anchor, c0 }
    }

    /// Offset of a planet-centred point.
    #[inline]
    pub(crate) fn offset(&self, p: Vec3) -> Vec3 {
        p - self.anchor
    }

    /// The planet-centred point at offset `o`.
    #[inline]
    pub(crate) fn point(&self, o: Vec3) -> Vec3 {
        self.anchor + o
    }

    /// r² − R_g² at offset `o`.
    #[inline]
    pub(crate) fn x(&self, o: Vec3) -> f64 {
        self.c0 + 2.0 * self.anchor.dot(o) + o.dot(o)
    }

    /// (A + o)·d = r μ.
    #[inline]
    pub(crate) fn b(&self, o: Vec3, d: Vec3) -> f64 {
        self.anchor.dot(d) + o.dot(d)
    }

    /// Local vertical (unit) at offset `o`.
    #[inline]
    pub(crate) fn up(&self, o: Vec3) -> Vec3 {
        (self.anchor + o).normalize_or_zero()
    }
}

#[inline]
pub(crate) fn advance(o: Vec3, t: f64, d: Vec3) -> Vec3 {
    o + t * d
}

/// Orthonormal basis around a unit vector (Duff et al. 2017, JCGT 6(1)).
#[inline]
fn basis(n: Vec3) -> (Vec3, Vec3) {
    let s = 1.0f64.copysign(n.z);
    let a = -1.0 / (s + n.z);
    let b = n.x * n.y * a;
    (
        Vec3::new(1.0 + s * n.x * n.x * a, s * b, -s * n.x),
        Vec3::new(b, s + n.y * n.y * a, -n.y),
    )
}

/// The direction at angle acos(`cos_t`) from unit `axis`, at azimuth `phi` around it.
#[inline]
pub(crate) fn rotate(axis: Vec3, cos_t: f64, phi: f64) -> Vec3 {
    let c = cos_t.clamp(-1.0, 1.0);
    let s = ((1.0 - c) * (1.0 + c)).max(0.0).sqrt();
    let (t1, t2) = basis(axis);
    let (cp, sp) = (phi.cos(), phi.sin());
    (c * axis + s * (cp * t1 + sp * t2)).normalize_or_zero()
}

/// A cosine-distributed direction around unit `n`.
#[inline]
pub(crate) fn cosine_direction(n: Vec3, rng: &mut Rng) -> Vec3 {
    let u1 = rng.next_f64();
    let u2 = rng.next_f64();
    rotate(n, (1.0 - u1).sqrt(), 2.0 * PI * u2)
}

//! Where a view ray starts in the atmosphere: at the observer when it is inside, else where
//! the ray enters the top (a camera in space). Every sky method's view starts its rays here.

use crate::math::sphere::distance_to_enter_sphere;
use crate::math::Vec3;

/// The start of a view ray in the atmosphere.
#[derive(Clone, Copy, Debug)]
pub struct Entry {
    /// The start point (planet-centred, m).
    pub point: Vec3,
    /// Its radius (m).
    pub r: f64,
    /// r·μ along the ray at the start (m).
    pub rmu: f64,
    /// Whether it is the observer itself.
    pub at_observer: bool,
}

impl Entry {
    /// Distance (m) from the observer to the start (0 inside the atmosphere).
    #[inline]
    pub fn offset_m(&self, observer: Vec3) -> f64 {
        if self.at_observer {
            0.0
        } else {
            (self.point - observer).length()
        }
    }

    /// Distance (m) along the ray from the start to `point`, which lies on the ray from
    /// `observer`: not positive for a point the ray reaches before it enters the atmosphere
    /// (the air between the observer and it is none).
    #[inline]
    pub fn distance_to(&self, observer: Vec3, point: Vec3) -> f64 {
        (point - observer).length() - self.offset_m(observer)
    }

    /// The zenith cosine of the ray at its start.
    #[inline]
    pub fn mu(&self) -> f64 {
        (self.rmu / self.r).clamp(-1.0, 1.0)
    }
}

/// The start of the ray from `observer` (radius `observer_r`, m) along unit `dir` in an
/// atmosphere whose top has radius `top` (m); None when the ray misses the atmosphere.
#[inline]
pub fn enter_atmosphere(observer: Vec3, observer_r: f64, dir: Vec3, top: f64) -> Option<Entry> {
    let rmu = observer.dot(dir);
    if observer_r <= top {
        return Some(Entry {
            point: observer,
            r: observer_r,
            rmu,
            at_observer: true,
        });
    }
    let d = distance_to_enter_sphere(observer_r, rmu, top)?;
    Some(Entry {
        point: observer + dir * d,
        r: top,
        rmu: rmu + d,
        at_observer: false,
    })
}

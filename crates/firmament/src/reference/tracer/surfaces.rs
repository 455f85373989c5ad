//! The scene's surfaces in the path tracer (terrain, balls: anything implementing
//! [`crate::scene::Surface`]) besides the planet's ground sphere, which stays analytic with
//! the model's albedo. A flight through the air ends at the nearest of the ground sphere,
//! the top of the atmosphere and the surfaces; a surface hit is a Lambertian reflection
//! exactly like a ground bounce (NEE towards the sun with cos = n·l, cosine-sampled
//! continuation about the hit's normal), with the surface's albedo of this channel; a
//! shadow ray that meets a surface carries no sunlight.
//!
//! Surfaces are met only inside the atmosphere (up to where the flight would leave through
//! its top): the traced world ends there, for paths and shadow rays alike, so one beyond
//! the top neither shows nor shades. Every query is a world-space ray (the frame's anchor
//! plus the offset); with no surfaces nothing is asked, so the planet alone costs what it
//! did.

use super::geometry::{advance, Frame};
use super::{Channel, End, Scratch};
use crate::math::Vec3;
use crate::scene::{Ray, SurfaceHit};

/// A path leaving a surface starts this far (m) off it along the normal, so that the
/// rounding of the hit does not put it under the surface it just left (which would then be
/// met again at a distance of nanometres, or hide the sun from it).
const LIFT_M: f64 = 1e-4;

/// A surface wins a tie with the ground sphere within this distance (m) along the ray
/// beyond the sphere, so that a terrain lying on the sphere (a plain at height 0) is the
/// terrain, with its own albedo, whatever the rounding of the two hits, as in the renderer.
const TIE_M: f64 = 1e-2;

/// The lift grows with the size of the world coordinates where LIFT_M would be below their
/// rounding (a planet of 1e12 m, the plane-parallel limit, has an ulp of 1.2e-4 m): this
/// many ulps of |position|.
const LIFT_ULPS: f64 = 64.0;

impl Channel<'_> {
    /// Where the flight from offset `o` along unit `d` (x₀, b its invariants) leaves the
    /// air: its length (m) and what it meets there (a surface before the ground sphere
    /// within [`TIE_M`]).
    #[inline]
    pub(super) fn flight(&self, frame: &Frame, o: Vec3, d: Vec3, x0: f64, b: f64) -> (f64, End) {
        let (t_end, ground) = self.boundary(x0, b);
        if self.surfaces.is_empty() {
            return (t_end, if ground { End::Ground } else { End::Space });
        }
        let (max_m, end) = if ground {
            (t_end + TIE_M, End::Ground)
        } else {
            (t_end, End::Space)
        };
        match self.surface_hit(frame, o, d, max_m) {
            Some((i, hit)) => (hit.distance_m, End::Surface(i, hit)),
            None => (t_end, end),
        }
    }

    /// The nearest surface hit, and the surface's index, of the ray from offset `o` along
    /// `d` within (0, `max_m`).
    fn surface_hit(
        &self,
        frame: &Frame,
        o: Vec3,
        d: Vec3,
        max_m: f64,
    ) -> Option<(usize, SurfaceHit)> {
        let ray = Ray {
            origin: frame.point(o),
            dir: d,
        };
        let mut nearest = None;
        let mut max_m = max_m;
        for (i, s) in self.surfaces.iter().enumerate() {
            if let Some(hit) = s.intersect(&ray, max_m) {
                max_m = hit.distance_m;
                nearest = Some((i, hit));
            }
        }
        nearest
    }

    /// Whether a surface lies on the ray from offset `o` along `d` within (0, `max_m`): a
    /// shadow ray blocked.
    #[inline]
    pub(super) fn surfaces_block(&self, frame: &Frame, o: Vec3, d: Vec3, max_m: f64) -> bool {
        if self.surfaces.is_empty() {
            return false;
        }
        let ray = Ray {
            origin: frame.point(o),
            dir: d,
        };
        self.surfaces
            .iter()
            .any(|s| s.intersect(&ray, max_m).is_some())
    }

    /// The reflection where the flight from offset `o` along `d` ends, after `t_end` m at
    /// `end`: the offset the path goes on from (lifted off a surface, see [`LIFT_M`]), the
    /// unit normal about which it is reflected, and the albedo of this channel there (the
    /// model's on the ground sphere, the surface's own on a surface). None through the top
    /// of the atmosphere.
    #[inline]
    pub(super) fn reflection(
        &self,
        frame: &Frame,
        o: Vec3,
        d: Vec3,
        t_end: f64,
        end: &End,
        scratch: &mut Scratch,
    ) -> Option<(Vec3, Vec3, f64)> {
        match end {
            End::Space => None,
            End::Ground => {
                let p = advance(o, t_end, d);
                Some((p, frame.up(p), self.ground_albedo))
            }
            End::Surface(i, hit) => {
                self.surfaces[*i].albedo(hit, &mut scratch.albedo);
                let lift = LIFT_M.max(LIFT_ULPS * f64::EPSILON * hit.position.length());
                let p = advance(o, t_end, d) + lift * hit.normal;
                Some((p, hit.normal, scratch.albedo[self.index]))
            }
        }
    }

    /// Whether there are surfaces besides the ground sphere.
    pub(super) fn has_surfaces(&self) -> bool {
        !self.surfaces.is_empty()
    }
}

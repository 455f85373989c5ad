//! The scene's volumes in the path tracer: their extinction joins the atmosphere's in delta
//! tracking (majorants added over each chunk of a flight), their scattering in the choice of
//! scatterer and the phase function at a collision, their optical depth in the
//! transmittance towards the sun. Everything in world coordinates (the frame's anchor plus
//! the offset).

use super::geometry::Frame;
use super::{Channel, Scratch};
use crate::math::Vec3;
use crate::scene::Ray;

impl Channel<'_> {
    /// The volumes' extinction and scattering of this channel at `point`; each volume's
    /// scattering left in `scratch` with the point.
    pub(super) fn volume_coefficients(&self, point: Vec3, scratch: &mut Scratch) -> (f64, f64) {
        let k = self.index;
        let (mut st, mut ss) = (0.0, 0.0);
        scratch.point = point;
        for (v, s) in self
            .volumes
            .iter()
            .zip(scratch.volume_scattering.iter_mut())
        {
            v.coefficients(point, &mut scratch.extinction, &mut scratch.scattering);
            st += scratch.extinction[k];
            *s = scratch.scattering[k];
            ss += *s;
        }
        (st, ss)
    }

    /// The volumes' extinction of this channel at `point`.
    pub(super) fn volume_extinction(&self, point: Vec3, scratch: &mut Scratch) -> f64 {
        let mut st = 0.0;
        for v in self.volumes {
            v.coefficients(point, &mut scratch.extinction, &mut scratch.scattering);
            st += scratch.extinction[self.index];
        }
        st
    }

    /// An upper bound of the volumes' extinction over [t0, t1] of the flight from offset `o`
    /// along `d`.
    pub(super) fn volume_majorant(&self, frame: &Frame, o: Vec3, d: Vec3, t0: f64, t1: f64) -> f64 {
        let ray = Ray {
            origin: frame.point(o),
            dir: d,
        };
        self.volumes
            .iter()
            .map(|v| v.majorant(&ray, t0, t1, self.index))
            .sum()
    }

    /// The volumes' optical depth from offset `o` along `d` to infinity.
    pub(super) fn volume_optical_depth(&self, frame: &Frame, o: Vec3, d: Vec3) -> f64 {
        let ray = Ray {
            origin: frame.point(o),
            dir: d,
        };
        self.volumes
            .iter()
            .map(|v| v.optical_depth(&ray, 0.0, f64::INFINITY, self.index))
            .sum()
    }

    /// Whether there are volumes.
    pub(super) fn has_volumes(&self) -> bool {
        !self.volumes.is_empty()
    }
}

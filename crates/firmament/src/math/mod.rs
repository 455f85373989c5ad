//! Mathematics shared by every part of firmament: 3-vectors (glam's `DVec3`, planet-centred
//! metres or unit directions), ray geometry in a spherical atmosphere ([`sphere`]) and
//! quadrature rules ([`quadrature`]), cheap elementary functions for the hot loops ([`fast`]).

pub mod fast;
pub mod hash;
pub mod lattice;
pub mod quadrature;
pub mod sphere;

/// A 3-vector in metres (planet-centred positions) or a unit direction.
pub use glam::DVec3 as Vec3;

/// Unit direction from a zenith angle and an azimuth (radians) in the local frame
/// x = east, y = north, z = up, azimuth clockwise from north (towards east).
pub fn direction_from_zenith_azimuth(zenith_rad: f64, azimuth_rad: f64) -> Vec3 {
    let s = zenith_rad.sin();
    Vec3::new(
        s * azimuth_rad.sin(),
        s * azimuth_rad.cos(),
        zenith_rad.cos(),
    )
}

/// GLSL's smoothstep: 0 below `e0`, 1 above `e1`, the cubic 3t² − 2t³ between (a step at
/// `e0` when the edges coincide). Inlined always, so that constant edges fold their
/// reciprocal span into a constant (the clouds' profiles run for every sample of a march).
#[inline(always)]
pub fn smoothstep(e0: f64, e1: f64, x: f64) -> f64 {
    if e1 <= e0 {
        return if x < e0 { 0.0 } else { 1.0 };
    }
    let t = ((x - e0) * (1.0 / (e1 - e0))).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

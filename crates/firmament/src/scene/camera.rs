//! Cameras. The world is planet-centred (metres). The observer stands above the point of the
//! planet on the +z axis; its local frame there is x = east, y = north, z = up, and
//! azimuths/headings are clockwise from north.

use std::f64::consts::PI;

use serde::{Deserialize, Serialize};

use crate::math::{direction_from_zenith_azimuth, Vec3};
use crate::{Error, Result};

/// The kind of projection.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Projection {
    /// Pinhole camera with a vertical field of view.
    Perspective,
    /// Equidistant all-sky fisheye: zenith at the centre, horizon on the circle, the heading
    /// (north by default) up, east of it to the left (as seen looking up, the standard for
    /// sky cameras).
    Fisheye,
    /// Equirectangular 360×180 map: columns are azimuth clockwise from the heading (north by
    /// default), from −180° at the left edge through the heading at the centre column and
    /// 90° east of it at three quarters of the width; rows are elevation, +90° at the top
    /// row. See docs/conventions.md for where this lands in Blender, Unity, Godot, Unreal.
    Equirect,
    /// Six square faces side by side in the order +X (east), −X (west), +Y (north),
    /// −Y (south), +Z (up), −Z (down); each is a 90° view as seen from the inside, side
    /// faces with the zenith at the top, the up and down faces with north at the top.
    Cubemap,
    /// A perspective camera in space looking at the planet's centre from above the observer
    /// point; the field of view fits the whole planet unless given.
    Orbit,
}

/// Camera parameters.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Camera {
    /// Projection.
    pub projection: Projection,
    /// Altitude above the ground (m).
    pub altitude_m: f64,
    /// Heading of the view (degrees clockwise from north).
    #[serde(default)]
    pub heading_deg: f64,
    /// Pitch (degrees above the horizon).
    #[serde(default)]
    pub pitch_deg: f64,
    /// Roll (degrees, clockwise).
    #[serde(default)]
    pub roll_deg: f64,
    /// Vertical field of view (degrees), perspective and orbit.
    #[serde(default = "default_fov")]
    pub fov_deg: f64,
}

fn default_fov() -> f64 {
    60.0
}

/// A primary ray.
#[derive(Clone, Copy, Debug)]
pub struct Ray {
    /// Origin (m, planet-centred).
    pub origin: Vec3,
    /// Unit direction.
    pub dir: Vec3,
}

impl Camera {
    /// Check the values.
    pub fn validate(&self) -> Result<()> {
        if !(self.altitude_m.is_finite() && self.altitude_m >= 0.0) {
            return Err(Error::invalid(
                "camera.altitude_m",
                self.altitude_m,
                "a finite altitude ≥ 0 m",
            ));
        }
        for (name, v) in [
            ("camera.heading_deg", self.heading_deg),
            ("camera.roll_deg", self.roll_deg),
        ] {
            if !(v.is_finite() && v.abs() <= 360.0) {
                return Err(Error::invalid(name, v, "a number in [-360, 360] degrees"));
            }
        }
        if !(self.pitch_deg.is_finite() && self.pitch_deg.abs() <= 90.0) {
            return Err(Error::invalid(
                "camera.pitch_deg",
                self.pitch_deg,
                "a number in [-90, 90] degrees",
            ));
        }
        let level = match self.projection {
            Projection::Fisheye | Projection::Equirect => ["pitch_deg", "roll_deg"].as_slice(),
            Projection::Cubemap => &["heading_deg", "pitch_deg", "roll_deg"],
            Projection::Orbit => &["pitch_deg"],
            Projection::Perspective => &[],
        };
        for name in level {
            let v = match *name {
                "heading_deg" => self.heading_deg,
                "pitch_deg" => self.pitch_deg,
                _ => self.roll_deg,
            };
            if v != 0.0 {
                return Err(Error::invalid(
                    format!("camera.{name}"),
                    v,
                    format!(
                        "0 for the {:?} projection (it would be ignored: all-round maps are level, a cube map's faces face the axes, an orbit camera looks down)",
                        self.projection
                    ),
                ));
            }
        }
        if !(self.fov_deg.is_finite() && self.fov_deg > 0.0 && self.fov_deg < 180.0) {
            return Err(Error::invalid(
                "camera.fov_deg",
                self.fov_deg,
                "a number in (0, 180) degrees",
            ));
        }
        Ok(())
    }

    /// Per-frame constants for [`PreparedCamera::ray`].
    pub fn prepare(&self, bottom_radius_m: f64, width: usize, height: usize) -> PreparedCamera {
        let (forward, right, up) = match self.projection {
            Projection::Orbit => Camera {
                pitch_deg: -90.0,
                ..self.clone()
            }
            .basis(),
            _ => self.basis(),
        };
        PreparedCamera {
            camera: self.clone(),
            bottom_radius_m,
            width,
            height,
            forward,
            right,
            up,
            tan_half_fov: (self.fov_deg.to_radians() / 2.0).tan(),
        }
    }

    fn ray_all_round(
        &self,
        bottom_radius_m: f64,
        width: usize,
        height: usize,
        px: f64,
        py: f64,
    ) -> Option<Ray> {
        let origin = Vec3::new(0.0, 0.0, bottom_radius_m + self.altitude_m);
        // Normalised device coordinates, x right, y up, in [-1, 1].
        let (u, v) = (
            2.0 * px / width as f64 - 1.0,
            1.0 - 2.0 * py / height as f64,
        );
        let local = match self.projection {
            // Pinhole projections go through PreparedCamera::ray.
            Projection::Perspective | Projection::Orbit => {
                unreachable!("handled by PreparedCamera")
            }
            Projection::Fisheye => {
                // Square inscribed circle; zenith angle proportional to radius (equidistant).
                let aspect = width as f64 / height as f64;
                let (x, y) = if aspect >= 1.0 {
                    (u * aspect, v)
                } else {
                    (u, v / aspect)
                };
                let rho = (x * x + y * y).sqrt();
                if rho > 1.0 {
                    return None;
                }
                // Looking up with north at the top of the image: east is on the left, so
                // the azimuth θ has sin θ = −x/ρ, cos θ = y/ρ (no arctangent needed).
                let (sin_z, cos_z) = (rho * PI / 2.0).sin_cos();
                if rho > 0.0 {
                    turned(
                        Vec3::new(-x / rho * sin_z, y / rho * sin_z, cos_z),
                        self.heading_deg,
                    )
                } else {
                    Vec3::Z
                }
            }
            Projection::Equirect => {
                // Column: azimuth from −180° (south, left edge) through 0° (north, centre)
                // to 180°; row: elevation +90° (top) to −90° (bottom).
                let azimuth = u * PI + self.heading_deg.to_radians();
                let elevation = v * PI / 2.0;
                direction_from_zenith_azimuth(PI / 2.0 - elevation, azimuth)
            }
            Projection::Cubemap => {
                let face_w = width as f64 / 6.0;
                let face = ((px / face_w) as usize).min(5);
                let fu = 2.0 * (px - face as f64 * face_w) / face_w - 1.0;
                let fv = 1.0 - 2.0 * py / height as f64;
                cube_direction(face, fu, fv)
            }
        };
        Some(Ray {
            origin,
            dir: local.normalize_or_zero(),
        })
    }

    /// (forward, right, up) unit vectors of the view in the local frame.
    pub fn basis(&self) -> (Vec3, Vec3, Vec3) {
        let h = self.heading_deg.to_radians();
        let p = self.pitch_deg.to_radians();
        let forward = Vec3::new(h.sin() * p.cos(), h.cos() * p.cos(), p.sin());
        // Right is horizontal, clockwise from forward; degenerate at ±90° pitch, where the
        // heading gives the image's up direction instead.
        let right0 = Vec3::new(h.cos(), -h.sin(), 0.0);
        let up0 = right0.cross(forward);
        let r = self.roll_deg.to_radians();
        let right = right0 * r.cos() + -r.sin() * up0;
        let up = right.cross(forward);
        (forward, right.normalize_or_zero(), up.normalize_or_zero())
    }
}

/// A camera with its per-frame constants (view basis, field of view) computed once.
#[derive(Clone, Debug)]
pub struct PreparedCamera {
    camera: Camera,
    bottom_radius_m: f64,
    width: usize,
    height: usize,
    forward: Vec3,
    right: Vec3,
    up: Vec3,
    tan_half_fov: f64,
}

impl PreparedCamera {
    /// The view's (forward, right, up) unit vectors in the local frame, as the pinhole
    /// projections use them (the orbit camera's looks straight down).
    pub fn basis(&self) -> (Vec3, Vec3, Vec3) {
        (self.forward, self.right, self.up)
    }

    /// The projection.
    pub fn projection(&self) -> Projection {
        self.camera.projection
    }

    /// tan(fov/2) of the pinhole projections.
    pub fn tan_half_fov(&self) -> f64 {
        self.tan_half_fov
    }

    /// The ray through pixel position (px, py) (pixel centres at +0.5), None outside the
    /// projection.
    #[inline]
    pub fn ray(&self, px: f64, py: f64) -> Option<Ray> {
        match self.camera.projection {
            Projection::Perspective | Projection::Orbit => {
                let (w, h) = (self.width as f64, self.height as f64);
                let (u, v) = (2.0 * px / w - 1.0, 1.0 - 2.0 * py / h);
                let t = self.tan_half_fov;
                let d = self.forward + (u * t * w / h) * self.right + (v * t) * self.up;
                Some(Ray {
                    origin: Vec3::new(0.0, 0.0, self.bottom_radius_m + self.camera.altitude_m),
                    dir: d.normalize_or_zero(),
                })
            }
            _ => self
                .camera
                .ray_all_round(self.bottom_radius_m, self.width, self.height, px, py),
        }
    }
}

impl PreparedCamera {
    /// The camera's position and the angle (rad) between the rays of two neighbouring
    /// pixels at the image's centre: a pixel's angular width, for what is filtered over a
    /// pixel's footprint (the clouds' density seen from far away).
    pub fn pixel_footprint(&self) -> Option<(Vec3, f64)> {
        let (cx, cy) = (0.5 * self.width as f64, 0.5 * self.height as f64);
        let a = self.ray(cx, cy)?;
        let b = self.ray(cx + 1.0, cy)?;
        Some((a.origin, a.dir.dot(b.dir).clamp(-1.0, 1.0).acos()))
    }

    /// The continuous pixel position (pixel centres at +0.5) that sees direction `dir`
    /// (unit, local frame): the inverse of [`PreparedCamera::ray`]. None outside the image.
    pub fn pixel_of(&self, dir: Vec3) -> Option<(f64, f64)> {
        let (w, h) = (self.width as f64, self.height as f64);
        let (u, v) = match self.camera.projection {
            Projection::Perspective | Projection::Orbit => {
                let f = dir.dot(self.forward);
                if f <= 0.0 {
                    return None;
                }
                let t = self.tan_half_fov;
                (
                    dir.dot(self.right) / (f * t * w / h),
                    dir.dot(self.up) / (f * t),
                )
            }
            Projection::Fisheye => {
                let dir = turned(dir, -self.camera.heading_deg);
                let zenith = dir.z.clamp(-1.0, 1.0).acos();
                let rho = zenith / (PI / 2.0);
                if rho > 1.0 {
                    return None;
                }
                let s = zenith.sin();
                let (x, y) = if s > 0.0 {
                    (-rho * dir.x / s, rho * dir.y / s)
                } else {
                    (0.0, 0.0)
                };
                let aspect = w / h;
                if aspect >= 1.0 {
                    (x / aspect, y)
                } else {
                    (x, y * aspect)
                }
            }
            Projection::Equirect => {
                let dir = turned(dir, -self.camera.heading_deg);
                (
                    dir.x.atan2(dir.y) / PI,
                    dir.z.clamp(-1.0, 1.0).asin() / (PI / 2.0),
                )
            }
            Projection::Cubemap => {
                // The face of the major axis; cube_direction solved for (u, v).
                let a = dir.abs();
                let (face, fu, fv) = if a.x >= a.y && a.x >= a.z {
                    if dir.x > 0.0 {
                        (0, -dir.y / a.x, dir.z / a.x)
                    } else {
                        (1, dir.y / a.x, dir.z / a.x)
                    }
                } else if a.y >= a.z {
                    if dir.y > 0.0 {
                        (2, dir.x / a.y, dir.z / a.y)
                    } else {
                        (3, -dir.x / a.y, dir.z / a.y)
                    }
                } else if dir.z > 0.0 {
                    (4, -dir.x / a.z, dir.y / a.z)
                } else {
                    (5, dir.x / a.z, dir.y / a.z)
                };
                let face_w = w / 6.0;
                let px = face as f64 * face_w + (fu + 1.0) / 2.0 * face_w;
                return Some((px, (1.0 - fv) / 2.0 * h));
            }
        };
        if u.abs() > 1.0 || v.abs() > 1.0 {
            return None;
        }
        Some(((u + 1.0) / 2.0 * w, (1.0 - v) / 2.0 * h))
    }

    /// Solid angle (sr) seen by pixel (x, y), from the rays through its edges' midpoints.
    pub fn pixel_solid_angle(&self, x: usize, y: usize) -> f64 {
        let (cx, cy) = (x as f64 + 0.5, y as f64 + 0.5);
        let d = |px: f64, py: f64| self.ray(px, py).map(|r| r.dir);
        match (
            d(cx - 0.5, cy),
            d(cx + 0.5, cy),
            d(cx, cy - 0.5),
            d(cx, cy + 0.5),
        ) {
            (Some(l), Some(r), Some(t), Some(b)) => (r - l).cross(b - t).length(),
            _ => 0.0,
        }
    }
}

/// `v` turned clockwise (seen from above) by `heading_deg` about the zenith: its azimuth
/// grows by the heading. Exact at a zero heading.
fn turned(v: Vec3, heading_deg: f64) -> Vec3 {
    if heading_deg == 0.0 {
        return v;
    }
    let (s, c) = heading_deg.to_radians().sin_cos();
    // Azimuth θ has (x, y) = (sin θ, cos θ): sin(θ + h), cos(θ + h).
    Vec3::new(v.x * c + v.y * s, v.y * c - v.x * s, v.z)
}

/// Vertical field of view (degrees) that frames a sphere of `radius_m` seen from
/// `distance_m` from its centre with a 15 % margin (120° when the camera is too close).
pub fn orbit_fit_fov_deg(radius_m: f64, distance_m: f64) -> f64 {
    if radius_m >= distance_m * 0.99 {
        return 120.0;
    }
    (2.0 * (radius_m / distance_m).asin().to_degrees() * 1.15).min(120.0)
}

/// Direction of cube face `face` (+X, −X, +Y, −Y, +Z, −Z) at face coordinates (u right,
/// v up) in [-1, 1], as seen from the inside (x east, y north, z up): side faces have the
/// zenith at the top; the +Z and −Z faces have north at the top.
pub fn cube_direction(face: usize, u: f64, v: f64) -> Vec3 {
    match face {
        0 => Vec3::new(1.0, -u, v),  // +X east: right is south (−y)
        1 => Vec3::new(-1.0, u, v),  // −X west: right is north
        2 => Vec3::new(u, 1.0, v),   // +Y north: right is east
        3 => Vec3::new(-u, -1.0, v), // −Y south: right is west
        4 => Vec3::new(-u, v, 1.0),  // +Z up, north at the top: right is west
        _ => Vec3::new(u, v, -1.0),  // −Z down, north at the top: right is east
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pixel_of_inverts_ray_for_every_projection() {
        for (projection, w, h) in [
            (Projection::Perspective, 320, 200),
            (Projection::Fisheye, 256, 256),
            (Projection::Equirect, 400, 200),
            (Projection::Cubemap, 600, 100),
        ] {
            let camera = Camera {
                projection,
                altitude_m: 10.0,
                heading_deg: 30.0,
                pitch_deg: 10.0,
                roll_deg: 5.0,
                fov_deg: 60.0,
            };
            // (Unvalidated: the all-round projections ignore the pitch and roll.)
            let p = camera.prepare(6_360_000.0, w, h);
            for (px, py) in [(10.3, 20.7), (w as f64 * 0.6, h as f64 * 0.45), (5.5, 90.2)] {
                let Some(ray) = p.ray(px, py) else { continue };
                let (qx, qy) = p.pixel_of(ray.dir).unwrap();
                assert!(
                    (qx - px).abs() < 1e-6 && (qy - py).abs() < 1e-6,
                    "{projection:?}: ({px}, {py}) → ({qx}, {qy})"
                );
            }
        }
        // The heading turns the level all-round maps: at 90° the equirect's centre column
        // and the fisheye's top face east, and the equirect's three-quarter column south.
        let east = Vec3::X;
        for (projection, w, h, px, py, want) in [
            (Projection::Equirect, 400, 200, 200.0, 100.0, east),
            (Projection::Equirect, 400, 200, 300.0, 100.0, -Vec3::Y),
            (Projection::Fisheye, 200, 200, 100.0, 0.0, east),
        ] {
            let camera = Camera {
                projection,
                altitude_m: 0.0,
                heading_deg: 90.0,
                pitch_deg: 0.0,
                roll_deg: 0.0,
                fov_deg: 60.0,
            };
            let d = camera.prepare(6_360_000.0, w, h).ray(px, py).unwrap().dir;
            assert!((d - want).length() < 1e-9, "{projection:?}: {d:?}");
            camera.validate().unwrap();
            let tilted = Camera {
                pitch_deg: 10.0,
                ..camera
            };
            assert!(tilted.validate().is_err(), "{projection:?} refuses a pitch");
        }
        // A fisheye's pixels tile the upper hemisphere: their solid angles sum to 2π.
        let camera = Camera {
            projection: Projection::Fisheye,
            altitude_m: 0.0,
            heading_deg: 0.0,
            pitch_deg: 0.0,
            roll_deg: 0.0,
            fov_deg: 60.0,
        };
        let p = camera.prepare(6_360_000.0, 200, 200);
        let sum: f64 = (0..200)
            .flat_map(|y| (0..200).map(move |x| (x, y)))
            .map(|(x, y)| p.pixel_solid_angle(x, y))
            .sum();
        assert!((sum / (2.0 * PI) - 1.0).abs() < 0.02, "{sum}");
    }
}

//! The documented view set of `firmament validate` (see the module documentation of
//! [`super`]): directions above and below the horizon, rings around the sun, with the
//! views that carry no comparable light left out.

use firmament::atmosphere::Model;
use firmament::math::sphere::{horizon_mu, ray_sphere};
use firmament::math::{direction_from_zenith_azimuth, Vec3};

/// A view: its direction and where it points relative to the horizon and the sun.
#[derive(Clone, Copy, Debug)]
pub struct View {
    pub elevation_deg: f64,
    pub azimuth_from_sun_deg: f64,
    /// Angle from the sun's centre (degrees).
    pub sun_distance_deg: f64,
    pub dir: Vec3,
}

impl View {
    /// The view along `dir` with the sun in `sun` (at azimuth 0: north = +y, east = +x).
    fn new(dir: Vec3, sun: Vec3) -> View {
        let dir = dir.normalize_or_zero();
        let azimuth_deg = dir[0].atan2(dir[1]).to_degrees().abs();
        View {
            elevation_deg: dir[2].clamp(-1.0, 1.0).asin().to_degrees(),
            azimuth_from_sun_deg: if dir[0].hypot(dir[1]) < 1e-12 {
                0.0
            } else {
                azimuth_deg
            },
            sun_distance_deg: dir.dot(sun).clamp(-1.0, 1.0).acos().to_degrees(),
            dir,
        }
    }
}

/// The unit direction at an elevation above the horizon and an azimuth (degrees, clockwise
/// from north).
pub fn direction_from_elevation_deg(elevation_deg: f64, azimuth_deg: f64) -> Vec3 {
    direction_from_zenith_azimuth(
        (90.0 - elevation_deg).to_radians(),
        azimuth_deg.to_radians(),
    )
}

/// Elevation (degrees, negative) of the horizon of a sphere of `radius_m` seen from radius
/// `r_m`, when the observer is above it.
fn horizon_elevation_deg(r_m: f64, radius_m: f64) -> Option<f64> {
    (r_m > radius_m).then(|| horizon_mu(r_m, radius_m).asin().to_degrees())
}

/// The documented view set for an observer at `altitude_m` with the sun in `sun`, or the
/// reduced one of `--quick`; and how many views were left out (within 1° of the sun, below
/// the horizon from the ground, rays that miss the atmosphere).
pub fn views(model: &Model, altitude_m: f64, sun: Vec3, quick: bool) -> (Vec<View>, usize) {
    let r = model.bottom_radius_m + altitude_m;
    let camera = Vec3::new(0.0, 0.0, r);
    let mut dirs: Vec<Vec3> = Vec::new();
    let (above, azimuths, rings): (&[f64], &[f64], &[f64]) = if quick {
        (
            &[1.0, 3.0, 10.0, 30.0, 60.0],
            &[0.0, 60.0, 120.0, 180.0],
            &[3.0],
        )
    } else {
        (
            &[0.5, 1.0, 2.0, 4.0, 7.0, 10.0, 15.0, 25.0, 40.0, 60.0],
            &[0.0, 30.0, 60.0, 90.0, 135.0, 180.0],
            &[2.0, 4.0, 8.0],
        )
    };
    let mut elevations: Vec<f64> = above.to_vec();
    if altitude_m > 0.0 && quick {
        // Down towards the ground (the ground half of the tables), the horizon excluded.
        elevations.extend([-3.0, -30.0, -60.0]);
    }
    if altitude_m > 0.0 && !quick {
        let mut below = vec![-1.0, -3.0, -10.0, -30.0, -60.0];
        if let Some(ground) = horizon_elevation_deg(r, model.bottom_radius_m) {
            below.extend([
                ground + 0.5,
                ground + 0.1,
                ground - 0.1,
                ground - 0.5,
                ground - 2.0,
            ]);
            if let Some(limb) = horizon_elevation_deg(r, model.top_radius_m) {
                below.push(limb - 0.1);
                for f in [0.25, 0.5, 0.75] {
                    below.push(limb + f * (ground - limb));
                }
            }
        }
        below.retain(|&e| e < 0.0 && e > -89.0);
        elevations.extend(below);
    }
    for &e in &elevations {
        for &a in azimuths {
            dirs.push(direction_from_elevation_deg(e, a));
        }
    }
    dirs.push(Vec3::Z);
    if altitude_m > 0.0 && !quick {
        dirs.push(Vec3::NEG_Z);
    }
    // Rings around the sun: towards the zenith, sideways, towards the horizon.
    let towards_zenith = {
        let v = Vec3::Z - Vec3::Z.dot(sun) * sun;
        if v.dot(v) < 1e-12 {
            Vec3::Y
        } else {
            v.normalize()
        }
    };
    let sideways = sun.cross(towards_zenith);
    for &d in rings {
        let (s, c) = d.to_radians().sin_cos();
        for phi in [0.0f64, 90.0, 180.0] {
            let (sp, cp) = phi.to_radians().sin_cos();
            dirs.push((c * sun + s * (cp * towards_zenith + sp * sideways)).normalize());
        }
    }
    let mut skipped = 0;
    let mut kept: Vec<View> = Vec::new();
    for d in dirs {
        let v = View::new(d, sun);
        // Sun disk excluded; at the ground only views above the horizon; rays that miss
        // the atmosphere carry no light.
        let misses = !matches!(ray_sphere(camera, v.dir, model.top_radius_m), Some((_, far)) if far > 0.0)
            || (r >= model.top_radius_m && camera.dot(v.dir) >= 0.0);
        if v.sun_distance_deg < 1.0 || (altitude_m <= 0.0 && v.elevation_deg < 0.25) || misses {
            skipped += 1;
            continue;
        }
        kept.push(v);
    }
    (kept, skipped)
}

//! The camera under the mouse and the keyboard: look by dragging, fly with W/S (along the
//! view) and E/Q (straight up and down) at a speed that grows with altitude, so that one
//! key goes from 2 m above the ground to geostationary orbit in about half a minute, and
//! zoom with the wheel. The scene's camera has no horizontal position (the clear sky over a
//! sphere is the same everywhere but for the sun's angles), so a flight changes altitude.

use firmament::scene::Camera;

use super::state::MAX_ALTITUDE_M;

/// The lowest altitude (m).
pub const MIN_ALTITUDE_M: f64 = 2.0;
/// Speed per metre of altitude (1/s): the altitude doubles in ln 2 / 0.5 ≈ 1.4 s of E.
const SPEED_PER_ALTITUDE: f64 = 0.5;
/// The slowest speed (m/s), near the ground.
const MIN_SPEED_M_S: f64 = 5.0;
/// Shift's factor.
const FAST: f64 = 10.0;

/// The movement keys held during a frame.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Keys {
    pub forward: bool,
    pub back: bool,
    pub up: bool,
    pub down: bool,
    pub fast: bool,
}

/// The flying speed at `altitude_m` (m/s).
pub fn speed_m_s(altitude_m: f64, fast: bool) -> f64 {
    let v = (SPEED_PER_ALTITUDE * altitude_m).max(MIN_SPEED_M_S);
    if fast {
        v * FAST
    } else {
        v
    }
}

/// Fly for `dt_s` seconds: W/S along the view's vertical component, E/Q straight up or
/// down. Integrated in log-altitude for the altitude-proportional part, so that a long
/// frame does not overshoot. Returns whether the camera moved.
pub fn fly(camera: &mut Camera, keys: Keys, dt_s: f64) -> bool {
    let along = keys.forward as i32 - keys.back as i32;
    let vertical = keys.up as i32 - keys.down as i32;
    let climb = vertical as f64 + along as f64 * camera.pitch_deg.to_radians().sin();
    if climb == 0.0 || dt_s <= 0.0 {
        return false;
    }
    let h = camera.altitude_m;
    let v = speed_m_s(h, keys.fast);
    let next = if v > MIN_SPEED_M_S * if keys.fast { FAST } else { 1.0 } {
        // dh/dt = ±k·h: exact over the step.
        let k = SPEED_PER_ALTITUDE * if keys.fast { FAST } else { 1.0 };
        h * (k * climb * dt_s).exp()
    } else {
        h + v * climb * dt_s
    };
    camera.altitude_m = next.clamp(MIN_ALTITUDE_M, MAX_ALTITUDE_M);
    camera.altitude_m != h
}

/// Look by a mouse drag of (dx, dy) pixels in a view `height_px` tall: the scene follows the
/// pointer (one pixel turns the view by one pixel's angle).
pub fn look(camera: &mut Camera, dx: f64, dy: f64, height_px: f64) {
    let per_px = camera.fov_deg / height_px.max(1.0);
    camera.heading_deg = (camera.heading_deg - dx * per_px).rem_euclid(360.0);
    camera.pitch_deg = (camera.pitch_deg + dy * per_px).clamp(-89.0, 89.0);
}

/// Zoom by `steps` wheel steps (positive: narrower), 10 % each, within 5–120°.
pub fn zoom(camera: &mut Camera, steps: f64) {
    camera.fov_deg = (camera.fov_deg * 0.9f64.powf(steps)).clamp(5.0, 120.0);
}

#[cfg(test)]
mod tests {
    use super::*;
    use firmament::scene::Projection;

    fn camera() -> Camera {
        Camera {
            projection: Projection::Perspective,
            altitude_m: MIN_ALTITUDE_M,
            heading_deg: 250.0,
            pitch_deg: 0.0,
            roll_deg: 0.0,
            fov_deg: 60.0,
        }
    }

    #[test]
    fn one_key_flies_from_the_ground_to_geostationary_orbit_in_under_a_minute() {
        let mut c = camera();
        let up = Keys {
            up: true,
            ..Keys::default()
        };
        let mut t = 0.0;
        while c.altitude_m < MAX_ALTITUDE_M && t < 600.0 {
            fly(&mut c, up, 1.0 / 60.0);
            t += 1.0 / 60.0;
        }
        assert_eq!(c.altitude_m, MAX_ALTITUDE_M);
        assert!((20.0..60.0).contains(&t), "{t} s");
        // And back down, never below the floor.
        let down = Keys {
            down: true,
            fast: true,
            ..Keys::default()
        };
        for _ in 0..10_000 {
            fly(&mut c, down, 0.1);
        }
        assert_eq!(c.altitude_m, MIN_ALTITUDE_M);
    }

    #[test]
    fn flying_forward_climbs_only_when_looking_up() {
        let mut c = camera();
        c.altitude_m = 1000.0;
        let fwd = Keys {
            forward: true,
            ..Keys::default()
        };
        assert!(!fly(&mut c, fwd, 1.0));
        c.pitch_deg = 30.0;
        assert!(fly(&mut c, fwd, 0.1));
        // Half the vertical speed: 1000·e^(0.5·0.5·0.1).
        assert!((c.altitude_m - 1000.0 * (0.025f64).exp()).abs() < 1e-9);
    }

    #[test]
    fn dragging_turns_the_view_and_the_wheel_zooms() {
        let mut c = camera();
        look(&mut c, 100.0, -50.0, 600.0);
        assert!((c.heading_deg - 240.0).abs() < 1e-12);
        assert!((c.pitch_deg + 5.0).abs() < 1e-12);
        look(&mut c, 0.0, 1e6, 600.0);
        assert_eq!(c.pitch_deg, 89.0);
        zoom(&mut c, 1.0);
        assert!((c.fov_deg - 54.0).abs() < 1e-12);
        zoom(&mut c, -100.0);
        assert_eq!(c.fov_deg, 120.0);
    }
}

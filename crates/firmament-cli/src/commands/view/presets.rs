//! Camera and sun presets of the viewer: the gallery's kinds of view, from the valley floor
//! to orbit, one click each.

use super::state::ViewState;

/// A named view: the camera's altitude, heading, pitch and field of view, and the sun's
/// elevation and azimuth (kept when the scene has a date).
pub struct Preset {
    pub name: &'static str,
    altitude_m: f64,
    heading_deg: f64,
    pitch_deg: f64,
    fov_deg: f64,
    sun: (f64, f64),
}

/// The presets, in the panel's order.
pub const PRESETS: [Preset; 6] = [
    Preset {
        name: "noon",
        altitude_m: 2.0,
        heading_deg: 0.0,
        pitch_deg: 20.0,
        fov_deg: 75.0,
        sun: (60.0, 180.0),
    },
    Preset {
        name: "golden hour",
        altitude_m: 25.0,
        heading_deg: 250.0,
        pitch_deg: 6.0,
        fov_deg: 55.0,
        sun: (5.5, 237.0),
    },
    Preset {
        name: "sunset",
        altitude_m: 2.0,
        heading_deg: 270.0,
        pitch_deg: 8.0,
        fov_deg: 60.0,
        sun: (0.5, 270.0),
    },
    Preset {
        name: "blue hour",
        altitude_m: 2.0,
        heading_deg: 90.0,
        pitch_deg: 15.0,
        fov_deg: 75.0,
        sun: (-4.0, 270.0),
    },
    Preset {
        name: "100 km",
        altitude_m: 100_000.0,
        heading_deg: 270.0,
        pitch_deg: -8.0,
        fov_deg: 60.0,
        sun: (3.0, 270.0),
    },
    Preset {
        name: "orbit",
        altitude_m: 6_000_000.0,
        heading_deg: 0.0,
        pitch_deg: -89.0,
        fov_deg: 80.0,
        sun: (35.0, 120.0),
    },
];

impl Preset {
    /// Put the camera (and, without a date, the sun) where the preset says.
    pub fn apply(&self, state: &mut ViewState) {
        let c = &mut state.scene.camera;
        c.altitude_m = self.altitude_m;
        c.heading_deg = self.heading_deg;
        c.pitch_deg = self.pitch_deg;
        c.fov_deg = self.fov_deg;
        c.roll_deg = 0.0;
        c.projection = firmament::scene::Projection::Perspective;
        if !state.dated() {
            state.set_sun(self.sun.0, self.sun.1);
        }
    }
}

//! What the viewer shows: a scene file (camera, sun or date, atmosphere, exposure), the sky
//! method drawing it, and the viewer's own settings. Everything a panel changes lands in the
//! scene file, so that "save scene" writes what `firmament render` reproduces.

use anyhow::Result;
use firmament::astro::Instant;
use firmament::render::tonemap::ToneCurve;
use firmament::scene::SceneFile;

use crate::method::Method;

/// The methods the viewer draws with (on the GPU).
pub const VIEW_METHODS: [Method; 3] = [Method::Bruneton4d, Method::Hillaire2020, Method::Elek3d];

/// The presets offered in the panel.
pub const PRESETS: [&str; 5] = ["earth", "bruneton2008", "frostbite2016", "hazy", "mars"];

/// The highest camera altitude the viewer flies to (m): geostationary orbit.
pub const MAX_ALTITUDE_M: f64 = 35_786_000.0;

/// The viewer's state.
#[derive(Clone, Debug, PartialEq)]
pub struct ViewState {
    /// The scene as `firmament render` reads it.
    pub scene: SceneFile,
    /// The sky method drawing it.
    pub method: Method,
    /// The automatic exposure's adaptation time constant (s).
    pub adapt_tau_s: f64,
    /// The fraction of the window's size the sky is rendered at (the display upsamples).
    pub render_scale: f64,
    /// The clock runs (the date's time advances, or the sun moves along its azimuth).
    pub playing: bool,
    /// Simulated hours per real second while playing (24/60: a day in a minute).
    pub hours_per_second: f64,
}

impl ViewState {
    /// The viewer's state for a scene; the clear sky (terrain and clouds are drawn by
    /// `firmament render`, not yet by the viewer: the caller says so).
    pub fn new(scene: SceneFile, method: Method, software: bool) -> ViewState {
        ViewState {
            scene,
            method,
            adapt_tau_s: 0.5,
            // A software rasteriser draws a quarter of the pixels.
            render_scale: if software { 0.5 } else { 1.0 },
            playing: false,
            hours_per_second: 24.0 / 60.0,
        }
    }

    /// The sun's elevation (degrees above the horizon) when given by angles.
    pub fn sun_elevation_deg(&self) -> f64 {
        90.0 - self.scene.sun.zenith_deg
    }

    /// Set the sun by its angles (clamped to zenith 0–180°, azimuth wrapped to 0–360°).
    pub fn set_sun(&mut self, elevation_deg: f64, azimuth_deg: f64) {
        self.scene.sun.zenith_deg = (90.0 - elevation_deg).clamp(0.0, 180.0);
        self.scene.sun.azimuth_deg = azimuth_deg.rem_euclid(360.0);
    }

    /// Whether the sun comes from a date and a place.
    pub fn dated(&self) -> bool {
        self.scene.time.is_some() && self.scene.location.is_some()
    }

    /// Move the date by `hours` (refused when it leaves what the ephemerides accept).
    pub fn shift_time(&mut self, hours: f64) -> Result<()> {
        let Some(time) = self.scene.time.as_mut() else {
            return Ok(());
        };
        let at = Instant::parse(&time.at, "time.at")?;
        let utc = at.utc + chrono::Duration::milliseconds((hours * 3.6e6).round() as i64);
        let moved = Instant::from_utc(utc)?;
        time.at = moved.iso();
        Ok(())
    }

    /// Advance the clock by `dt_s` real seconds when playing: the date moves at
    /// `hours_per_second`, or, without a date, the sun turns about the zenith-free arc of
    /// an equatorial day (15° per hour along a great circle through east, zenith, west).
    pub fn tick(&mut self, dt_s: f64) -> Result<bool> {
        if !self.playing || dt_s <= 0.0 {
            return Ok(false);
        }
        let hours = dt_s * self.hours_per_second;
        if self.dated() {
            self.shift_time(hours)?;
        } else {
            // The hour angle of the sun on the equator at an equinox: elevation and
            // azimuth from one angle, the sun rising due east and setting due west.
            let h = self.hour_angle_deg() + 15.0 * hours;
            let (elevation, azimuth) = equatorial_sun(h);
            self.set_sun(elevation, azimuth);
        }
        Ok(true)
    }

    /// The hour angle (degrees, 0 at noon, negative in the morning) of the equinox sun at
    /// the equator with the current angles: the inverse of [`equatorial_sun`].
    fn hour_angle_deg(&self) -> f64 {
        let e = self.sun_elevation_deg().to_radians();
        let a = self.scene.sun.azimuth_deg.to_radians();
        // Direction (east, north, up) = (sin a cos e, cos a cos e, sin e); on the equinox
        // circle east = −sin H, up = cos H.
        let east = a.sin() * e.cos();
        (-east).atan2(e.sin()).to_degrees()
    }

    /// Apply a tone curve name from the panel.
    pub fn set_curve(&mut self, curve: ToneCurve) {
        self.scene.output.tonemap = curve;
    }

    /// The camera's altitude, clamped to [2 m, geostationary].
    pub fn set_altitude(&mut self, altitude_m: f64) {
        self.scene.camera.altitude_m = altitude_m.clamp(2.0, MAX_ALTITUDE_M);
    }

    /// The scene as TOML for "save scene": `firmament render --scene FILE` reproduces the
    /// view at any resolution (with `--method` as the panel says).
    pub fn scene_toml(&self, width: usize, height: usize) -> Result<String> {
        let mut scene = self.scene.clone();
        scene.image.width = width;
        scene.image.height = height;
        Ok(toml::to_string_pretty(&scene)?)
    }

    /// The command that renders the saved scene offline.
    pub fn render_command(&self, scene_path: &str) -> String {
        format!(
            "firmament render --scene {scene_path} --method {} --backend gpu",
            self.method.name()
        )
    }
}

/// The default scene's golden hour without its terrain: the clear sky, for tests.
#[cfg(test)]
pub fn clear_scene() -> SceneFile {
    SceneFile {
        terrain: None,
        ..SceneFile::default()
    }
}

/// The equinox sun at the equator for hour angle `h_deg`: (elevation, azimuth) in degrees.
pub fn equatorial_sun(h_deg: f64) -> (f64, f64) {
    let h = h_deg.to_radians();
    let (east, up) = (-h.sin(), h.cos());
    let elevation = up.clamp(-1.0, 1.0).asin().to_degrees();
    // Due east before noon, due west after (north = 0 on the equinox circle).
    let azimuth = if east >= 0.0 { 90.0 } else { 270.0 };
    (elevation, azimuth)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn state() -> ViewState {
        ViewState::new(clear_scene(), Method::Bruneton4d, true)
    }

    #[test]
    fn a_day_in_a_minute_moves_the_sun_by_its_hour_angle() {
        let mut s = state();
        s.set_sun(0.0, 90.0); // sunrise, due east
        s.playing = true;
        // 15 real seconds at 24 h a minute: 6 hours, from sunrise to noon.
        s.tick(15.0).unwrap();
        assert!(
            (s.sun_elevation_deg() - 90.0).abs() < 1e-6,
            "{}",
            s.sun_elevation_deg()
        );
        s.tick(7.5).unwrap();
        assert!((s.sun_elevation_deg() - 45.0).abs() < 1e-6);
        assert_eq!(s.scene.sun.azimuth_deg, 270.0);
        // Paused, nothing moves.
        s.playing = false;
        assert!(!s.tick(10.0).unwrap());
        assert!((s.sun_elevation_deg() - 45.0).abs() < 1e-6);
    }

    #[test]
    fn a_dated_scene_moves_its_clock() {
        let mut s = state();
        s.scene.location = Some(firmament::scene::file::SceneLocation {
            lat_deg: 45.0,
            lon_deg: 6.0,
            elevation_m: 0.0,
            pressure_hpa: 1013.25,
            temperature_c: 10.0,
        });
        s.scene.time = Some(firmament::scene::file::SceneTime {
            at: "2026-06-21T12:00:00Z".into(),
            moon_disk: true,
        });
        s.shift_time(-1.5).unwrap();
        assert!(s
            .scene
            .time
            .as_ref()
            .unwrap()
            .at
            .starts_with("2026-06-21T10:30:00"));
        s.playing = true;
        s.hours_per_second = 1.0;
        s.tick(2.0).unwrap();
        assert!(s
            .scene
            .time
            .as_ref()
            .unwrap()
            .at
            .starts_with("2026-06-21T12:30:00"));
    }

    #[test]
    fn the_saved_scene_reads_back_as_the_view() {
        let mut s = state();
        s.set_sun(12.5, 200.0);
        s.set_altitude(1.0e9);
        assert_eq!(s.scene.camera.altitude_m, MAX_ALTITUDE_M);
        s.scene.output.ev100 = Some(11.5);
        let text = s.scene_toml(3840, 2160).unwrap();
        let back: SceneFile = toml::from_str(&text).unwrap();
        assert_eq!(back.camera, s.scene.camera);
        assert_eq!(back.sun, s.scene.sun);
        assert_eq!(back.output.ev100, Some(11.5));
        assert_eq!((back.image.width, back.image.height), (3840, 2160));
        assert!(back.terrain.is_none());
    }
}

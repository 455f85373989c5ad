//! What the viewer shows: a scene file (camera, sun or date, atmosphere, exposure), the sky
//! method drawing it, and the viewer's own settings. Everything a panel changes lands in the
//! scene file, so that "save scene" writes what `firmament render` reproduces.

use anyhow::Result;
use firmament::astro::Instant;
use firmament::atmosphere::{Albedo, Atmosphere};
use firmament::render::tonemap::ToneCurve;
use firmament::scene::file::{SceneLocation, SceneTime};
use firmament::scene::SceneFile;

use super::progressive::Compare;
use crate::method::Method;

/// The methods the viewer draws with (on the GPU).
pub const VIEW_METHODS: [Method; 3] = [Method::Bruneton4d, Method::Hillaire2020, Method::Elek3d];

/// The presets offered in the panel.
pub const PRESETS: [&str; 5] = ["earth", "bruneton2008", "frostbite2016", "hazy", "mars"];

/// The highest camera altitude the viewer flies to (m): geostationary orbit.
pub const MAX_ALTITUDE_M: f64 = 35_786_000.0;
/// The viewer's step under clouds or over a terrain: a quarter of the pixels marched a
/// frame (a still view is the full frame after four).
pub const DEFAULT_MARCH_STEP: u32 = 2;

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
    /// Frames a new atmosphere's 4D tables are spread over on a software rasteriser
    /// (`AmortisedTables`), the previous tables drawn meanwhile.
    pub update_frames: usize,
    /// The reference path tracer beside the method's frame (or instead of it).
    pub compare: Compare,
    /// Under clouds or over a terrain, one pixel of each N×N block marched a frame, the
    /// others from the previous frames reprojected (`firmament_gpu::TemporalFrames`): 1, 2
    /// or 4.
    pub march_step: u32,
    /// [`ViewState::air_values`] of the atmosphere last asked (preset, file).
    air_cache: Option<(AirSource, Option<AirValues>)>,
}

/// A preset's name and an atmosphere file.
type AirSource = (String, Option<std::path::PathBuf>);

/// An atmosphere's own aerosol depth, ozone column, ground albedo and radius.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AirValues {
    /// Aerosol optical depth at 550 nm.
    pub aerosol_optical_depth: f64,
    /// Absorbers' column as ozone (DU).
    pub ozone_du: f64,
    /// Ground albedo (a table's mean).
    pub ground_albedo: f64,
    /// Planet radius (m).
    pub planet_radius_m: f64,
    /// The shell's thickness, top radius − planet radius (m).
    pub shell_m: f64,
}

impl AirValues {
    fn of(preset: &str, file: Option<&std::path::Path>) -> Option<AirValues> {
        let a = match file {
            Some(f) => Atmosphere::from_file(f).ok()?,
            None => Atmosphere::preset(preset).ok()?,
        };
        Some(AirValues {
            aerosol_optical_depth: a.aerosol_optical_depth().ok()?,
            ozone_du: a.ozone_du().ok()?,
            ground_albedo: match &a.ground_albedo {
                Albedo::Grey(v) => *v,
                Albedo::Table { values, .. } => {
                    values.iter().sum::<f64>() / values.len().max(1) as f64
                }
            },
            planet_radius_m: a.bottom_radius_m,
            shell_m: a.top_radius_m - a.bottom_radius_m,
        })
    }
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
            // A software rasteriser's frames take seconds: a few of them carry the update.
            update_frames: 8,
            air_cache: None,
            compare: Compare::Off,
            march_step: DEFAULT_MARCH_STEP,
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

    /// Turn the date and place on (at `now`, from Chamonix: the default valley is
    /// alpine) or off (the sun kept where the date put it, as angles).
    pub fn set_dated(&mut self, on: bool, now: chrono::DateTime<chrono::Utc>) -> Result<()> {
        if on == self.dated() {
            return Ok(());
        }
        if on {
            self.scene.location = Some(SceneLocation {
                lat_deg: 45.92,
                lon_deg: 6.87,
                elevation_m: 0.0,
                pressure_hpa: 1013.25,
                temperature_c: 10.0,
            });
            self.scene.time = Some(SceneTime {
                at: Instant::from_utc(now)?.iso(),
                moon_disk: true,
            });
        } else {
            let sun = self.scene.astro()?.map(|sky| sky.sun);
            self.scene.time = None;
            self.scene.location = None;
            if let Some(sun) = sun {
                self.scene.sun.zenith_deg = sun.zenith_deg.clamp(0.0, 180.0);
                self.scene.sun.azimuth_deg = sun.azimuth_deg;
            }
        }
        Ok(())
    }

    /// The local mean solar time (hours in [0, 24): UTC plus the longitude over 15°) of a
    /// dated scene.
    pub fn solar_hours(&self) -> Option<f64> {
        let (t, l) = (self.scene.time.as_ref()?, self.scene.location.as_ref()?);
        let at = Instant::parse(&t.at, "time.at").ok()?;
        let utc = at.utc.time();
        let h = chrono::Timelike::num_seconds_from_midnight(&utc) as f64 / 3600.0;
        Some((h + l.lon_deg / 15.0).rem_euclid(24.0))
    }

    /// Move a dated scene's clock to `hours` of local mean solar time on the same solar day.
    pub fn set_solar_hours(&mut self, hours: f64) -> Result<()> {
        if let Some(now) = self.solar_hours() {
            self.shift_time(hours.clamp(0.0, 24.0) - now)?;
        }
        Ok(())
    }

    /// Move a dated scene to the day `ymd` (YYYY-MM-DD), keeping the time of day (UTC).
    pub fn set_date(&mut self, ymd: &str) -> Result<()> {
        let Some(time) = self.scene.time.as_mut() else {
            return Ok(());
        };
        let day = chrono::NaiveDate::parse_from_str(ymd.trim(), "%Y-%m-%d").map_err(|e| {
            anyhow::anyhow!("invalid value for `date`: {ymd:?} ({e}; accepted: YYYY-MM-DD)")
        })?;
        let at = Instant::parse(&time.at, "time.at")?;
        let utc = day.and_time(at.utc.time()).and_utc();
        time.at = Instant::from_utc(utc)?.iso();
        Ok(())
    }

    /// The atmosphere's own values (before the adjustments) the panel's sliders start
    /// from; None when the atmosphere cannot be read (the error is shown when drawing).
    pub fn air_values(&mut self) -> Option<AirValues> {
        let a = &self.scene.atmosphere;
        let source = (a.preset.clone(), a.file.clone());
        if let Some((s, v)) = &self.air_cache {
            if *s == source {
                return *v;
            }
        }
        let values = AirValues::of(&source.0, source.1.as_deref());
        self.air_cache = Some((source, values));
        values
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
        let mut table = toml::Table::try_from(&scene)?;
        if self.dated() {
            // The date places the sun: a scene file gives either, and `[sun]` then says only
            // whether the disk is drawn.
            if let Some(sun) = table.get_mut("sun").and_then(|s| s.as_table_mut()) {
                sun.remove("zenith_deg");
                sun.remove("azimuth_deg");
            }
        }
        Ok(toml::to_string_pretty(&table)?)
    }

    /// The command that renders the saved scene offline.
    pub fn render_command(&self, scene_path: &str) -> String {
        format!(
            "firmament render --scene {scene_path} --method {} --backend gpu",
            self.method.name()
        )
    }
}

/// The default scene's golden hour without its terrain and clouds: the clear sky, for tests.
#[cfg(test)]
pub fn clear_scene() -> SceneFile {
    SceneFile {
        terrain: None,
        clouds: Vec::new(),
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

    #[test]
    fn a_date_and_place_turn_on_and_off_and_the_clock_follows_the_solar_time() {
        let mut s = state();
        let now = chrono::DateTime::parse_from_rfc3339("2026-06-21T09:00:00Z")
            .unwrap()
            .to_utc();
        s.set_dated(true, now).unwrap();
        assert!(s.dated());
        // 9:00 UTC at 6.87° E is 9:27.5 local mean solar time.
        let h = s.solar_hours().unwrap();
        assert!((h - (9.0 + 6.87 / 15.0)).abs() < 1e-6, "{h}");
        s.set_solar_hours(12.0).unwrap();
        assert!((s.solar_hours().unwrap() - 12.0).abs() < 1e-3);
        // Local noon at the solstice from 45.9° N: the sun due south, ~67.5° high.
        let sun = s.scene.astro().unwrap().unwrap().sun;
        assert!((sun.azimuth_deg - 180.0).abs() < 2.0, "{}", sun.azimuth_deg);
        assert!(
            (90.0 - sun.zenith_deg - 67.5).abs() < 0.5,
            "{}",
            sun.zenith_deg
        );
        s.set_date("2026-12-21").unwrap();
        assert!(s.scene.time.as_ref().unwrap().at.starts_with("2026-12-21T"));
        assert!((s.solar_hours().unwrap() - 12.0).abs() < 1e-3);
        assert!(s.set_date("2026-02-30").is_err());
        // Off: the sun stays where the date put it (the winter noon, ~20.7° high).
        s.set_dated(false, now).unwrap();
        assert!(!s.dated() && s.scene.location.is_none());
        assert!(
            (s.sun_elevation_deg() - 20.7).abs() < 0.5,
            "{}",
            s.sun_elevation_deg()
        );
    }

    #[test]
    fn a_dated_view_saves_a_scene_that_render_reads() {
        let mut s = state();
        let now = chrono::DateTime::parse_from_rfc3339("2026-03-20T17:00:00Z")
            .unwrap()
            .to_utc();
        s.set_dated(true, now).unwrap();
        s.scene.atmosphere.adjust.aerosol_optical_depth = Some(0.25);
        let dir = std::env::temp_dir().join(format!("firmament-view-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("dated.toml");
        std::fs::write(&path, s.scene_toml(640, 360).unwrap()).unwrap();
        let back = SceneFile::from_file(&path).unwrap();
        assert_eq!(back.time, s.scene.time);
        assert_eq!(back.location, s.scene.location);
        assert_eq!(back.atmosphere.adjust.aerosol_optical_depth, Some(0.25));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn the_sliders_start_from_the_atmospheres_own_values() {
        let mut s = state();
        let earth = s.air_values().unwrap();
        // Ångström β 0.04, α 1.3 at 550 nm; 300 DU; earth's radius.
        assert!((earth.aerosol_optical_depth - 0.04 * 0.55f64.powf(-1.3)).abs() < 1e-12);
        assert!((earth.ozone_du - 300.0).abs() < 1e-9);
        assert_eq!(earth.planet_radius_m, 6_360_000.0);
        s.scene.atmosphere.preset = "mars".into();
        let mars = s.air_values().unwrap();
        assert_eq!(mars.ozone_du, 0.0);
        assert!(mars.planet_radius_m < 4.0e6);
    }
}

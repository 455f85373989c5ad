//! `firmament astro`: where the sun and the moon are for a date and a place, and the day's
//! sunrise, sunset and twilights, as JSON; and the date-and-place flags that `render` and
//! `query` share.

use anyhow::Result;
use clap::Args;
use firmament::astro::{sun_events, Instant, Place, Sky, Weather};
use serde_json::json;

/// A date and a place: the sun, the moon and the sky's rotation follow from them.
#[derive(Args, Debug, Clone, Default)]
pub struct AstroArgs {
    /// Date and time, ISO 8601 with `Z` or an offset (e.g. 2026-06-21T16:30:00+02:00); the
    /// sun and the moon follow from it and the place (instead of the sun's angles).
    #[arg(long, value_name = "ISO8601", conflicts_with_all = ["sun_zenith_deg", "sun_azimuth_deg"])]
    pub time: Option<String>,
    /// Latitude of the place (degrees north, −90 to 90).
    #[arg(long, allow_hyphen_values = true)]
    pub lat_deg: Option<f64>,
    /// Longitude of the place (degrees east, −180 to 360).
    #[arg(long, allow_hyphen_values = true)]
    pub lon_deg: Option<f64>,
    /// Height of the place above the ellipsoid (m), for the parallax (the camera's
    /// altitude above the ground is separate).
    #[arg(long, allow_hyphen_values = true)]
    pub elevation_m: Option<f64>,
    #[arg(long, help = format!(
        "Surface pressure for refraction (hPa) [default: {}, ISO 2533 sea level]",
        Weather::default().pressure_hpa
    ))]
    pub pressure_hpa: Option<f64>,
    #[arg(long, allow_hyphen_values = true, help = format!(
        "Surface temperature for refraction (°C) [default: {}]",
        Weather::default().temperature_c
    ))]
    pub temperature_c: Option<f64>,
}

impl AstroArgs {
    /// Whether any place flag was given.
    fn any_place(&self) -> bool {
        self.lat_deg.is_some()
            || self.lon_deg.is_some()
            || self.elevation_m.is_some()
            || self.pressure_hpa.is_some()
            || self.temperature_c.is_some()
    }

    /// The instant, place and weather, when `--time` is given (then `--lat-deg` and
    /// `--lon-deg` are required).
    pub fn resolve(&self) -> Result<Option<(Instant, Place, Weather)>> {
        let Some(time) = &self.time else {
            if self.any_place() {
                anyhow::bail!(
                    "--lat-deg/--lon-deg/--elevation-m/--pressure-hpa/--temperature-c need --time"
                );
            }
            return Ok(None);
        };
        let instant = Instant::parse(time, "--time")?;
        let (Some(lat), Some(lon)) = (self.lat_deg, self.lon_deg) else {
            anyhow::bail!("--time needs the place: --lat-deg and --lon-deg");
        };
        let place = Place::new(lat, lon, self.elevation_m.unwrap_or(0.0))?;
        let standard = Weather::default();
        let weather = Weather::new(
            self.pressure_hpa.unwrap_or(standard.pressure_hpa),
            self.temperature_c.unwrap_or(standard.temperature_c),
        )?;
        Ok(Some((instant, place, weather)))
    }
}

/// Arguments of `firmament astro`.
#[derive(Args, Debug)]
pub struct AstroCommandArgs {
    /// Date and time, ISO 8601 with `Z` or an offset.
    #[arg(long, value_name = "ISO8601")]
    pub time: String,
    /// Latitude (degrees north, −90 to 90).
    #[arg(long, allow_hyphen_values = true)]
    pub lat_deg: f64,
    /// Longitude (degrees east, −180 to 360).
    #[arg(long, allow_hyphen_values = true)]
    pub lon_deg: f64,
    /// Height above the ellipsoid (m).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub elevation_m: f64,
    /// Surface pressure for refraction (hPa).
    #[arg(long, default_value_t = Weather::default().pressure_hpa)]
    pub pressure_hpa: f64,
    /// Surface temperature for refraction (°C).
    #[arg(long, default_value_t = Weather::default().temperature_c, allow_hyphen_values = true)]
    pub temperature_c: f64,
}

/// Run `firmament astro`: the JSON answer.
pub fn run(args: &AstroCommandArgs) -> Result<serde_json::Value> {
    let instant = Instant::parse(&args.time, "--time")?;
    let place = Place::new(args.lat_deg, args.lon_deg, args.elevation_m)?;
    let weather = Weather::new(args.pressure_hpa, args.temperature_c)?;
    let sky = Sky::at(instant, place, &weather)?;
    let (events, start, end) = sun_events(&instant, &place)?;
    let (s, m) = (&sky.sun, &sky.moon);
    Ok(json!({
        "time_utc": instant.iso(),
        "delta_t_s": instant.delta_t_s,
        "place": { "lat_deg": place.lat_deg, "lon_deg": place.lon_deg, "elevation_m": place.elevation_m },
        "weather": { "pressure_hpa": weather.pressure_hpa, "temperature_c": weather.temperature_c },
        "sun": {
            "zenith_deg": s.zenith_deg,
            "apparent_zenith_deg": s.apparent_zenith_deg,
            "azimuth_deg": s.azimuth_deg,
            "distance_au": s.distance_au,
        },
        "moon": {
            "zenith_deg": m.zenith_deg,
            "altitude_deg": 90.0 - m.zenith_deg,
            "apparent_zenith_deg": m.apparent_zenith_deg,
            "azimuth_deg": m.azimuth_deg,
            "distance_km": m.distance_km,
            "angular_radius_deg": m.angular_radius_deg,
            "phase_angle_deg": m.phase_angle_deg,
            "illuminated_fraction": m.illuminated_fraction,
            "bright_limb_angle_deg": m.bright_limb_angle_deg,
        },
        "events": events,
        "events_window_utc": [start.iso(), end.iso()],
        "notes": [
            "sun: NREL SPA (Reda & Andreas 2004) via the solar-positioning crate; moon: Meeus 1998 ch. 47 (ELP-2000/82 truncated), topocentric with the rigorous parallax",
            "zenith_deg and altitude_deg are geometric (no refraction); apparent_zenith_deg adds refraction (SPA eq. 42) from the pressure and temperature; azimuth clockwise from north",
            "events: the sun's centre crossing −0.8333° (sunrise/sunset, refraction and radius included), −6°, −12°, −18°, within the local solar day (events_window_utc: local mean midnight to midnight); null when it does not happen",
            "UTC is taken as UT1 (|UT1 − UTC| < 0.9 s); ΔT = TT − UT1 from Espenak & Meeus's polynomials",
        ],
    }))
}

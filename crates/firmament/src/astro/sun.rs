//! The sun: topocentric position by NREL's Solar Position Algorithm (Reda & Andreas 2004,
//! Solar Energy 76, 577–589: ±0.0003° for the years −2000 to 6000) as implemented by the
//! `solar-positioning` crate, and the day's sunrise, sunset and twilights from it.

use solar_positioning::time::JulianDate;
use solar_positioning::{Horizon, Location, RefractionCorrection, SolarEvents, SolarPositions};

use super::time::Instant;
use super::{Place, Weather};
use crate::{Error, Result};

/// The astronomical unit (m), IAU 2012 resolution B2.
pub const ASTRONOMICAL_UNIT_M: f64 = 149_597_870_700.0;

/// Where the sun is, seen from a place at an instant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SunPosition {
    /// Topocentric zenith angle, no refraction (degrees).
    pub zenith_deg: f64,
    /// With the atmosphere's refraction (SPA eq. 42, from `Weather`) (degrees).
    pub apparent_zenith_deg: f64,
    /// Azimuth, clockwise from north (degrees, [0, 360)).
    pub azimuth_deg: f64,
    /// Earth–sun distance (AU).
    pub distance_au: f64,
    /// Geocentric apparent right ascension and declination of date (degrees).
    pub ra_deg: f64,
    /// See `ra_deg`.
    pub dec_deg: f64,
}

fn spa_error(e: solar_positioning::Error) -> Error {
    Error::invalid("time/place", e.to_string(), "inputs the SPA accepts")
}

fn julian(instant: &Instant) -> Result<JulianDate> {
    JulianDate::new(instant.julian_day_ut(), instant.delta_t_s).map_err(spa_error)
}

fn location(place: &Place) -> Location {
    Location {
        latitude: place.lat_deg,
        longitude: place.lon_east_deg(),
    }
}

/// The sun seen from `place` at `instant`.
pub fn sun_position(instant: &Instant, place: &Place, weather: &Weather) -> Result<SunPosition> {
    let jd = julian(instant)?;
    let spa = SolarPositions::new();
    let loc = location(place);
    let geometric = spa
        .at_from_julian(jd, loc, place.elevation_m, None)
        .map_err(spa_error)?;
    let refraction = RefractionCorrection::new(weather.pressure_hpa, weather.temperature_c)
        .map_err(spa_error)?;
    let apparent = spa
        .at_from_julian(jd, loc, place.elevation_m, Some(refraction))
        .map_err(spa_error)?;
    let (ra_deg, dec_deg, distance_au) = geocentric_equatorial(instant.centuries_tt());
    Ok(SunPosition {
        zenith_deg: geometric.zenith_angle(),
        apparent_zenith_deg: apparent.zenith_angle(),
        azimuth_deg: geometric.azimuth(),
        distance_au,
        ra_deg,
        dec_deg,
    })
}

/// The sun's geocentric apparent right ascension, declination (degrees, of date) and
/// distance (AU) at `t` Julian centuries TT from J2000.0, by Meeus's low-accuracy theory
/// (1998, ch. 25: 0.01°), enough for the moon's phase and bright limb (the SPA above gives
/// the sun's own position).
pub fn geocentric_equatorial(t: f64) -> (f64, f64, f64) {
    // Meeus eq. 25.2–25.5: mean longitude, mean anomaly, eccentricity, equation of centre.
    let l0 = 280.466_46 + t * (36_000.769_83 + t * 0.000_303_2);
    let m = (357.529_11 + t * (35_999.050_29 - t * 0.000_153_7)).to_radians();
    let e = 0.016_708_634 - t * (0.000_042_037 + t * 0.000_000_126_7);
    let c = (1.914_602 - t * (0.004_817 + t * 0.000_014)) * m.sin()
        + (0.019_993 - t * 0.000_101) * (2.0 * m).sin()
        + 0.000_289 * (3.0 * m).sin();
    let nu = m + c.to_radians();
    let r = 1.000_001_018 * (1.0 - e * e) / (1.0 + e * nu.cos());
    // Apparent longitude (eq. 25.8–25.9): aberration and nutation.
    let omega = (125.04 - 1934.136 * t).to_radians();
    let lambda = l0 + c - 0.005_69 - 0.004_78 * omega.sin();
    let eps = super::coordinates::mean_obliquity(t) + 0.002_56 * omega.cos();
    let (ra, dec) = super::coordinates::ecliptic_to_equatorial(lambda, 0.0, eps);
    (ra, dec, r)
}

/// The sun's horizon crossings within one window of time (ISO 8601 UTC), None where the
/// crossing does not happen in it (midnight sun, polar night).
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct SunEvents {
    /// Upper limb on the refracted horizon (centre at −0.8333°), rising.
    pub sunrise: Option<String>,
    /// The same, setting.
    pub sunset: Option<String>,
    /// Centre at −6°, rising and setting.
    pub civil_dawn: Option<String>,
    /// See `civil_dawn`.
    pub civil_dusk: Option<String>,
    /// Centre at −12°.
    pub nautical_dawn: Option<String>,
    /// See `nautical_dawn`.
    pub nautical_dusk: Option<String>,
    /// Centre at −18°.
    pub astronomical_dawn: Option<String>,
    /// See `astronomical_dawn`.
    pub astronomical_dusk: Option<String>,
}

/// The events of the local solar day around `instant` at `place`: the 24 hours from local
/// mean midnight (UTC midnight of the instant's local date minus longitude/15°·h), so the
/// day's own dawn and dusk fall in it wherever the place is.
pub fn sun_events(instant: &Instant, place: &Place) -> Result<(SunEvents, Instant, Instant)> {
    let shift_days = place.lon_east_deg() / 360.0;
    let local = instant.julian_day_ut() + shift_days;
    let start = (local - 0.5).floor() + 0.5 - shift_days;
    let end = start + 1.0;
    let loc = location(place);
    let solar = SolarEvents::new();
    let crossing = |horizon: Horizon, rising: bool| -> Result<Option<String>> {
        let jd = if rising {
            solar.next_rise_from_julian(start, end, loc, instant.delta_t_s, horizon)
        } else {
            solar.next_set_from_julian(start, end, loc, instant.delta_t_s, horizon)
        }
        .map_err(spa_error)?;
        Ok(jd.map(|jd| instant.at_julian_day(jd).iso()))
    };
    let events = SunEvents {
        sunrise: crossing(Horizon::SunriseSunset, true)?,
        sunset: crossing(Horizon::SunriseSunset, false)?,
        civil_dawn: crossing(Horizon::CivilTwilight, true)?,
        civil_dusk: crossing(Horizon::CivilTwilight, false)?,
        nautical_dawn: crossing(Horizon::NauticalTwilight, true)?,
        nautical_dusk: crossing(Horizon::NauticalTwilight, false)?,
        astronomical_dawn: crossing(Horizon::AstronomicalTwilight, true)?,
        astronomical_dusk: crossing(Horizon::AstronomicalTwilight, false)?,
    };
    Ok((
        events,
        instant.at_julian_day(start),
        instant.at_julian_day(end),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spa_paper_example() {
        // Reda & Andreas 2004, Table A5.1: 2003-10-17 12:30:30 at −7 h, 39.742476°N,
        // 105.1786°W, 1830.14 m, 820 mbar, 11 °C, ΔT = 67 s: topocentric zenith 50.11162°,
        // azimuth 194.34024° (with the paper's refraction).
        let t = Instant::with_delta_t("2003-10-17T19:30:30Z".parse().unwrap(), 67.0);
        let place = Place {
            lat_deg: 39.742_476,
            lon_deg: -105.1786,
            elevation_m: 1830.14,
        };
        let weather = Weather {
            pressure_hpa: 820.0,
            temperature_c: 11.0,
        };
        let s = sun_position(&t, &place, &weather).unwrap();
        assert!((s.apparent_zenith_deg - 50.111_62).abs() < 1e-4, "{s:?}");
        assert!((s.azimuth_deg - 194.340_24).abs() < 1e-4, "{s:?}");
        assert!(s.zenith_deg > s.apparent_zenith_deg);
    }

    #[test]
    fn low_accuracy_sun_of_meeus_example_25a() {
        // 1992 October 13, 0h TD: α = 198.38083°, δ = −7.78507°, R = 0.99766 AU.
        let t = (2_448_908.5 - super::super::time::J2000_JD) / 36_525.0;
        let (ra, dec, r) = geocentric_equatorial(t);
        assert!((ra - 198.380_83).abs() < 2e-4 && (dec + 7.785_07).abs() < 2e-4);
        assert!((r - 0.997_66).abs() < 1e-5);
    }
}

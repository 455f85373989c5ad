//! Astronomy: where the sun and the moon are for a date and a place ([`sun`], [`moon`]),
//! the coordinates between them ([`coordinates`]) and the instants ([`time`]).
//!
//! Positions are topocentric (seen from the place, parallax included) in the local
//! horizontal frame the scene uses: zenith angle from the vertical, azimuth clockwise from
//! north. Geometric positions have no refraction; the apparent ones add it from the
//! [`Weather`].

pub mod coordinates;
pub mod moon;
pub mod photometry;
pub mod stars;
pub mod sun;
pub mod time;

pub use moon::{moon_position, MoonPosition};
pub use sun::{sun_events, sun_position, SunEvents, SunPosition};
pub use time::Instant;

use crate::math::{direction_from_zenith_azimuth, Vec3};
use crate::{Error, Result};

/// A place on the Earth.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Place {
    /// Geodetic latitude (degrees, north positive, [−90, 90]).
    pub lat_deg: f64,
    /// Longitude (degrees, east positive, [−180, 360)).
    pub lon_deg: f64,
    /// Height above the WGS 84 ellipsoid (m).
    pub elevation_m: f64,
}

impl Place {
    /// Checks the ranges; errors name the flag (`--lat-deg`, `--lon-deg`, `--elevation-m`).
    pub fn new(lat_deg: f64, lon_deg: f64, elevation_m: f64) -> Result<Place> {
        if !(-90.0..=90.0).contains(&lat_deg) {
            return Err(Error::invalid(
                "--lat-deg",
                lat_deg,
                "between −90 and 90 degrees",
            ));
        }
        if !(-180.0..360.0).contains(&lon_deg) {
            return Err(Error::invalid(
                "--lon-deg",
                lon_deg,
                "between −180 (inclusive) and 360 (exclusive) degrees, east positive",
            ));
        }
        if !(-500.0..=100_000.0).contains(&elevation_m) {
            return Err(Error::invalid(
                "--elevation-m",
                elevation_m,
                "between −500 and 100000 m",
            ));
        }
        Ok(Place {
            lat_deg,
            lon_deg,
            elevation_m,
        })
    }

    /// Longitude in [−180, 180) (degrees east).
    pub fn lon_east_deg(&self) -> f64 {
        if self.lon_deg >= 180.0 {
            self.lon_deg - 360.0
        } else {
            self.lon_deg
        }
    }
}

/// The air at the place, for refraction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Weather {
    /// Surface pressure (hPa).
    pub pressure_hpa: f64,
    /// Surface temperature (°C).
    pub temperature_c: f64,
}

impl Default for Weather {
    /// The standard atmosphere at sea level: 1013.25 hPa, 15 °C (ISO 2533).
    fn default() -> Self {
        Weather {
            pressure_hpa: 1013.25,
            temperature_c: 15.0,
        }
    }
}

impl Weather {
    /// Checks the ranges; errors name the flags.
    pub fn new(pressure_hpa: f64, temperature_c: f64) -> Result<Weather> {
        if !(pressure_hpa > 0.0 && pressure_hpa <= 2000.0) {
            return Err(Error::invalid(
                "--pressure-hpa",
                pressure_hpa,
                "above 0 and at most 2000 hPa",
            ));
        }
        if !(temperature_c > -273.15 && temperature_c <= 100.0) {
            return Err(Error::invalid(
                "--temperature-c",
                temperature_c,
                "above −273.15 and at most 100 °C",
            ));
        }
        Ok(Weather {
            pressure_hpa,
            temperature_c,
        })
    }
}

/// Refraction (degrees) lifting a body at true altitude `altitude_deg`: SPA's formula
/// (Reda & Andreas 2004, eq. 42: Sæmundsson 1986 scaled by pressure and temperature), the
/// one the sun's apparent position uses, so the moon's follows the same law; none below
/// −0.83337° (the SPA's cut-off, the sun's upper limb on the horizon).
pub fn refraction_deg(altitude_deg: f64, weather: &Weather) -> f64 {
    if altitude_deg <= -0.833_37 {
        return 0.0;
    }
    let phase = (altitude_deg + 10.3 / (altitude_deg + 5.11)).to_radians();
    (weather.pressure_hpa / 1010.0) * (283.0 / (273.0 + weather.temperature_c)) * 1.02
        / (60.0 * phase.tan())
}

/// The sun and the moon for one instant and place.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sky {
    /// The instant.
    pub instant: Instant,
    /// The place.
    pub place: Place,
    /// The air, for refraction.
    pub weather: Weather,
    /// The sun.
    pub sun: SunPosition,
    /// The moon.
    pub moon: MoonPosition,
}

impl Sky {
    /// Both bodies at `instant` from `place`.
    pub fn at(instant: Instant, place: Place, weather: &Weather) -> Result<Sky> {
        let sun = sun_position(&instant, &place, weather)?;
        let moon = moon_position(&instant, &place, weather, &sun);
        Ok(Sky {
            instant,
            place,
            weather: *weather,
            sun,
            moon,
        })
    }

    /// Unit vector to the sun's apparent (refracted) centre in the scene's local frame
    /// (x east, y north, z up): what a camera there sees.
    pub fn sun_direction(&self) -> Vec3 {
        local_direction(self.sun.apparent_zenith_deg, self.sun.azimuth_deg)
    }

    /// Unit vector to the moon's apparent centre in the local frame.
    pub fn moon_direction(&self) -> Vec3 {
        local_direction(self.moon.apparent_zenith_deg, self.moon.azimuth_deg)
    }
}

/// Unit vector in the local frame (x east, y north, z up) from a zenith angle and an
/// azimuth clockwise from north (degrees).
pub fn local_direction(zenith_deg: f64, azimuth_deg: f64) -> Vec3 {
    direction_from_zenith_azimuth(zenith_deg.to_radians(), azimuth_deg.to_radians())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn places_are_checked_with_the_flag_named() {
        assert!(Place::new(91.0, 0.0, 0.0)
            .unwrap_err()
            .to_string()
            .contains("--lat-deg"));
        assert!(Place::new(0.0, 360.0, 0.0)
            .unwrap_err()
            .to_string()
            .contains("--lon-deg"));
        let p = Place::new(0.0, 350.0, 0.0).unwrap();
        assert_eq!(p.lon_east_deg(), -10.0);
        assert!(Weather::new(0.0, 15.0).is_err());
        // Refraction at the horizon is about 0.5°, at 45° about 1′ (Sæmundsson).
        let w = Weather::default();
        assert!((refraction_deg(0.0, &w) - 0.48).abs() < 0.05);
        assert!((refraction_deg(45.0, &w) * 60.0 - 1.0).abs() < 0.1);
    }
}

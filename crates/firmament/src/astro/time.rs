//! Instants: UTC from ISO 8601 text, Julian days in Universal and Terrestrial Time.
//!
//! UTC stands in for UT1 (they differ by less than 0.9 s, IERS; a 0.9 s error moves the sun
//! by 0.004° and the moon by 0.0001° on its orbit, far below what rendering needs and
//! within what `astro`'s tests allow). ΔT = TT − UT1 is estimated from the date with the
//! polynomials of Espenak & Meeus (2006, NASA/TP-2006-214141; Espenak's 2014 update and later
//! IERS fits), as implemented by the `solar-positioning` crate, or given explicitly.

use chrono::{DateTime, Datelike, FixedOffset, SecondsFormat, TimeZone, Utc};

use crate::{Error, Result};

/// Julian day of the Unix epoch, 1970-01-01T00:00:00 UTC (Meeus 1998, ch. 7).
const UNIX_EPOCH_JD: f64 = 2_440_587.5;
/// J2000.0 = 2000-01-01T12:00:00 TT as a Julian day (IAU 1976).
pub const J2000_JD: f64 = 2_451_545.0;
/// Seconds per day.
pub const SECONDS_PER_DAY: f64 = 86_400.0;

/// A moment in time: its UTC and the ΔT used for dynamical time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Instant {
    /// The moment (UTC).
    pub utc: DateTime<Utc>,
    /// ΔT = TT − UT1 (s).
    pub delta_t_s: f64,
}

impl Instant {
    /// Parses ISO 8601 / RFC 3339 with `Z` or an offset (`2026-06-21T16:30:00+02:00`); a
    /// time without a zone is refused (it would be ambiguous). `field` names the input in
    /// the error. ΔT is estimated from the date.
    pub fn parse(text: &str, field: &str) -> Result<Instant> {
        let t: DateTime<FixedOffset> = DateTime::parse_from_rfc3339(text.trim()).map_err(|e| {
            Error::invalid(
                field,
                text,
                format!(
                    "an ISO 8601 date and time with `Z` or an offset, such as \
                         2026-06-21T16:30:00Z or 2026-06-21T16:30:00+02:00 ({e})"
                ),
            )
        })?;
        Instant::from_utc(t.with_timezone(&Utc))
    }

    /// `utc` with ΔT estimated from its date (years −500 to 3000).
    pub fn from_utc(utc: DateTime<Utc>) -> Result<Instant> {
        let year = utc.year() as f64 + (utc.ordinal0() as f64 + 0.5) / 365.25;
        let delta_t_s = solar_positioning::delta_t::estimate(year).map_err(|_| {
            Error::invalid(
                "time",
                utc.to_rfc3339(),
                "a date between the years −500 and 3000 (ΔT estimate)",
            )
        })?;
        Ok(Instant { utc, delta_t_s })
    }

    /// `utc` with an explicit ΔT (s).
    pub fn with_delta_t(utc: DateTime<Utc>, delta_t_s: f64) -> Instant {
        Instant { utc, delta_t_s }
    }

    /// The instant at Julian day `jd_ut` (UT), with this instant's ΔT.
    pub fn at_julian_day(&self, jd_ut: f64) -> Instant {
        // To the millisecond: a Julian day near 2.46·10⁶ holds about 40 µs.
        let ms = ((jd_ut - UNIX_EPOCH_JD) * SECONDS_PER_DAY * 1000.0).round() as i64;
        let utc = Utc.timestamp_millis_opt(ms).single().unwrap_or(self.utc);
        Instant {
            utc,
            delta_t_s: self.delta_t_s,
        }
    }

    /// Julian day, Universal Time (Meeus 1998, ch. 7, from the Unix time scale).
    pub fn julian_day_ut(&self) -> f64 {
        let t = self.utc.timestamp() as f64 + self.utc.timestamp_subsec_nanos() as f64 * 1e-9;
        UNIX_EPOCH_JD + t / SECONDS_PER_DAY
    }

    /// Julian ephemeris day, Terrestrial Time: JD_UT + ΔT.
    pub fn julian_day_tt(&self) -> f64 {
        self.julian_day_ut() + self.delta_t_s / SECONDS_PER_DAY
    }

    /// Julian centuries of TT from J2000.0 (Meeus eq. 22.1).
    pub fn centuries_tt(&self) -> f64 {
        (self.julian_day_tt() - J2000_JD) / 36_525.0
    }

    /// ISO 8601 in UTC with a `Z`, to the second.
    pub fn iso(&self) -> String {
        self.utc.to_rfc3339_opts(SecondsFormat::Secs, true)
    }
}

/// A step of a duration written `30s`, `10m`, `1h` or `2d` (seconds).
pub fn parse_duration_s(text: &str, field: &str) -> Result<f64> {
    let t = text.trim();
    let bad = || {
        Error::invalid(
            field,
            text,
            "a positive number followed by s, m, h or d (e.g. 10m)",
        )
    };
    let (number, unit) = t.split_at(t.len().saturating_sub(1));
    let scale = match unit {
        "s" => 1.0,
        "m" => 60.0,
        "h" => 3600.0,
        "d" => SECONDS_PER_DAY,
        _ => return Err(bad()),
    };
    let v: f64 = number.parse().map_err(|_| bad())?;
    if !(v.is_finite() && v > 0.0) {
        return Err(bad());
    }
    Ok(v * scale)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn julian_days_of_known_dates() {
        // Meeus 1998, example 7.a: 1957 October 4.81 = JD 2436116.31.
        let t = Instant::parse("1957-10-04T19:26:24Z", "time").unwrap();
        assert!((t.julian_day_ut() - 2_436_116.31).abs() < 1e-6);
        // J2000.0 in UT (12:00 UTC on 2000-01-01).
        let t = Instant::parse("2000-01-01T12:00:00Z", "time").unwrap();
        assert!((t.julian_day_ut() - J2000_JD).abs() < 1e-9);
        // ΔT near 2000 is 63.8 s (Espenak & Meeus 2006).
        assert!((t.delta_t_s - 63.8).abs() < 0.5, "{}", t.delta_t_s);
    }

    #[test]
    fn offsets_are_honoured_and_naive_times_refused() {
        let a = Instant::parse("2026-06-21T16:30:00+02:00", "time").unwrap();
        let b = Instant::parse("2026-06-21T14:30:00Z", "time").unwrap();
        assert_eq!(a.utc, b.utc);
        let e = Instant::parse("2026-06-21T16:30:00", "time")
            .unwrap_err()
            .to_string();
        assert!(e.contains("`time`") && e.contains("offset"), "{e}");
        assert!(Instant::parse("21 June", "time").is_err());
        let back = b.at_julian_day(b.julian_day_ut());
        assert_eq!(back.iso(), "2026-06-21T14:30:00Z");
    }

    #[test]
    fn durations() {
        assert_eq!(parse_duration_s("10m", "every").unwrap(), 600.0);
        assert_eq!(parse_duration_s("1.5h", "every").unwrap(), 5400.0);
        assert!(parse_duration_s("-1m", "every").is_err());
        assert!(parse_duration_s("10", "every").is_err());
    }
}

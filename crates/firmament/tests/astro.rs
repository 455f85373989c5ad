//! Sun and moon positions against independent computations generated offline by
//! `tools/gen_astro_cases.py`: NREL SPA as implemented by pvlib (sun), JPL DE421 through
//! skyfield (moon, twilight times).

use std::collections::HashMap;

use chrono::{DateTime, Duration, Utc};
use firmament::astro::{moon_position, sun_events, sun_position, Instant, Place, Weather};

/// Rows of a test CSV as maps from column name to text.
fn rows(text: &str) -> Vec<HashMap<String, String>> {
    let mut lines = text
        .lines()
        .filter(|l| !l.starts_with('#') && !l.is_empty());
    let header: Vec<String> = lines
        .next()
        .unwrap()
        .split(',')
        .map(str::to_string)
        .collect();
    lines
        .map(|l| {
            header
                .iter()
                .cloned()
                .zip(l.split(',').map(str::to_string))
                .collect()
        })
        .collect()
}

fn num(row: &HashMap<String, String>, key: &str) -> f64 {
    row[key]
        .parse()
        .unwrap_or_else(|_| panic!("{key}: {}", row[key]))
}

fn time(row: &HashMap<String, String>, key: &str) -> DateTime<Utc> {
    row[key].parse().unwrap()
}

/// Angle difference in degrees, wrapped to [−180, 180].
fn angle_diff(a: f64, b: f64) -> f64 {
    (a - b + 540.0).rem_euclid(360.0) - 180.0
}

#[test]
fn sun_matches_spa_cases_to_a_thousandth_of_a_degree() {
    let cases = rows(include_str!("data/astro/sun_spa.csv"));
    assert!(cases.len() >= 21, "{} cases", cases.len());
    let mut worst = (0.0f64, 0.0f64, 0.0f64);
    for c in &cases {
        let instant = Instant::with_delta_t(time(c, "time_utc"), num(c, "delta_t_s"));
        let place =
            Place::new(num(c, "lat_deg"), num(c, "lon_deg"), num(c, "elevation_m")).unwrap();
        let weather = Weather::new(num(c, "pressure_hpa"), num(c, "temperature_c")).unwrap();
        let s = sun_position(&instant, &place, &weather).unwrap();
        let dz = (s.zenith_deg - num(c, "zenith_deg")).abs();
        let dza = (s.apparent_zenith_deg - num(c, "apparent_zenith_deg")).abs();
        // The azimuth is undefined at the poles' zenith; none of the cases is there.
        let da = angle_diff(s.azimuth_deg, num(c, "azimuth_deg")).abs();
        worst = (worst.0.max(dz), worst.1.max(dza), worst.2.max(da));
        assert!(
            dz < 1e-3 && dza < 1e-3 && da < 1e-3,
            "{}: Δzenith {dz:.2e}, Δapparent {dza:.2e}, Δazimuth {da:.2e}",
            c["time_utc"]
        );
    }
    eprintln!(
        "sun, worst |Δ| (deg): zenith {:.1e}, apparent {:.1e}, azimuth {:.1e}",
        worst.0, worst.1, worst.2
    );
}

#[test]
fn moon_matches_the_jpl_ephemeris() {
    let cases = rows(include_str!("data/astro/moon.csv"));
    assert!(cases.len() >= 20, "{} cases", cases.len());
    let (mut worst_alt, mut worst_az, mut worst_k, mut worst_d, mut worst_limb) =
        (0.0f64, 0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for c in &cases {
        // Our instants treat their clock as UT1: give it UT1 and the ephemeris's ΔT.
        let ut1 = time(c, "time_utc")
            + Duration::microseconds((num(c, "ut1_minus_utc_s") * 1e6).round() as i64);
        let instant = Instant::with_delta_t(ut1, num(c, "delta_t_s"));
        let place =
            Place::new(num(c, "lat_deg"), num(c, "lon_deg"), num(c, "elevation_m")).unwrap();
        let weather = Weather::default();
        let sun = sun_position(&instant, &place, &weather).unwrap();
        let m = moon_position(&instant, &place, &weather, &sun);
        let d_alt = ((90.0 - m.zenith_deg) - num(c, "altitude_deg")).abs();
        // Azimuth differences shrink by cos(altitude) on the sky.
        let d_az = angle_diff(m.azimuth_deg, num(c, "azimuth_deg")).abs()
            * num(c, "altitude_deg").to_radians().cos();
        let d_k = (m.illuminated_fraction - num(c, "illuminated_fraction")).abs();
        // Instantaneous distances (the ephemeris's light-time corrected ones differ by up to
        // ~40 km: the moon moved back along the barycentric frame).
        let d_dist = (m.distance_km - num(c, "geometric_distance_km")).abs();
        worst_alt = worst_alt.max(d_alt);
        worst_az = worst_az.max(d_az);
        worst_k = worst_k.max(d_k);
        worst_d = worst_d.max(d_dist);
        assert!(
            d_alt < 0.05 && d_az < 0.05 && d_k < 0.005,
            "{}: Δalt {d_alt:.4}°, Δaz·cos(alt) {d_az:.4}°, Δfraction {d_k:.5}",
            c["time_utc"]
        );
        // Meeus's truncated distance series is good to a few km.
        assert!(d_dist < 10.0, "{}: Δdistance {d_dist:.1} km", c["time_utc"]);
        // The bright limb is undefined near new and full moon.
        let elongation = num(c, "elongation_deg");
        if elongation > 5.0 && elongation < 175.0 {
            let d_limb = angle_diff(m.bright_limb_angle_deg, num(c, "bright_limb_angle_deg")).abs();
            worst_limb = worst_limb.max(d_limb);
            assert!(d_limb < 0.5, "{}: Δlimb {d_limb:.3}°", c["time_utc"]);
        }
        assert!((m.phase_angle_deg - num(c, "phase_angle_deg")).abs() < 0.6);
    }
    eprintln!(
        "moon, worst |Δ|: altitude {worst_alt:.4}°, azimuth·cos(alt) {worst_az:.4}°, fraction \
         {worst_k:.5}, distance {worst_d:.1} km, bright limb {worst_limb:.3}°"
    );
}

#[test]
fn sunrise_sunset_and_twilights_match_the_ephemeris() {
    let cases = rows(include_str!("data/astro/sun_events.csv"));
    let keys = [
        "sunrise",
        "sunset",
        "civil_dawn",
        "civil_dusk",
        "nautical_dawn",
        "nautical_dusk",
        "astronomical_dawn",
        "astronomical_dusk",
    ];
    let mut worst = 0.0f64;
    for c in &cases {
        let place = Place::new(num(c, "lat_deg"), num(c, "lon_deg"), 0.0).unwrap();
        // Noon of the row's date: its window is the local solar day around it.
        let noon: DateTime<Utc> = format!("{}T12:00:00Z", c["date_utc"]).parse().unwrap();
        let instant = Instant::from_utc(noon).unwrap();
        let (events, start, _) = sun_events(&instant, &place).unwrap();
        let start_diff = (start.utc - time(c, "window_start_utc"))
            .num_seconds()
            .abs();
        assert!(start_diff <= 1, "{}: window {}", c["date_utc"], start.iso());
        let ours = serde_json::to_value(&events).unwrap();
        for key in keys {
            match (ours[key].as_str(), c[key].as_str()) {
                (None, "") => {}
                (Some(a), b) if !b.is_empty() => {
                    let a: DateTime<Utc> = a.parse().unwrap();
                    let b: DateTime<Utc> = b.parse().unwrap();
                    let dt = (a - b).num_milliseconds().abs() as f64 / 1000.0;
                    worst = worst.max(dt);
                    assert!(dt < 10.0, "{} {key}: {a} vs {b}", c["date_utc"]);
                }
                (a, b) => panic!("{} {key}: ours {a:?}, ephemeris {b:?}", c["date_utc"]),
            }
        }
    }
    eprintln!("sun events, worst |Δt| {worst:.1} s");
}

#[test]
fn stars_match_the_ephemeris() {
    use firmament::astro::stars::{catalogue, star_place};
    let cases = rows(include_str!("data/astro/stars.csv"));
    let mut worst = 0.0f64;
    for c in &cases {
        let ut1 = time(c, "time_utc")
            + Duration::microseconds((num(c, "ut1_minus_utc_s") * 1e6).round() as i64);
        let instant = Instant::with_delta_t(ut1, num(c, "delta_t_s"));
        let place = Place::new(num(c, "lat_deg"), num(c, "lon_deg"), 0.0).unwrap();
        let star = catalogue().iter().find(|s| s.name == c["name"]).unwrap();
        let p = star_place(star, &instant, &place, &Weather::default());
        let d_alt = (p.altitude_deg - num(c, "altitude_deg")).abs();
        let d_az = angle_diff(p.azimuth_deg, num(c, "azimuth_deg")).abs()
            * num(c, "altitude_deg").to_radians().cos();
        worst = worst.max(d_alt).max(d_az);
        // Nutation (≤ 17″) and aberration (≤ 20.5″) are left out: at most ~0.011°.
        assert!(
            d_alt < 0.012 && d_az < 0.012,
            "{} {}: {d_alt:.4}° {d_az:.4}°",
            c["time_utc"],
            c["name"]
        );
    }
    eprintln!("stars, worst |Δ| {worst:.4}° on the sky");
}

//! Celestial coordinates: nutation and obliquity, sidereal time, ecliptic → equatorial →
//! horizontal, and the topocentric parallax of a near body (Meeus, Astronomical Algorithms,
//! 2nd ed., 1998, ch. 11–13, 21, 22, 40). Angles in degrees unless the name says otherwise.

use super::time::{Instant, J2000_JD};
use super::Place;

/// Equatorial radius of the Earth, WGS 84 (m).
pub const EARTH_EQUATORIAL_RADIUS_M: f64 = 6_378_137.0;
/// Polar over equatorial radius, b/a = 1 − f with WGS 84's f = 1/298.257223563.
const EARTH_AXIS_RATIO: f64 = 1.0 - 1.0 / 298.257_223_563;

/// Nutation in longitude Δψ and in obliquity Δε (degrees), Meeus ch. 22's short series
/// (accurate to 0.5″ and 0.1″), at `t` Julian centuries TT from J2000.0.
pub fn nutation(t: f64) -> (f64, f64) {
    let omega = (125.04452 - 1934.136261 * t).to_radians();
    let l_sun = (280.4665 + 36_000.769_8 * t).to_radians();
    let l_moon = (218.3165 + 481_267.881_3 * t).to_radians();
    let dpsi = -17.20 * omega.sin() - 1.32 * (2.0 * l_sun).sin() - 0.23 * (2.0 * l_moon).sin()
        + 0.21 * (2.0 * omega).sin();
    let deps = 9.20 * omega.cos() + 0.57 * (2.0 * l_sun).cos() + 0.10 * (2.0 * l_moon).cos()
        - 0.09 * (2.0 * omega).cos();
    (dpsi / 3600.0, deps / 3600.0)
}

/// Mean obliquity of the ecliptic ε₀ (degrees), Meeus eq. 22.2 (IAU 1976).
pub fn mean_obliquity(t: f64) -> f64 {
    23.0 + 26.0 / 60.0 + (21.448 - t * (46.8150 + t * (0.00059 - t * 0.001813))) / 3600.0
}

/// Greenwich apparent sidereal time (degrees, [0, 360)): the mean sidereal time of Meeus
/// eq. 12.4 (UT) plus the equation of the equinoxes Δψ cos ε.
pub fn apparent_sidereal_time(instant: &Instant) -> f64 {
    let jd = instant.julian_day_ut();
    let t = (jd - J2000_JD) / 36_525.0;
    let mean = 280.460_618_37 + 360.985_647_366_29 * (jd - J2000_JD) + t * t * 0.000_387_933
        - t * t * t / 38_710_000.0;
    let tt = instant.centuries_tt();
    let (dpsi, deps) = nutation(tt);
    let eps = (mean_obliquity(tt) + deps).to_radians();
    (mean + dpsi * eps.cos()).rem_euclid(360.0)
}

/// Right ascension and declination (degrees) of ecliptic longitude λ and latitude β with
/// obliquity ε (Meeus eq. 13.3, 13.4).
pub fn ecliptic_to_equatorial(lambda: f64, beta: f64, epsilon: f64) -> (f64, f64) {
    let (l, b, e) = (lambda.to_radians(), beta.to_radians(), epsilon.to_radians());
    let ra = (l.sin() * e.cos() - b.tan() * e.sin()).atan2(l.cos());
    let dec = (b.sin() * e.cos() + b.cos() * e.sin() * l.sin()).asin();
    (ra.to_degrees().rem_euclid(360.0), dec.to_degrees())
}

/// ρ sin φ′ and ρ cos φ′ of `place`: its geocentric position in Earth equatorial radii
/// (Meeus ch. 11, WGS 84 ellipsoid).
pub fn geocentric_place(place: &Place) -> (f64, f64) {
    let phi = place.lat_deg.to_radians();
    let u = (EARTH_AXIS_RATIO * phi.tan()).atan();
    let h = place.elevation_m / EARTH_EQUATORIAL_RADIUS_M;
    (
        EARTH_AXIS_RATIO * u.sin() + h * phi.sin(),
        u.cos() + h * phi.cos(),
    )
}

/// Topocentric right ascension and declination (degrees) of a body at geocentric (α, δ)
/// and distance `distance_m`, seen from `place` at local hour angle `hour_angle` (degrees),
/// and its topocentric distance (m): Meeus eq. 40.2, 40.3 (rigorous), the distance from
/// the same vector geometry.
pub fn topocentric(
    ra: f64,
    dec: f64,
    distance_m: f64,
    hour_angle: f64,
    place: &Place,
) -> (f64, f64, f64) {
    let (rho_sin, rho_cos) = geocentric_place(place);
    // sin π = a / Δ, the equatorial horizontal parallax.
    let sin_pi = EARTH_EQUATORIAL_RADIUS_M / distance_m;
    let (h, d) = (hour_angle.to_radians(), dec.to_radians());
    let d_ra = (-rho_cos * sin_pi * h.sin()).atan2(d.cos() - rho_cos * sin_pi * h.cos());
    let dec_topo =
        ((d.sin() - rho_sin * sin_pi) * d_ra.cos()).atan2(d.cos() - rho_cos * sin_pi * h.cos());
    // The body in equatorial coordinates (hour angle frame), minus the observer's vector.
    let r = distance_m / EARTH_EQUATORIAL_RADIUS_M;
    let body = [r * d.cos() * h.cos(), r * d.cos() * h.sin(), r * d.sin()];
    let obs = [rho_cos, 0.0, rho_sin];
    let rel = [body[0] - obs[0], body[1] - obs[1], body[2] - obs[2]];
    let dist =
        (rel[0] * rel[0] + rel[1] * rel[1] + rel[2] * rel[2]).sqrt() * EARTH_EQUATORIAL_RADIUS_M;
    (
        (ra + d_ra.to_degrees()).rem_euclid(360.0),
        dec_topo.to_degrees(),
        dist,
    )
}

/// Altitude and azimuth (degrees; azimuth clockwise from north, [0, 360)) of declination
/// `dec` at local hour angle `hour_angle` from latitude `lat` (Meeus eq. 13.5, 13.6, with
/// the azimuth turned from Meeus's south origin to north).
pub fn horizontal(hour_angle: f64, dec: f64, lat: f64) -> (f64, f64) {
    let (h, d, p) = (hour_angle.to_radians(), dec.to_radians(), lat.to_radians());
    let alt = (p.sin() * d.sin() + p.cos() * d.cos() * h.cos()).asin();
    let az_south = h.sin().atan2(h.cos() * p.sin() - d.tan() * p.cos());
    (
        alt.to_degrees(),
        (az_south.to_degrees() + 180.0).rem_euclid(360.0),
    )
}

/// Precession of J2000.0 equatorial coordinates (degrees) to the mean equinox of `t`
/// Julian centuries TT from J2000.0 (Meeus eq. 21.2, 21.4, rigorous).
pub fn precess_from_j2000(ra: f64, dec: f64, t: f64) -> (f64, f64) {
    let arcsec = |x: f64| (x / 3600.0).to_radians();
    let zeta = arcsec(t * (2306.2181 + t * (0.30188 + t * 0.017998)));
    let z = arcsec(t * (2306.2181 + t * (1.09468 + t * 0.018203)));
    let theta = arcsec(t * (2004.3109 - t * (0.42665 + t * 0.041833)));
    let (a, d) = (ra.to_radians() + zeta, dec.to_radians());
    let aa = d.cos() * a.sin();
    let bb = theta.cos() * d.cos() * a.cos() - theta.sin() * d.sin();
    let cc = theta.sin() * d.cos() * a.cos() + theta.cos() * d.sin();
    let ra_new = aa.atan2(bb) + z;
    let dec_new = cc.clamp(-1.0, 1.0).asin();
    (ra_new.to_degrees().rem_euclid(360.0), dec_new.to_degrees())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sidereal_time_and_nutation_of_meeus_examples() {
        // Example 12.a: 1987 April 10, 0h UT: apparent sidereal time 13h10m46.1351s.
        let t = Instant::with_delta_t("1987-04-10T00:00:00Z".parse().unwrap(), 55.0);
        let expected = (13.0 + 10.0 / 60.0 + 46.1351 / 3600.0) * 15.0;
        assert!((apparent_sidereal_time(&t) - expected).abs() < 0.5 / 3600.0 * 15.0);
        // Example 22.a: 1987 April 10, 0h TD: Δψ = −3.788″, Δε = +9.443″, ε₀ = 23°26′27.407″.
        let tt = (2_446_895.5 - J2000_JD) / 36_525.0;
        let (dpsi, deps) = nutation(tt);
        assert!((dpsi * 3600.0 + 3.788).abs() < 0.5 && (deps * 3600.0 - 9.443).abs() < 0.1);
        let eps0 = 23.0 + 26.0 / 60.0 + 27.407 / 3600.0;
        assert!((mean_obliquity(tt) - eps0).abs() < 0.001 / 3600.0);
    }

    #[test]
    fn precession_of_meeus_example_21b() {
        // θ Persei, J2000.0 α = 2h44m11.986s, δ = +49°13′42.48″, proper motion +0.03425 s/yr
        // and −0.0895″/yr applied first. Epoch 2028 Nov 13.19 TD: α = 2h46m11.331s
        // (41.547213°), δ = +49°20′54.54″ (49.348483°).
        let years = 28.867_214_6;
        let (ra0, dec0) = (
            (2.0 + 44.0 / 60.0 + (11.986 + 0.034_25 * years) / 3600.0) * 15.0,
            49.0 + 13.0 / 60.0 + (42.48 - 0.0895 * years) / 3600.0,
        );
        let t = (2_462_088.69 - J2000_JD) / 36_525.0;
        let (ra, dec) = precess_from_j2000(ra0, dec0, t);
        assert!((ra - 41.547_213).abs() < 3e-6, "{ra}");
        assert!((dec - 49.348_483).abs() < 3e-6, "{dec}");
    }

    #[test]
    fn horizontal_of_meeus_example_13b() {
        // Venus from Washington, 1987 April 10 19:21 UT: H = 64.352133°, δ = −6.719892°,
        // φ = 38°55′17″: A = 68.0337° from the south (248.0337° from north), h = 15.1249°.
        let (alt, az) = horizontal(64.352_133, -6.719_892, 38.0 + 55.0 / 60.0 + 17.0 / 3600.0);
        assert!((alt - 15.1249).abs() < 1e-4 && (az - 248.0337).abs() < 1e-4);
    }

    #[test]
    fn parallax_of_meeus_example_40a() {
        // Mars from Palomar (φ = 33°21′22″, 1706 m), 2003 Aug 28 3h17m UT: H = 288.7958°,
        // α = 339.530208°, δ = −15.771083°, Δ = 0.37276 AU: α′ = 22h38m08.54s
        // (339.535583°), δ′ = −15°46′30.0″ (−15.775°).
        let place = Place {
            lat_deg: 33.0 + 21.0 / 60.0 + 22.0 / 3600.0,
            lon_deg: 116.0 + 51.0 / 60.0 + 45.0 / 3600.0 - 360.0,
            elevation_m: 1706.0,
        };
        let au = 149_597_870_700.0;
        let (ra, dec, _) = topocentric(339.530_208, -15.771_083, 0.37276 * au, 288.7958, &place);
        assert!((ra - 339.535_583).abs() < 3e-5, "{ra}");
        assert!((dec + 15.775).abs() < 3e-5, "{dec}");
        let (rho_sin, rho_cos) = geocentric_place(&place);
        assert!((rho_sin - 0.546_861).abs() < 2e-6 && (rho_cos - 0.836_339).abs() < 2e-6);
    }
}

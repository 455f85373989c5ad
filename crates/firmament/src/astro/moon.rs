//! The moon: geocentric position from Meeus's truncated ELP-2000/82 theory (Astronomical
//! Algorithms, 2nd ed., 1998, ch. 47: about 10″ in longitude, 4″ in latitude), topocentric
//! place with the rigorous parallax (ch. 40, up to ~1°), phase angle, illuminated fraction
//! and the bright limb's position angle (ch. 48).

use std::sync::OnceLock;

use super::coordinates::{
    apparent_sidereal_time, ecliptic_to_equatorial, horizontal, mean_obliquity, nutation,
    topocentric,
};
use super::sun::SunPosition;
use super::time::Instant;
use super::{refraction_deg, Place, Weather};

/// Mean radius of the moon (m), IAU/IAG 2015 (Archinal et al. 2018).
pub const MOON_RADIUS_M: f64 = 1_737_400.0;

/// Where the moon is, seen from a place at an instant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MoonPosition {
    /// Topocentric zenith angle, no refraction (degrees).
    pub zenith_deg: f64,
    /// With the atmosphere's refraction (degrees).
    pub apparent_zenith_deg: f64,
    /// Azimuth, clockwise from north (degrees, [0, 360)).
    pub azimuth_deg: f64,
    /// Distance from the observer (km).
    pub distance_km: f64,
    /// Distance from the Earth's centre (km).
    pub geocentric_distance_km: f64,
    /// Angular radius seen from the observer (degrees).
    pub angular_radius_deg: f64,
    /// The Sun–Moon–Earth angle (degrees; 0 at full moon).
    pub phase_angle_deg: f64,
    /// Fraction of the disk lit, (1 + cos i) / 2.
    pub illuminated_fraction: f64,
    /// Position angle of the bright limb's midpoint, from the disk's north point towards
    /// east (degrees, [0, 360); Meeus eq. 48.5, geocentric).
    pub bright_limb_angle_deg: f64,
    /// Geocentric apparent right ascension and declination of date (degrees).
    pub ra_deg: f64,
    /// See `ra_deg`.
    pub dec_deg: f64,
}

/// Geocentric apparent ecliptic longitude, latitude (degrees, of date) and distance (km) of
/// the moon at `t` Julian centuries TT from J2000.0: Meeus ch. 47 plus the nutation in
/// longitude.
pub fn geocentric_ecliptic(t: f64) -> (f64, f64, f64) {
    let poly = |c: [f64; 5]| c[0] + t * (c[1] + t * (c[2] + t * (c[3] + t * c[4])));
    // Meeus eq. 47.1–47.5: mean longitude, mean elongation, the sun's and the moon's mean
    // anomalies, the argument of latitude (degrees).
    let l1 = poly([
        218.316_447_7,
        481_267.881_234_21,
        -0.001_578_6,
        1.0 / 538_841.0,
        -1.0 / 65_194_000.0,
    ]);
    let d = poly([
        297.850_192_1,
        445_267.111_403_4,
        -0.001_881_9,
        1.0 / 545_868.0,
        -1.0 / 113_065_000.0,
    ]);
    let m = poly([
        357.529_109_2,
        35_999.050_290_9,
        -0.000_153_6,
        1.0 / 24_490_000.0,
        0.0,
    ]);
    let m1 = poly([
        134.963_396_4,
        477_198.867_505_5,
        0.008_741_4,
        1.0 / 69_699.0,
        -1.0 / 14_712_000.0,
    ]);
    let f = poly([
        93.272_095_0,
        483_202.017_523_3,
        -0.003_653_9,
        -1.0 / 3_526_000.0,
        1.0 / 863_310_000.0,
    ]);
    let a1 = (119.75 + 131.849 * t).to_radians();
    let a2 = (53.09 + 479_264.290 * t).to_radians();
    let a3 = (313.45 + 481_266.484 * t).to_radians();
    // The eccentricity of the Earth's orbit scales terms in M (eq. 47.6).
    let e = 1.0 - t * (0.002_516 + t * 0.000_007_4);
    let args = [
        d.to_radians(),
        m.to_radians(),
        m1.to_radians(),
        f.to_radians(),
    ];
    let (l1r, m1r, fr) = (l1.to_radians(), m1.to_radians(), f.to_radians());
    let term = |mult: &[i32; 4]| {
        let arg: f64 = mult.iter().zip(&args).map(|(&k, a)| k as f64 * a).sum();
        (arg, e.powi(mult[1].abs()))
    };
    let (mut sl, mut sr, mut sb) = (0.0, 0.0, 0.0);
    for (mult, cl, cr) in &terms().lr {
        let (arg, scale) = term(mult);
        sl += cl * scale * arg.sin();
        sr += cr * scale * arg.cos();
    }
    for (mult, cb) in &terms().b {
        let (arg, scale) = term(mult);
        sb += cb * scale * arg.sin();
    }
    // Additive terms for Venus (A1), Jupiter (A2) and the flattening of the Earth.
    sl += 3958.0 * a1.sin() + 1962.0 * (l1r - fr).sin() + 318.0 * a2.sin();
    sb += -2235.0 * l1r.sin()
        + 382.0 * a3.sin()
        + 175.0 * (a1 - fr).sin()
        + 175.0 * (a1 + fr).sin()
        + 127.0 * (l1r - m1r).sin()
        - 115.0 * (l1r + m1r).sin();
    let (dpsi, _) = nutation(t);
    (
        (l1 + sl / 1e6 + dpsi).rem_euclid(360.0),
        sb / 1e6,
        385_000.56 + sr / 1000.0,
    )
}

/// The moon seen from `place` at `instant`, with `sun` the sun's position at the same
/// instant (for the phase).
pub fn moon_position(
    instant: &Instant,
    place: &Place,
    weather: &Weather,
    sun: &SunPosition,
) -> MoonPosition {
    let t = instant.centuries_tt();
    let (lambda, beta, distance_km) = geocentric_ecliptic(t);
    let (_, deps) = nutation(t);
    let (ra, dec) = ecliptic_to_equatorial(lambda, beta, mean_obliquity(t) + deps);
    let hour_angle = apparent_sidereal_time(instant) + place.lon_deg - ra;
    let (ra_topo, dec_topo, topo_m) = topocentric(ra, dec, distance_km * 1000.0, hour_angle, place);
    let hour_angle_topo = hour_angle - (ra_topo - ra);
    let (alt, azimuth_deg) = horizontal(hour_angle_topo, dec_topo, place.lat_deg);
    // Phase (Meeus eq. 48.2, 48.3): elongation ψ from the sun, then the phase angle i.
    let (ra0, dec0) = (sun.ra_deg.to_radians(), sun.dec_deg.to_radians());
    let (a, d) = (ra.to_radians(), dec.to_radians());
    let cos_psi = dec0.sin() * d.sin() + dec0.cos() * d.cos() * (ra0 - a).cos();
    let psi = cos_psi.clamp(-1.0, 1.0).acos();
    let sun_km = sun.distance_au * super::sun::ASTRONOMICAL_UNIT_M / 1000.0;
    let phase = (sun_km * psi.sin()).atan2(distance_km - sun_km * psi.cos());
    // Bright limb (eq. 48.5).
    let chi = (dec0.cos() * (ra0 - a).sin())
        .atan2(dec0.sin() * d.cos() - dec0.cos() * d.sin() * (ra0 - a).cos());
    let topo_km = topo_m / 1000.0;
    MoonPosition {
        zenith_deg: 90.0 - alt,
        apparent_zenith_deg: 90.0 - alt - refraction_deg(alt, weather),
        azimuth_deg,
        distance_km: topo_km,
        geocentric_distance_km: distance_km,
        angular_radius_deg: (MOON_RADIUS_M / topo_m).asin().to_degrees(),
        phase_angle_deg: phase.to_degrees(),
        illuminated_fraction: (1.0 + phase.cos()) / 2.0,
        bright_limb_angle_deg: chi.to_degrees().rem_euclid(360.0),
        ra_deg: ra,
        dec_deg: dec,
    }
}

/// Meeus's tables 47.A (longitude and distance) and 47.B (latitude): multiples of
/// (D, M, M′, F) and coefficients (10⁻⁶ degree, 10⁻³ km).
struct Terms {
    lr: Vec<([i32; 4], f64, f64)>,
    b: Vec<([i32; 4], f64)>,
}

fn terms() -> &'static Terms {
    static T: OnceLock<Terms> = OnceLock::new();
    T.get_or_init(|| {
        let rows = |name: &str, text: &str| -> Vec<Vec<f64>> {
            text.lines()
                .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
                .skip(1)
                .map(|l| {
                    l.split(',')
                        .map(|v| v.trim().parse().unwrap_or_else(|_| panic!("{name}: {l}")))
                        .collect()
                })
                .collect()
        };
        let mult = |r: &[f64]| [r[0] as i32, r[1] as i32, r[2] as i32, r[3] as i32];
        let lr = rows(
            "meeus_moon_lr.csv",
            include_str!("../../data/meeus_moon_lr.csv"),
        );
        let b = rows(
            "meeus_moon_b.csv",
            include_str!("../../data/meeus_moon_b.csv"),
        );
        Terms {
            lr: lr.iter().map(|r| (mult(r), r[4], r[5])).collect(),
            b: b.iter().map(|r| (mult(r), r[4])).collect(),
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::astro::time::J2000_JD;

    #[test]
    fn meeus_example_47a() {
        // 1992 April 12, 0h TD: λ = 133.162655° (apparent: + Δψ = 0.004610°),
        // β = −3.229126°, Δ = 368409.7 km.
        let t = (2_448_724.5 - J2000_JD) / 36_525.0;
        let (lambda, beta, dist) = geocentric_ecliptic(t);
        assert_eq!(terms().lr.len(), 60);
        assert_eq!(terms().b.len(), 60);
        assert!((lambda - 133.167_265).abs() < 1e-4, "{lambda}");
        assert!((beta + 3.229_126).abs() < 1e-6, "{beta}");
        assert!((dist - 368_409.7).abs() < 0.1, "{dist}");
    }
}

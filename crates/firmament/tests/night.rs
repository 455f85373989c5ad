//! The night sky against published photometry: the full moon's illuminance on the ground,
//! the dark sky's zenith brightness at new moon, the moon's disk and phase.

use std::sync::OnceLock;

use chrono::{DateTime, Utc};
use firmament::astro::photometry::luminance_from_surface_brightness;
use firmament::astro::{Instant, Place, Sky, Weather};
use firmament::atmosphere::Atmosphere;
use firmament::math::Vec3;
use firmament::render::{ShadeScratch, Shader};
use firmament::scene::sky_lights::{lights_of, night_sky_background};
use firmament::scene::{Ray, Scene, Sphere};
use firmament::sky::bruneton4d::{Bruneton4d, MieStorage, TableConfig, TableSizes, Tables};
use firmament::sky::SkyMethod;
use firmament::spectrum::{ColourMatrix, Wavelengths};

fn sky() -> &'static Bruneton4d {
    static SKY: OnceLock<Bruneton4d> = OnceLock::new();
    SKY.get_or_init(|| {
        let model = Atmosphere::earth().resolve(&Wavelengths::rgb()).unwrap();
        let config = TableConfig {
            sizes: TableSizes::small(),
            orders: 4,
            mie: MieStorage::Separate,
            order_tail: true,
        };
        Bruneton4d::new(model.clone(), Tables::compute(&model, &config).unwrap()).unwrap()
    })
}

/// The place along latitude `lat` where the moon stands closest to `altitude` degrees at
/// `time` in astronomical night (the sun below −18°; longitudes in 0.25° steps).
fn place_with_moon_at(time: &str, lat: f64, altitude: f64) -> Sky {
    let utc: DateTime<Utc> = time.parse().unwrap();
    let instant = Instant::from_utc(utc).unwrap();
    (0..1440)
        .map(|i| {
            let place = Place::new(lat, -180.0 + i as f64 * 0.25, 0.0).unwrap();
            Sky::at(instant, place, &Weather::default()).unwrap()
        })
        .filter(|s| s.sun.zenith_deg > 108.0)
        .min_by(|a, b| {
            let d = |s: &Sky| ((90.0 - s.moon.zenith_deg) - altitude).abs();
            d(a).total_cmp(&d(b))
        })
        .unwrap()
}

fn night_scene<'a>(method: &'a Bruneton4d, sky: &Sky) -> Scene<'a> {
    let model = method.model();
    Scene {
        sky: method,
        surfaces: vec![Box::new(Sphere::ground(model))],
        volumes: Vec::new(),
        lights: lights_of(model, sky, true, true),
        background: Some(night_sky_background(model)),
    }
}

/// Luminance (cd/m²) along `dir` from 2 m above the ground.
fn luminance(scene: &Scene, dir: Vec3) -> f64 {
    let model = scene.sky.model();
    let origin = Vec3::new(0.0, 0.0, model.bottom_radius_m + 2.0);
    let mut l = vec![0.0; model.channels()];
    Shader::new(scene, origin).unwrap().shade(
        &Ray { origin, dir },
        &mut ShadeScratch::default(),
        &mut l,
    );
    ColourMatrix::new(model.wavelengths.nm()).to_xyz(&l)[1]
}

/// Illuminance (lx) on a horizontal surface 2 m up: each light's direct beam through the air
/// and the sky's light.
fn horizontal_illuminance(scene: &Scene) -> f64 {
    let model = scene.sky.model();
    let colour = ColourMatrix::new(model.wavelengths.nm());
    let point = Vec3::new(0.0, 0.0, model.bottom_radius_m + 2.0);
    let n = model.channels();
    let (mut direct, mut diffuse) = (vec![0.0; n], vec![0.0; n]);
    let mut e = 0.0;
    for light in &scene.lights {
        let view = scene.sky.view(point, light);
        view.sun_and_sky_irradiance(point, Vec3::Z, &mut direct, &mut diffuse);
        e += colour.to_xyz(&direct)[1] + colour.to_xyz(&diffuse)[1];
    }
    e
}

#[test]
fn full_moon_at_45_degrees_gives_a_fifth_of_a_lux() {
    // Full moon of 2026-01-03 10:03 UTC, seen from 20° N where it stands 45° high.
    let astro = place_with_moon_at("2026-01-03T10:03:00Z", 20.0, 45.0);
    assert!((astro.moon.illuminated_fraction - 1.0).abs() < 0.002);
    assert!((90.0 - astro.moon.zenith_deg - 45.0).abs() < 0.3);
    assert!(astro.sun.zenith_deg > 108.0, "astronomical night");
    let method = sky();
    let scene = night_scene(method, &astro);
    assert_eq!(scene.lights.len(), 2, "the sun and the moon");
    let e = horizontal_illuminance(&scene);
    // Published full-moon illuminance on the ground: 0.1–0.3 lx (e.g. Kyba et al. 2017,
    // Sci. Rep. 7, 3270: up to 0.3 lx with the moon high; Bond & Henderson 1963: 0.27 lx at
    // the zenith).
    assert!((0.1..0.3).contains(&e), "{e} lx");
    let zenith = luminance(&scene, Vec3::Z);
    // The moonlit sky: the daylight sky dimmed by the sun/moon ratio, 10^(0.4·14) = 4·10⁵,
    // plus the night glow: about 10⁻² cd/m² at the zenith (Kyba et al. 2017: 21 → 18–19
    // mag/arcsec² under a full moon).
    let mag = |l: f64| -2.5 * (l / luminance_from_surface_brightness(0.0)).log10();
    eprintln!(
        "full moon 45° high: {e:.3} lx on the ground, zenith {zenith:.2e} cd/m² ({:.2} mag/arcsec²)",
        mag(zenith)
    );
    assert!((17.0..20.0).contains(&mag(zenith)), "{}", mag(zenith));
}

#[test]
fn new_moon_night_is_as_dark_as_a_dark_site() {
    // New moon of 2026-02-17 12:01 UTC; at 0° longitude it is local noon, so look from the
    // antimeridian: the sun ~60° below the horizon there, the moon with it.
    let utc: DateTime<Utc> = "2026-02-17T12:01:00Z".parse().unwrap();
    let astro = Sky::at(
        Instant::from_utc(utc).unwrap(),
        Place::new(-10.0, 179.0, 0.0).unwrap(),
        &Weather::default(),
    )
    .unwrap();
    assert!(astro.moon.illuminated_fraction < 0.01 && astro.sun.zenith_deg > 130.0);
    let method = sky();
    let scene = night_scene(method, &astro);
    let zenith = luminance(&scene, Vec3::Z);
    let mag = -2.5 * (zenith / luminance_from_surface_brightness(0.0)).log10();
    eprintln!("new moon: zenith {zenith:.3e} cd/m² ({mag:.2} mag/arcsec²)");
    // Dark sites at the zenith: 21.8–22.1 V mag/arcsec² (Benn & Ellison 1998; Walker 1987).
    assert!((21.8..22.2).contains(&mag), "{mag}");
    // Not black; 30° up the airglow's longer path (van Rhijn) outweighs the extinction, as
    // in real dark skies (Leinert et al. 1998: brighter towards the horizon).
    let low = luminance(&scene, Vec3::new(0.0, 0.866, 0.5));
    eprintln!("new moon: 30° up {low:.3e} cd/m²");
    assert!(low > zenith && low < 2.0 * zenith, "{low} vs {zenith}");
}

#[test]
fn the_moons_disk_shows_its_phase() {
    // First quarter, 2026-01-26 04:47 UTC, 40° high at night: sample the disk towards the
    // sun and away from it.
    let astro = place_with_moon_at("2026-01-26T04:47:00Z", 0.0, 40.0);
    assert!((90.0 - astro.moon.zenith_deg - 40.0).abs() < 0.5);
    assert!((astro.moon.illuminated_fraction - 0.5).abs() < 0.05);
    let method = sky();
    let scene = night_scene(method, &astro);
    let m = astro.moon_direction();
    let sun = astro.sun_direction();
    // Towards the sun across the disk (perpendicular to the line of sight).
    let across = (sun - m * sun.dot(m)).normalize();
    let r = astro.moon.angular_radius_deg.to_radians();
    let at = |f: f64| luminance(&scene, (m + across * (f * r)).normalize());
    let (lit, dark, centre) = (at(0.6), at(-0.6), at(0.0));
    let sky_beside = luminance(&scene, (m + across * (3.0 * r)).normalize());
    eprintln!("first quarter: lit {lit:.1}, centre {centre:.1}, dark {dark:.3}, sky {sky_beside:.3} cd/m²");
    // Lit limb: thousands of cd/m² (the full moon is ~2500 cd/m² seen through the air);
    // the dark half: earthshine, a few ten-thousandths of it, above the moonlit sky.
    assert!(lit > 500.0 && lit < 5000.0, "{lit}");
    assert!(
        dark < 1e-2 * lit && dark > sky_beside,
        "{dark} vs {sky_beside}"
    );
}

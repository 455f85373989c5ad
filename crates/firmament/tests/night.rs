//! The night sky against published photometry: the full moon's illuminance on the ground,
//! the dark sky's zenith brightness at new moon, the moon's disk and phase.

mod common;

use common::sky;

use chrono::{DateTime, Utc};
use firmament::astro::photometry::luminance_from_surface_brightness;
use firmament::astro::refraction_deg;
use firmament::astro::{Instant, Place, Sky, Weather};
use firmament::math::Vec3;
use firmament::render::{self, RenderSettings};
use firmament::render::{ShadeScratch, Shader};
use firmament::scene::sky_lights::{lights_of, night_sky_background, sources_of};
use firmament::scene::{Camera, Projection};
use firmament::scene::{Ray, Scene, Sphere};
use firmament::sky::bruneton4d::Bruneton4d;
use firmament::sky::SkyMethod;

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
        stars: Vec::new(),
        aerial_volume: None,
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
    model.colour_matrix().to_xyz(&l)[1]
}

/// Illuminance (lx) on a horizontal surface 2 m up: each light's direct beam through the air
/// and the sky's light.
fn horizontal_illuminance(scene: &Scene) -> f64 {
    let model = scene.sky.model();
    let colour = model.colour_matrix();
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

#[test]
fn sirius_vega_and_polaris_land_on_their_pixels_with_their_brightness_and_colours() {
    // 2026-01-15 23:30 UTC from 60° N, 10° E: all three up (positions from skyfield in
    // tests/data/astro/stars.csv, independent of our astronomy).
    let utc: DateTime<Utc> = "2026-01-15T23:30:00Z".parse().unwrap();
    let weather = Weather::default();
    let astro = Sky::at(
        Instant::from_utc(utc).unwrap(),
        Place::new(60.0, 10.0, 0.0).unwrap(),
        &weather,
    )
    .unwrap();
    let method = sky();
    let model = method.model();
    let sources = sources_of(model, &astro, true, true);
    assert!(
        sources.stars.len() > 3000,
        "{} stars up",
        sources.stars.len()
    );
    let mut scene = night_scene(method, &astro);
    scene.stars = sources.stars;
    let size = 512;
    let camera = Camera {
        projection: Projection::Fisheye,
        altitude_m: 2.0,
        heading_deg: 0.0,
        pitch_deg: 0.0,
        roll_deg: 0.0,
        fov_deg: 60.0,
    };
    let settings = RenderSettings {
        camera: &camera,
        width: size,
        height: size,
        white_balance: false,
    };
    let frame = render::render(&scene, &settings, &|_| {}, None).unwrap();
    let prepared = camera.prepare(model.bottom_radius_m, size, size);
    let cases = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/astro/stars.csv"
    ))
    .unwrap();
    let mut found = std::collections::HashMap::new();
    for line in cases
        .lines()
        .filter(|l| l.starts_with("2026-01-15T23:30:00Z"))
    {
        let f: Vec<&str> = line.split(',').collect();
        let (name, alt, az): (&str, f64, f64) =
            (f[3], f[8].parse().unwrap(), f[9].parse().unwrap());
        if alt < 5.0 {
            continue;
        }
        // The equidistant fisheye (zenith at the centre, north up, east left), written
        // out here rather than taken from the camera code.
        let zenith = (90.0 - alt - refraction_deg(alt, &weather)).to_radians();
        let rho = zenith / (std::f64::consts::PI / 2.0);
        let (x, y) = (-rho * az.to_radians().sin(), rho * az.to_radians().cos());
        let (ex, ey) = ((x + 1.0) / 2.0 * size as f64, (1.0 - y) / 2.0 * size as f64);
        // The star's light: the sum over a 5×5 window of (pixel − the window's median
        // border) × its solid angle, and its centroid.
        let (cx, cy) = (ex.floor() as i64, ey.floor() as i64);
        let px = |x: i64, y: i64| frame.image.data[y as usize * size + x as usize];
        let lum = |p: [f32; 3]| 0.2126 * p[0] as f64 + 0.7152 * p[1] as f64 + 0.0722 * p[2] as f64;
        let mut border: Vec<[f32; 3]> = Vec::new();
        for d in -3..=3 {
            border.extend([
                px(cx + d, cy - 3),
                px(cx + d, cy + 3),
                px(cx - 3, cy + d),
                px(cx + 3, cy + d),
            ]);
        }
        border.sort_by(|a, b| lum(*a).total_cmp(&lum(*b)));
        let bg = border[border.len() / 2];
        let (mut flux, mut mx, mut my) = ([0.0f64; 3], 0.0, 0.0);
        for dy in -2..=2 {
            for dx in -2..=2 {
                let (x, y) = (cx + dx, cy + dy);
                let omega = prepared.pixel_solid_angle(x as usize, y as usize);
                let p = px(x, y);
                let e: Vec<f64> = (0..3)
                    .map(|i| ((p[i] - bg[i]) as f64).max(0.0) * omega)
                    .collect();
                let l = 0.2126 * e[0] + 0.7152 * e[1] + 0.0722 * e[2];
                mx += l * (x as f64 + 0.5);
                my += l * (y as f64 + 0.5);
                for i in 0..3 {
                    flux[i] += e[i];
                }
            }
        }
        let total = 0.2126 * flux[0] + 0.7152 * flux[1] + 0.0722 * flux[2];
        let (mx, my) = (mx / total, my / total);
        assert!(
            (mx - ex).hypot(my - ey) < 0.75,
            "{name}: centroid ({mx:.2}, {my:.2}), expected ({ex:.2}, {ey:.2})"
        );
        // Blue/red outside the air: the rendered colour over the transmittance at the
        // red and blue samples of the RGB grid (680 and 440 nm).
        let dir = firmament::astro::local_direction(zenith.to_degrees(), az);
        let (mut l, mut t) = (vec![0.0; 3], vec![0.0; 3]);
        let origin = Vec3::new(0.0, 0.0, model.bottom_radius_m + 2.0);
        let view = method.view(origin, &scene.lights[0]);
        view.sky_radiance(dir, firmament::sky::Shadow::None, &mut l, &mut t);
        let outside = (flux[2] / t[2]) / (flux[0] / t[0]);
        found.insert(name.to_string(), (total, flux[2] / flux[0], outside));
    }
    let (sirius, vega, polaris) = (found["Sirius"], found["Vega"], found["Polaris"]);
    let betelgeuse = found["Betelgeuse"];
    eprintln!("illuminance (lx), blue/red in the image and outside the air: Sirius {sirius:?}, Vega {vega:?}, Polaris {polaris:?}, Betelgeuse {betelgeuse:?}");
    // Brightness: Sirius (−1.44, 12° up) > Vega (0.03, 10°) > Polaris (1.97, 60°); Sirius
    // outside the air gives 10^(−0.4(−1.44 + 13.98)) = 9.7·10⁻⁶ lx, dimmed by 12° of air.
    assert!(sirius.0 > vega.0 && vega.0 > polaris.0);
    assert!(sirius.0 > 2e-6 && sirius.0 < 9.7e-6, "{}", sirius.0);
    // Polaris at 60°: 10^(−0.4(1.97 + 13.98)) = 4.2·10⁻⁷ lx × about 0.8.
    assert!((polaris.0 / 4.2e-7 - 0.8).abs() < 0.15, "{}", polaris.0);
    // Colours outside the air: blue-white Sirius and Vega (B−V ≈ 0), yellow-white Polaris
    // (0.64), orange Betelgeuse (1.5).
    assert!(sirius.2 > polaris.2 && vega.2 > polaris.2 && polaris.2 > betelgeuse.2);
    assert!((sirius.2 / vega.2 - 1.0).abs() < 0.1);
    // In the image, low Sirius is reddened by 12° of air, and red Betelgeuse stays reddest.
    assert!(sirius.1 < sirius.2 && betelgeuse.1 < vega.1.min(polaris.1));
}

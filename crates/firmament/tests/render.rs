//! Image statistics of rendered scenes (not golden pixels): colours and brightness
//! orderings every clear-sky photograph shows, the sun disk's energy, HDR files.

mod common;

use common::sky;

use firmament::math::{direction_from_zenith_azimuth, Vec3};
use firmament::render::{self, RenderSettings, ShadeScratch, Shader};
use firmament::scene::camera::orbit_fit_fov_deg;
use firmament::scene::{sun_direction, Camera, Light, Projection, Ray, Scene};
use firmament::sky::SkyMethod;

/// Linear sRGB (Y in cd/m²) seen from 2 m along (elevation, azimuth) in degrees.
fn look(sun: (f64, f64), elevation: f64, azimuth: f64) -> [f64; 3] {
    let sky = sky();
    let ray = Ray {
        origin: Vec3::new(0.0, 0.0, sky.model.bottom_radius_m + 2.0),
        dir: direction_from_zenith_azimuth((90.0 - elevation).to_radians(), azimuth.to_radians()),
    };
    let scene = Scene::clear_sky(sky, sun_direction(sun.0, sun.1), false);
    let mut l = [0.0; 3];
    Shader::new(&scene, ray.origin)
        .unwrap()
        .shade(&ray, &mut ShadeScratch::default(), &mut l);
    sky.model.colour_matrix().to_srgb(&l)
}

fn lum(c: [f64; 3]) -> f64 {
    0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]
}

#[test]
fn noon_zenith_is_blue_and_the_horizon_away_from_the_sun_is_brighter_and_whiter() {
    let sun = (30.0, 180.0);
    let zenith = look(sun, 90.0, 0.0);
    assert!(
        zenith[2] > zenith[1] && zenith[1] > zenith[0],
        "zenith {zenith:?}"
    );
    let horizon = look(sun, 2.0, 0.0);
    assert!(
        lum(horizon) > lum(zenith),
        "horizon {horizon:?} zenith {zenith:?}"
    );
    // Whiter: a smaller blue-to-red ratio.
    assert!(
        horizon[2] / horizon[0] < zenith[2] / zenith[0],
        "horizon {horizon:?} zenith {zenith:?}"
    );
}

#[test]
fn sunset_sky_near_the_sun_is_red_orange_and_the_zenith_stays_blue() {
    let sun = (89.5, 270.0);
    let near = look(sun, 1.5, 270.0);
    assert!(
        near[0] > near[1] && near[1] > near[2],
        "near the sun {near:?}"
    );
    let zenith = look(sun, 90.0, 0.0);
    assert!(zenith[2] > zenith[0], "zenith {zenith:?}");
}

#[test]
fn twilight_shows_the_earth_shadow_under_a_pink_belt() {
    // Sun 4° below the horizon in the west; look east.
    let sun = (94.0, 270.0);
    let shadow = look(sun, 1.0, 90.0);
    let belt = look(sun, 12.0, 90.0);
    let zenith = look(sun, 90.0, 0.0);
    assert!(lum(shadow) < lum(belt), "shadow {shadow:?} belt {belt:?}");
    // Pinkish: redder than the zenith and than the shadow band below it.
    assert!(
        belt[0] / belt[2] > zenith[0] / zenith[2],
        "belt {belt:?} zenith {zenith:?}"
    );
    assert!(
        belt[0] / belt[2] > shadow[0] / shadow[2],
        "belt {belt:?} shadow {shadow:?}"
    );
}

#[test]
fn from_orbit_the_planet_has_a_bright_limb_and_a_black_night_side() {
    let sky = sky();
    let camera = Camera {
        projection: Projection::Orbit,
        altitude_m: 30_000_000.0,
        heading_deg: 0.0,
        pitch_deg: 0.0,
        roll_deg: 0.0,
        fov_deg: orbit_fit_fov_deg(6_424_000.0, 36_360_000.0),
    };
    // Sun on the horizon of the point below the camera, in the east: day on the right.
    let (w, h) = (160, 160);
    let settings = RenderSettings {
        camera: &camera,
        width: w,
        height: h,
        white_balance: false,
    };
    let scene = Scene::clear_sky(sky, sun_direction(90.0, 90.0), false);
    let frame = render::render(&scene, &settings, &|_| {}, None).unwrap();
    let y = |x: usize, row: usize| lum(frame.image.get(x, row).map(|v| v as f64));
    let row = h / 2;
    // Walk right along the middle row from the centre: lit ground, then the atmosphere's
    // limb, then black space.
    let xs: Vec<f64> = (w / 2..w).map(|x| y(x, row)).collect();
    let ground = xs[5..20].iter().cloned().fold(0.0, f64::max);
    let limb = xs.iter().cloned().fold(0.0, f64::max);
    let space = xs[xs.len() - 3];
    assert!(limb > 0.0 && space == 0.0, "limb {limb} space {space}");
    assert!(ground > 0.0);
    // The night side (left, well inside the disk) is black next to the day side.
    let night = (5..w / 2 - 20).map(|x| y(x, row)).fold(0.0, f64::max);
    assert!(night < 1e-3 * ground, "night {night} day {ground}");
    // The limb is thin and bright: the peak is at the outer edge of the lit disk, above
    // the ground just inside it.
    let edge = xs.iter().rposition(|&v| v > 0.0).unwrap();
    let peak = xs.iter().position(|&v| v == limb).unwrap();
    assert!(edge - peak <= 1, "peak at {peak}, edge at {edge}: {xs:?}");
    let inside = xs[edge - 12..edge - 2].iter().sum::<f64>() / 10.0;
    assert!(limb > 1.1 * inside, "limb {limb}, just inside {inside}");
}

#[test]
fn sun_disk_integrates_to_the_solar_irradiance_times_transmittance() {
    let sky = sky();
    let sun = Light::sun(&sky.model, Vec3::Z, true);
    let origin = Vec3::new(0.0, 0.0, sky.model.bottom_radius_m + 2.0);
    let mut t = [0.0; 3];
    sky.view(origin, &sun)
        .transmittance_to_light(origin, &mut t);
    let alpha = sky.model.sun_angular_radius_rad;
    // Integrate over a fine polar grid around the sun, out to 1.2 α.
    let (nr, nphi) = (400, 64);
    let mut e = [0.0; 3];
    for i in 0..nr {
        let theta = (i as f64 + 0.5) / nr as f64 * 1.2 * alpha;
        let d_omega =
            theta.sin() * (1.2 * alpha / nr as f64) * (2.0 * std::f64::consts::PI / nphi as f64);
        for j in 0..nphi {
            let phi = j as f64 * 2.0 * std::f64::consts::PI / nphi as f64;
            let dir = Vec3::new(
                theta.sin() * phi.cos(),
                theta.sin() * phi.sin(),
                theta.cos(),
            );
            let mut l = [0.0; 3];
            sun.add_disk_radiance(dir, &t, &mut l);
            for k in 0..3 {
                e[k] += l[k] * d_omega;
            }
        }
    }
    for k in 0..3 {
        let want = sky.model.solar_irradiance[k] * t[k];
        assert!(
            (e[k] - want).abs() / want < 0.01,
            "channel {k}: {} vs {want}",
            e[k]
        );
    }
}

#[test]
fn every_projection_renders_finite_pixels_and_hdr_files_read_back() {
    let sky = sky();
    let dir = std::env::temp_dir().join(format!("firmament-render-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (projection, w, h) in [
        (Projection::Perspective, 48, 32),
        (Projection::Fisheye, 32, 32),
        (Projection::Equirect, 64, 32),
        (Projection::Cubemap, 96, 16),
        (Projection::Orbit, 32, 32),
    ] {
        let camera = Camera {
            projection,
            altitude_m: if projection == Projection::Orbit {
                1e7
            } else {
                100.0
            },
            // Only a perspective view tilts; a cube map's faces face the axes.
            heading_deg: if projection == Projection::Cubemap {
                0.0
            } else {
                10.0
            },
            pitch_deg: if projection == Projection::Perspective {
                5.0
            } else {
                0.0
            },
            roll_deg: 0.0,
            fov_deg: 60.0,
        };
        let settings = RenderSettings {
            camera: &camera,
            width: w,
            height: h,
            white_balance: false,
        };
        let scene = Scene::clear_sky(sky, sun_direction(40.0, 100.0), true);
        let frame = render::render(&scene, &settings, &|_| {}, None).unwrap();
        // Finite, with luminance ≥ 0. A component may be below 0 where a colour lies outside
        // sRGB (the orbit's limb, deep blue): the frame keeps it, the outputs map it into
        // the gamut at constant luminance (`gamut::map_into_gamut`).
        assert!(
            frame
                .image
                .data
                .iter()
                .all(|p| p.iter().all(|v| v.is_finite())
                    && 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2] >= -1e-6),
            "{projection:?}"
        );
        assert!(
            frame.image.data.iter().any(|p| p[1] > 0.0),
            "{projection:?}"
        );
        let exr = dir.join("a.exr");
        firmament::io::write_exr(&exr, &frame.image, firmament::io::ExrPrecision::F32).unwrap();
        assert_eq!(
            firmament::io::read_exr(&exr).unwrap().data,
            frame.image.data
        );
        firmament::io::write_exr(&exr, &frame.image, firmament::io::ExrPrecision::F16).unwrap();
        for (a, b) in firmament::io::read_exr(&exr)
            .unwrap()
            .data
            .iter()
            .zip(&frame.image.data)
        {
            for k in 0..3 {
                // Half floats clamp at 65504 (a small disk drawn as a point is brighter).
                let b = b[k].min(65504.0);
                assert!((a[k] - b).abs() <= 1e-3 * b.abs() + 1e-6, "f16 {a:?} {b:?}");
            }
        }
        let hdr = dir.join("a.hdr");
        firmament::io::write_hdr(&hdr, &frame.image).unwrap();
        for (a, b) in firmament::io::read_hdr(&hdr)
            .unwrap()
            .data
            .iter()
            .zip(&frame.image.data)
        {
            // RGBE holds no negative: an out-of-gamut component is written as 0.
            let m = b.iter().cloned().fold(0.0f32, f32::max);
            for k in 0..3 {
                let bk = b[k].max(0.0);
                assert!((a[k] - bk).abs() <= m / 128.0 + 1e-30, "rgbe {a:?} {b:?}");
            }
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

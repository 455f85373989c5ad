//! The sun's disk carries its whole illuminance at any resolution: summed over an
//! equirectangular map (the disk's radiance times each pixel's solid angle, the sky under it
//! taken away), the sun's illuminance equals the direct normal illuminance the sky method
//! gives at the observer, whether the disk is a point (256 and 512 wide: smaller than four
//! pixels), a few pixels with its edge integrated over each pixel's footprint (4096 wide), or
//! a telephoto disk hundreds of pixels across.

mod common;

use common::sky;
use firmament::math::Vec3;
use firmament::render::{render, RenderSettings, ShadeScratch, Shader};
use firmament::scene::{sun_direction, Camera, Projection, Ray, Scene};
use firmament::sky::SkyMethod;
use firmament::spectrum::ColourMatrix;

/// The sun's illuminance (lux) in a frame of `camera` at `width`×`height`, and the direct
/// normal illuminance at the observer.
fn illuminance(camera: &Camera, width: usize, height: usize, sun: Vec3) -> (f64, f64) {
    let sky = sky();
    let model = sky.model();
    let scene = Scene::clear_sky(sky, sun, true);
    let settings = RenderSettings {
        camera,
        width,
        height,
        white_balance: false,
    };
    let frame = render(&scene, &settings, &|_| {}, None).unwrap();
    let prepared = camera.prepare(model.bottom_radius_m, width, height);
    let observer = Vec3::new(0.0, 0.0, model.bottom_radius_m + camera.altitude_m);
    // The sky alone along each pixel's centre ray.
    let plain = Shader::plain(&scene, observer).unwrap().without_disks();
    let colour = ColourMatrix::new(model.wavelengths.nm());
    let mut scratch = ShadeScratch::default();
    let y = |c: [f64; 3]| 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
    let radius = scene.lights[0].angular_radius_rad;
    let mut sum = 0.0;
    for j in 0..height {
        for i in 0..width {
            let Some(ray) = prepared.ray(i as f64 + 0.5, j as f64 + 0.5) else {
                continue;
            };
            // Within a few footprints of the disk (a point's splat included).
            let footprint = prepared.pixel_solid_angle(i, j).sqrt();
            if ray.dir.dot(sun).acos() > radius + 3.0 * footprint {
                continue;
            }
            let mut l = [0.0; 3];
            plain.shade(
                &Ray {
                    origin: observer,
                    dir: ray.dir,
                },
                &mut scratch,
                &mut l,
            );
            let p = frame.image.data[j * width + i];
            let pixel = y([p[0] as f64, p[1] as f64, p[2] as f64]);
            sum += (pixel - y(colour.to_srgb(&l))) * prepared.pixel_solid_angle(i, j);
        }
    }
    // Direct normal illuminance: the light's irradiance through the air to the observer.
    let view = sky.view(observer, &scene.lights[0]);
    let mut t = [0.0; 3];
    view.transmittance_to_light(observer, &mut t);
    let e: Vec<f64> = (0..3)
        .map(|k| scene.lights[0].irradiance[k] * t[k])
        .collect();
    (sum, colour.to_xyz(&e)[1])
}

fn camera(projection: Projection, heading: f64, pitch: f64, fov: f64) -> Camera {
    Camera {
        projection,
        altitude_m: 2.0,
        heading_deg: heading,
        pitch_deg: pitch,
        roll_deg: 0.0,
        fov_deg: fov,
    }
}

#[test]
fn an_equirectangular_map_carries_the_suns_illuminance_at_any_width() {
    let sun = sun_direction(60.0, 120.0);
    for width in [256, 512, 4096] {
        let (map, direct) = illuminance(
            &camera(Projection::Equirect, 0.0, 0.0, 60.0),
            width,
            width / 2,
            sun,
        );
        eprintln!("{width} wide: {map:.1} lx in the map, {direct:.1} lx direct");
        assert!(
            (map / direct - 1.0).abs() < 0.01,
            "{width} wide: {map} lx against {direct} lx"
        );
    }
}

#[test]
fn a_telephoto_disk_carries_it_too() {
    let sun = sun_direction(60.0, 120.0);
    // A 1.2° field 96 pixels wide: the disk about 43 pixels across.
    let (map, direct) = illuminance(
        &camera(Projection::Perspective, 120.0, 30.0, 1.2),
        96,
        96,
        sun,
    );
    eprintln!("telephoto: {map:.1} lx in the frame, {direct:.1} lx direct");
    assert!(
        (map / direct - 1.0).abs() < 0.01,
        "{map} lx against {direct} lx"
    );
}

//! The sun's disk carries its whole illuminance at any resolution: summed over an
//! equirectangular map (the disk's radiance times each pixel's solid angle, the sky under it
//! taken away), the sun's illuminance equals the direct normal illuminance the sky method
//! gives at the observer, whether the disk is a point (256 and 512 wide: smaller than four
//! pixels), a few pixels with its edge integrated over each pixel's footprint (4096 wide), or
//! a telephoto disk hundreds of pixels across.

mod common;

use common::sky;
use firmament::math::Vec3;
use firmament::render::disk_edges::disk_illuminance;
use firmament::render::{render, RenderSettings};
use firmament::scene::{sun_direction, Camera, Projection, Scene};

/// The sun's illuminance (lux) in a frame of `camera` at `width`×`height`, and the direct
/// normal illuminance at the observer.
fn illuminance(camera: &Camera, width: usize, height: usize, sun: Vec3) -> (f64, f64) {
    let sky = sky();
    let scene = Scene::clear_sky(sky, sun, true);
    let settings = RenderSettings {
        camera,
        width,
        height,
        white_balance: false,
    };
    let frame = render(&scene, &settings, &|_| {}, None).unwrap();
    disk_illuminance(&frame, &scene, &settings, 0).unwrap()
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

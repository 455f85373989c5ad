//! The sun's disk on the GPU carries its whole illuminance as on the CPU: a pixel straddling
//! the disk's edge is the mean over its footprint (`shaders/render/disk_edges.wgsl`), so the
//! disk's illuminance summed over a frame equals the direct normal illuminance, for a disk
//! under two pixels wide in an equirectangular map and for a telephoto disk.

mod common;

use firmament::math::Vec3;
use firmament::render::disk_edges::disk_illuminance;
use firmament::render::RenderSettings;
use firmament::scene::{sun_direction, Camera, Projection, Scene};
use firmament_gpu::GpuSky;

use common::*;

/// The sun's illuminance (lux) in a GPU frame of `camera`, and the direct normal one.
fn gpu_illuminance(
    name: &str,
    camera: &Camera,
    width: usize,
    height: usize,
    sun: Vec3,
) -> Option<(f64, f64)> {
    let gpu = gpu(name)?;
    let _guard = serial();
    let sky = earth_rgb();
    let scene = Scene::clear_sky(sky, sun, true);
    let settings = RenderSettings {
        camera,
        width,
        height,
        white_balance: false,
    };
    let gpu_sky = GpuSky::from_sky(&gpu.ctx, sky).unwrap();
    let frame = gpu
        .renderer
        .render(&gpu.ctx, &gpu_sky, &scene.lights, &settings)
        .unwrap();
    Some(disk_illuminance(&frame, &scene, &settings, 0).unwrap())
}

#[test]
fn the_gpus_disk_carries_the_suns_illuminance() {
    let sun = sun_direction(60.0, 120.0);
    for (name, camera, w, h) in [
        // 1024 wide: the disk 1.5 pixels across (the CPU renderer would make it a point;
        // the GPU integrates it over the footprints of the pixels around it).
        (
            "equirect 1024",
            common::camera(Projection::Equirect, 2.0, 0.0, 0.0, 60.0),
            1024,
            512,
        ),
        (
            "telephoto",
            common::camera(Projection::Perspective, 2.0, 120.0, 30.0, 1.2),
            96,
            96,
        ),
    ] {
        let Some((frame, direct)) = gpu_illuminance(name, &camera, w, h, sun) else {
            return;
        };
        eprintln!("{name}: {frame:.1} lx in the frame, {direct:.1} lx direct");
        assert!(
            (frame / direct - 1.0).abs() < 0.01,
            "{name}: {frame} lx against {direct} lx"
        );
    }
}

//! The sun's disk on the GPU carries its whole illuminance as on the CPU: a pixel straddling
//! the disk's edge is the mean over its footprint (`shaders/render/disk_edges.wgsl`), so the
//! disk's illuminance summed over a frame equals the direct normal illuminance, for a disk
//! under two pixels wide in an equirectangular map and for a telephoto disk.

mod common;

use firmament::math::Vec3;
use firmament::render::{RenderSettings, ShadeScratch, Shader};
use firmament::scene::{sun_direction, Camera, Projection, Ray, Scene};
use firmament::sky::SkyMethod;
use firmament::spectrum::ColourMatrix;
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
    let model = sky.model();
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
    let prepared = camera.prepare(model.bottom_radius_m, width, height);
    let observer = Vec3::new(0.0, 0.0, model.bottom_radius_m + camera.altitude_m);
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
    let view = sky.view(observer, &scene.lights[0]);
    let mut t = [0.0; 3];
    view.transmittance_to_light(observer, &mut t);
    let e: Vec<f64> = (0..3)
        .map(|k| scene.lights[0].irradiance[k] * t[k])
        .collect();
    Some((sum, colour.to_xyz(&e)[1]))
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

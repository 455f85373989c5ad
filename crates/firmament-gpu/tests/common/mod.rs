//! What the GPU tests share: the device (one per test binary), one GPU test at a time, the
//! skies and cameras of the parity scenes, and the frame comparison (luminance per pixel,
//! mean and largest relative difference, the lights' disk edges and black pixels left out).

#![allow(dead_code)]

pub mod tables;

use std::sync::{Mutex, OnceLock};

use firmament::atmosphere::Atmosphere;
use firmament::math::Vec3;
use firmament::render::{Frame, RenderSettings};
use firmament::scene::terrain::{Heightfield, TerrainConfig};
use firmament::scene::{Camera, Light, Projection};
use firmament::sky::bruneton4d::{Bruneton4d, MieStorage, TableConfig, TableSizes, Tables};
use firmament::spectrum::Wavelengths;
use firmament_gpu::{GpuContext, GpuRenderer};

pub const MEAN_TOLERANCE: f64 = 0.01;
pub const PIXEL_TOLERANCE: f64 = 0.05;
/// Pixels darker than this fraction of the frame's brightest are not compared.
pub const NEGLIGIBLE: f64 = 1e-6;
/// Pixel footprints around the sun disk's edge left out.
pub const DISK_EDGE_FOOTPRINTS: f64 = 2.0;

pub struct Gpu {
    pub ctx: GpuContext,
    pub renderer: GpuRenderer,
}

/// The device and renderer, or None (and a line saying that `test` is skipped) where there
/// is no adapter; with `CI` set a missing adapter fails instead ([`firmament_gpu::test_context`]).
pub fn gpu(test: &str) -> Option<&'static Gpu> {
    static GPU: OnceLock<Option<Gpu>> = OnceLock::new();
    let gpu = GPU.get_or_init(|| {
        let ctx = firmament_gpu::test_context()?;
        eprintln!(
            "GPU adapter: {} ({}, software: {})",
            ctx.adapter_name(),
            ctx.backend(),
            ctx.is_software()
        );
        let renderer = GpuRenderer::new(&ctx).expect("render pipeline");
        Some(Gpu { ctx, renderer })
    });
    if gpu.is_none() {
        eprintln!("{test}: skipped, no GPU adapter (set CI to make this a failure)");
    }
    gpu.as_ref()
}

/// One GPU test at a time: the machine is small and lavapipe uses every core.
pub fn serial() -> std::sync::MutexGuard<'static, ()> {
    static LOCK: Mutex<()> = Mutex::new(());
    LOCK.lock().unwrap_or_else(|e| e.into_inner())
}

pub fn sky(preset: &str, wavelengths: Wavelengths, orders: usize, mie: MieStorage) -> Bruneton4d {
    let model = Atmosphere::preset(preset)
        .unwrap()
        .resolve(&wavelengths)
        .unwrap();
    let config = TableConfig {
        sizes: TableSizes::small(),
        orders,
        mie,
        order_tail: true,
    };
    let tables = Tables::compute(&model, &config).unwrap();
    Bruneton4d::new(model, tables).unwrap()
}

/// The default valley at a coarser resolution, and the earth's air with its ground lifted to
/// the valley's floor (small tables).
pub fn valley(config: TerrainConfig) -> (Heightfield, Bruneton4d) {
    let wavelengths = Wavelengths::rgb();
    let earth = Atmosphere::earth();
    let radius = earth.resolve(&wavelengths).unwrap().bottom_radius_m;
    let terrain = config.build(radius, wavelengths.nm()).unwrap();
    let lifted = earth.lifted(terrain.floor_m(), &wavelengths).unwrap();
    let model = lifted.resolve(&wavelengths).unwrap();
    let config = TableConfig {
        sizes: TableSizes::small(),
        ..TableConfig::default()
    };
    let tables = Tables::compute(&model, &config).unwrap();
    (terrain, Bruneton4d::new(model, tables).unwrap())
}

/// The earth preset in RGB with 4 orders, computed once for the RGB scenes.
pub fn earth_rgb() -> &'static Bruneton4d {
    static SKY: OnceLock<Bruneton4d> = OnceLock::new();
    SKY.get_or_init(|| sky("earth", Wavelengths::rgb(), 4, MieStorage::Separate))
}

pub fn camera(
    projection: Projection,
    altitude_m: f64,
    heading: f64,
    pitch: f64,
    fov: f64,
) -> Camera {
    Camera {
        projection,
        altitude_m,
        heading_deg: heading,
        pitch_deg: pitch,
        roll_deg: 0.0,
        fov_deg: fov,
    }
}

pub fn luminance(p: &[f32; 3]) -> f64 {
    0.2126 * p[0] as f64 + 0.7152 * p[1] as f64 + 0.0722 * p[2] as f64
}

pub fn angle(a: Vec3, b: Vec3) -> f64 {
    a.cross(b).length().atan2(a.dot(b))
}

pub struct Parity {
    pub mean: f64,
    pub max: f64,
    pub compared: usize,
    pub worst: (usize, usize, f64, f64),
}

/// Compare the frames as the parity tests do (module documentation).
pub fn measure(
    name: &str,
    sky: &Bruneton4d,
    settings: &RenderSettings,
    lights: &[Light],
    cpu: &Frame,
    gpu: &Frame,
    gpu_seconds: f64,
) -> Parity {
    let (w, h) = (settings.width, settings.height);
    let mask_mismatches = cpu
        .mask
        .iter()
        .zip(&gpu.mask)
        .filter(|(a, b)| a != b)
        .count();
    assert_eq!(mask_mismatches, 0, "{name}: projection masks differ");
    let prepared = settings.camera.prepare(sky.model.bottom_radius_m, w, h);
    // Whether pixel (x, y) lies within the footprint margin of the sun disk's edge.
    let near_disk_edge = |x: usize, y: usize| -> bool {
        if lights.iter().all(|l| !l.visible_disk) {
            return false;
        }
        let (px, py) = (x as f64 + 0.5, y as f64 + 0.5);
        let Some(ray) = prepared.ray(px, py) else {
            return false;
        };
        let footprint = [(1.0, 0.0), (-1.0, 0.0), (0.0, 1.0), (0.0, -1.0)]
            .iter()
            .filter_map(|(dx, dy)| prepared.ray(px + dx, py + dy))
            .map(|n| angle(n.dir, ray.dir))
            .fold(0.0, f64::max);
        lights.iter().filter(|l| l.visible_disk).any(|l| {
            (angle(ray.dir, l.direction) - l.angular_radius_rad).abs()
                < DISK_EDGE_FOOTPRINTS * footprint
        })
    };
    let candidates: Vec<usize> = (0..w * h)
        .filter(|&i| cpu.mask[i] && !near_disk_edge(i % w, i / w))
        .collect();
    let max = candidates
        .iter()
        .map(|&i| luminance(&cpu.image.data[i]))
        .fold(0.0, f64::max);
    let floor = max * NEGLIGIBLE;
    let (mut sum, mut worst_rel, mut compared) = (0.0, 0.0f64, 0usize);
    let mut worst = (0, 0, 0.0, 0.0);
    let mut over_one_percent = 0;
    for &i in &candidates {
        let c = luminance(&cpu.image.data[i]);
        let g = luminance(&gpu.image.data[i]);
        assert!(g.is_finite(), "{name}: non-finite GPU pixel {i}");
        if c < floor {
            // Not compared relatively, but dark on the GPU too.
            assert!(
                (g - c).abs() <= floor,
                "{name}: pixel {i} is dark on the CPU ({c:e}) but not on the GPU ({g:e})"
            );
            continue;
        }
        let rel = (g - c).abs() / c;
        sum += rel;
        compared += 1;
        if rel > 0.01 {
            over_one_percent += 1;
        }
        if rel > worst_rel {
            worst_rel = rel;
            worst = (i % w, i / w, c, g);
        }
    }
    let mean = if compared > 0 {
        sum / compared as f64
    } else {
        0.0
    };
    eprintln!(
        "{name}: {w}×{h}, {compared} of {} pixels compared ({} near the disk edge, {} below {NEGLIGIBLE:e} of max {max:.4e} cd/m²); mean rel {:.2e}, max rel {:.2e} at ({}, {}) cpu {:.5e} gpu {:.5e}; {over_one_percent} over 1 %; GPU frame {:.0} ms",
        w * h,
        (0..w * h).filter(|&i| cpu.mask[i]).count() - candidates.len(),
        candidates.len() - compared,
        mean,
        worst_rel,
        worst.0,
        worst.1,
        worst.2,
        worst.3,
        gpu_seconds * 1e3,
    );
    Parity {
        mean,
        max: worst_rel,
        compared,
        worst,
    }
}

pub fn assert_parity(name: &str, p: &Parity) {
    assert!(p.compared > 0, "{name}: nothing compared");
    assert!(
        p.mean <= MEAN_TOLERANCE,
        "{name}: mean relative luminance difference {:.3e} > {MEAN_TOLERANCE}",
        p.mean
    );
    assert!(
        p.max <= PIXEL_TOLERANCE,
        "{name}: pixel ({}, {}) differs by {:.3e} (cpu {:e}, gpu {:e}) > {PIXEL_TOLERANCE}",
        p.worst.0,
        p.worst.1,
        p.max,
        p.worst.2,
        p.worst.3
    );
}

/// [`measure`] for frames of any sky method: the planet's radius `bottom_radius_m` in place
/// of the 4D sky (the same criteria and report).
#[allow(clippy::too_many_arguments)]
pub fn measure_frames(
    name: &str,
    bottom_radius_m: f64,
    settings: &RenderSettings,
    lights: &[Light],
    cpu: &Frame,
    gpu: &Frame,
    gpu_seconds: f64,
) -> Parity {
    let (w, h) = (settings.width, settings.height);
    let mask_mismatches = (cpu.mask.iter().zip(&gpu.mask))
        .filter(|(a, b)| a != b)
        .count();
    assert_eq!(mask_mismatches, 0, "{name}: projection masks differ");
    let prepared = settings.camera.prepare(bottom_radius_m, w, h);
    let near_disk_edge = |x: usize, y: usize| -> bool {
        let (px, py) = (x as f64 + 0.5, y as f64 + 0.5);
        let Some(ray) = prepared.ray(px, py) else {
            return false;
        };
        let footprint = [(1.0, 0.0), (-1.0, 0.0), (0.0, 1.0), (0.0, -1.0)]
            .iter()
            .filter_map(|(dx, dy)| prepared.ray(px + dx, py + dy))
            .map(|n| angle(n.dir, ray.dir))
            .fold(0.0, f64::max);
        lights.iter().filter(|l| l.visible_disk).any(|l| {
            (angle(ray.dir, l.direction) - l.angular_radius_rad).abs()
                < DISK_EDGE_FOOTPRINTS * footprint
        })
    };
    let candidates: Vec<usize> = (0..w * h)
        .filter(|&i| cpu.mask[i] && !near_disk_edge(i % w, i / w))
        .collect();
    let max = (candidates.iter())
        .map(|&i| luminance(&cpu.image.data[i]))
        .fold(0.0, f64::max);
    let floor = max * NEGLIGIBLE;
    let (mut sum, mut compared, mut over_one_percent) = (0.0, 0usize, 0usize);
    let mut worst = (0, 0, 0.0, 0.0);
    let mut worst_rel = 0.0f64;
    for &i in &candidates {
        let (c, g) = (luminance(&cpu.image.data[i]), luminance(&gpu.image.data[i]));
        assert!(g.is_finite(), "{name}: non-finite GPU pixel {i}");
        if c < floor {
            assert!(
                (g - c).abs() <= floor,
                "{name}: pixel {i} is dark on the CPU ({c:e}) but not on the GPU ({g:e})"
            );
            continue;
        }
        let rel = (g - c).abs() / c;
        sum += rel;
        compared += 1;
        over_one_percent += usize::from(rel > 0.01);
        if rel > worst_rel {
            worst_rel = rel;
            worst = (i % w, i / w, c, g);
        }
    }
    let mean = if compared > 0 {
        sum / compared as f64
    } else {
        0.0
    };
    eprintln!(
        "{name}: {w}×{h}, {compared} of {} pixels compared; mean rel {mean:.2e}, max rel {worst_rel:.2e} at ({}, {}) cpu {:.5e} gpu {:.5e}; {over_one_percent} over 1 %; GPU frame {:.0} ms",
        w * h,
        worst.0,
        worst.1,
        worst.2,
        worst.3,
        gpu_seconds * 1e3,
    );
    Parity {
        mean,
        max: worst_rel,
        compared,
        worst,
    }
}

/// The CPU's frame of the clear sky with a shadowed length per pixel (m, rows from the top),
/// for any sky method: each pixel's ray through the method's view with `Shadow::Length`, the
/// ground sphere in shadow where its length is > 0 (what a GPU frame with
/// `RenderInputs::shadow_lengths` draws).
pub fn shadow_length_frame(
    sky: &dyn firmament::sky::SkyMethod,
    sun: &Light,
    settings: &RenderSettings,
    lengths: &[f32],
) -> Frame {
    use firmament::scene::{Ray, Sphere, Surface};
    use firmament::sky::Shadow;
    let model = sky.model();
    let (w, h, n) = (settings.width, settings.height, model.channels());
    let prepared = settings.camera.prepare(model.bottom_radius_m, w, h);
    let observer = Vec3::new(0.0, 0.0, model.bottom_radius_m + settings.camera.altitude_m);
    let view = sky.view(observer, sun);
    let ground = Sphere::ground(model);
    let colour = model.colour_matrix();
    let mut image = firmament::io::ImageRgbF32::new(w, h);
    let mut mask = vec![false; w * h];
    let (mut l, mut t) = (vec![0.0; n], vec![0.0; n]);
    let (mut direct, mut e_sky) = (vec![0.0; n], vec![0.0; n]);
    for y in 0..h {
        for x in 0..w {
            let Some(ray) = prepared.ray(x as f64 + 0.5, y as f64 + 0.5) else {
                continue;
            };
            let length = lengths[y * w + x] as f64;
            let shadow = Shadow::Length(length);
            match ground.intersect(&Ray { ..ray }, f64::INFINITY) {
                Some(hit) => {
                    view.sky_radiance_to_point(hit.position, shadow, &mut l, &mut t);
                    view.sun_and_sky_irradiance(hit.position, hit.normal, &mut direct, &mut e_sky);
                    if length > 0.0 {
                        direct.iter_mut().for_each(|v| *v = 0.0);
                    }
                    for k in 0..n {
                        l[k] += model.ground_albedo[k] / std::f64::consts::PI
                            * (direct[k] + e_sky[k])
                            * t[k];
                    }
                }
                None => view.sky_radiance(ray.dir, shadow, &mut l, &mut []),
            }
            image.data[y * w + x] = colour.to_srgb(&l).map(|v| v as f32);
            mask[y * w + x] = true;
        }
    }
    Frame { image, mask }
}

/// The texels of a `width`×`height` `Rgba32Float` texture (usage COPY_SRC), rows from the
/// top (waits for the device).
pub fn read_rgba32_texture(
    ctx: &GpuContext,
    texture: &wgpu::Texture,
    width: usize,
    height: usize,
) -> Vec<[f32; 4]> {
    let device = ctx.device();
    let row = (16 * width as u32).div_ceil(256) * 256;
    let staging = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("texture readback"),
        size: (row * height as u32) as u64,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut encoder = device.create_command_encoder(&Default::default());
    encoder.copy_texture_to_buffer(
        texture.as_image_copy(),
        wgpu::TexelCopyBufferInfo {
            buffer: &staging,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(row),
                rows_per_image: Some(height as u32),
            },
        },
        wgpu::Extent3d {
            width: width as u32,
            height: height as u32,
            depth_or_array_layers: 1,
        },
    );
    ctx.queue().submit([encoder.finish()]);
    staging
        .slice(..)
        .map_async(wgpu::MapMode::Read, |r| r.expect("map"));
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .expect("poll");
    let bytes = staging
        .slice(..)
        .get_mapped_range()
        .expect("mapped")
        .to_vec();
    let mut out = Vec::with_capacity(width * height);
    for y in 0..height {
        for x in 0..width {
            let at = y * row as usize + 16 * x;
            out.push(std::array::from_fn(|c| {
                f32::from_le_bytes(bytes[at + 4 * c..at + 4 * c + 4].try_into().unwrap())
            }));
        }
    }
    out
}

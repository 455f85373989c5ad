//! The GPU API as an engine holds it: its own device handed to firmament, frames recorded
//! into its own encoder and written into its own textures, read back by itself; several
//! lights; per-pixel shadowed lengths. Each frame is compared with the CPU as the parity
//! tests do (common::measure: mean relative luminance difference ≤ 1 %, no pixel above 5 %).

mod common;

use firmament::math::Vec3;
use firmament::render::{render, Frame, RenderSettings};
use firmament::scene::{sun_direction, Light, Projection, Ray, Scene, Sphere, Surface};
use firmament::sky::bruneton4d::Bruneton4d;
use firmament::sky::{Shadow, SkyMethod};
use firmament_gpu::{GpuContext, GpuRenderer, GpuSky, RenderInputs, RenderTarget};

use common::*;

/// A device of the caller's own, as an engine opens it (any adapter with compute shaders,
/// hardware first); None outside CI when there is none.
fn own_device() -> Option<(wgpu::Device, wgpu::Queue, wgpu::AdapterInfo)> {
    let desc = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
    let backends = desc.backends;
    let instance = wgpu::Instance::new(desc);
    let mut adapters: Vec<wgpu::Adapter> =
        pollster::block_on(instance.enumerate_adapters(backends))
            .into_iter()
            .filter(|a| {
                a.get_downlevel_capabilities()
                    .flags
                    .contains(wgpu::DownlevelFlags::COMPUTE_SHADERS)
            })
            .collect();
    adapters.sort_by_key(|a| a.get_info().device_type == wgpu::DeviceType::Cpu);
    let Some(adapter) = adapters.into_iter().next() else {
        assert!(
            std::env::var_os("CI").is_none(),
            "CI is set but no GPU adapter was found"
        );
        eprintln!("skipped: no GPU adapter");
        return None;
    };
    let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
        label: Some("engine"),
        required_features: wgpu::Features::empty(),
        required_limits: adapter.limits(),
        experimental_features: wgpu::ExperimentalFeatures::default(),
        memory_hints: wgpu::MemoryHints::Performance,
        trace: wgpu::Trace::Off,
    }))
    .expect("device");
    Some((device, queue, adapter.get_info()))
}

/// Read a `width`×`height` texture of 4-channel float texels (`bytes` per texel) back
/// through the caller's own staging buffer.
fn read_texture(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    texture: &wgpu::Texture,
    width: u32,
    height: u32,
    bytes: u32,
) -> Vec<[f32; 4]> {
    let row = (width * bytes).div_ceil(256) * 256;
    let staging = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("engine readback"),
        size: (row * height) as u64,
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
                rows_per_image: Some(height),
            },
        },
        wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        },
    );
    queue.submit([encoder.finish()]);
    staging
        .slice(..)
        .map_async(wgpu::MapMode::Read, |r| r.expect("map"));
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .expect("poll");
    let data = staging
        .slice(..)
        .get_mapped_range()
        .expect("mapped")
        .to_vec();
    let mut out = Vec::with_capacity((width * height) as usize);
    for y in 0..height {
        for x in 0..width {
            let at = (y * row + x * bytes) as usize;
            let texel: [f32; 4] = std::array::from_fn(|c| {
                if bytes == 16 {
                    let i = at + 4 * c;
                    f32::from_le_bytes(data[i..i + 4].try_into().unwrap())
                } else {
                    let i = at + 2 * c;
                    half_to_f32(u16::from_le_bytes(data[i..i + 2].try_into().unwrap()))
                }
            });
            out.push(texel);
        }
    }
    out
}

/// IEEE 754 binary16 to f32 (finite values and zero; the tests write no others).
fn half_to_f32(h: u16) -> f32 {
    let sign = if h & 0x8000 != 0 { -1.0 } else { 1.0 };
    let exponent = ((h >> 10) & 0x1f) as i32;
    let mantissa = (h & 0x3ff) as f32;
    if exponent == 0 {
        sign * mantissa * 2f32.powi(-24)
    } else {
        sign * (1.0 + mantissa / 1024.0) * 2f32.powi(exponent - 15)
    }
}

fn frame_of(texels: &[[f32; 4]], width: usize, height: usize) -> Frame {
    let mut image = firmament::io::ImageRgbF32::new(width, height);
    let mut mask = vec![false; width * height];
    for ((p, m), t) in image.data.iter_mut().zip(&mut mask).zip(texels) {
        *p = [t[0], t[1], t[2]];
        *m = t[3] > 0.5;
    }
    Frame { image, mask }
}

#[test]
fn an_engine_device_renders_into_its_own_texture() {
    let Some((device, queue, info)) = own_device() else {
        return;
    };
    let _guard = serial();
    let ctx = GpuContext::from_device(device.clone(), queue.clone(), info);
    let renderer = GpuRenderer::new(&ctx).unwrap();
    let sky = earth_rgb();
    let gpu_sky = GpuSky::from_sky(&ctx, sky).unwrap();
    let cam = camera(Projection::Perspective, 2.0, 135.0, 20.0, 90.0);
    let (w, h) = (96u32, 64u32);
    let settings = RenderSettings {
        camera: &cam,
        width: w as usize,
        height: h as usize,
        white_balance: false,
    };
    // Rgba32Float with the sun's disk; Rgba16Float without (the disk's 1e8 cd/m² exceeds
    // half floats).
    for (format, bytes, disk) in [
        (wgpu::TextureFormat::Rgba32Float, 16, true),
        (wgpu::TextureFormat::Rgba16Float, 8, false),
    ] {
        let scene = Scene::clear_sky(sky, sun_direction(35.0, 135.0), disk);
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("engine frame"),
            size: wgpu::Extent3d {
                width: w,
                height: h,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage: wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let view = texture.create_view(&Default::default());
        let mut encoder = device.create_command_encoder(&Default::default());
        renderer
            .encode(
                &ctx,
                &mut encoder,
                &gpu_sky,
                &scene.lights,
                &settings,
                RenderTarget::Texture(&view, format),
                RenderInputs::default(),
            )
            .unwrap();
        queue.submit([encoder.finish()]);
        let texels = read_texture(&device, &queue, &texture, w, h, bytes);
        let gpu_frame = frame_of(&texels, w as usize, h as usize);
        let cpu_frame = render(&scene, &settings, &|_| {}, None).unwrap();
        let name = format!("engine texture {format:?}");
        let p = measure(
            &name,
            sky,
            &settings,
            &scene.lights,
            &cpu_frame,
            &gpu_frame,
            0.0,
        );
        assert_parity(&name, &p);
    }
}

#[test]
fn two_lights_match_the_cpu() {
    let Some(gpu) = gpu("two_lights_match_the_cpu") else {
        return;
    };
    let _guard = serial();
    let sky = earth_rgb();
    let mut scene = Scene::clear_sky(sky, sun_direction(60.0, 200.0), true);
    // A second, dimmer and bluer light low in the north-east, its disk drawn.
    let mut second = Light::sun(&sky.model, sun_direction(85.0, 40.0), true);
    for (k, e) in second.irradiance.iter_mut().enumerate() {
        *e *= [0.1, 0.2, 0.4][k];
    }
    scene.lights.push(second);
    let cam = camera(Projection::Fisheye, 2.0, 0.0, 0.0, 60.0);
    let settings = RenderSettings {
        camera: &cam,
        width: 96,
        height: 96,
        white_balance: false,
    };
    let cpu_frame = render(&scene, &settings, &|_| {}, None).unwrap();
    let gpu_sky = GpuSky::from_sky(&gpu.ctx, sky).unwrap();
    let gpu_frame = gpu
        .renderer
        .render(&gpu.ctx, &gpu_sky, &scene.lights, &settings)
        .unwrap();
    let p = measure(
        "two lights",
        sky,
        &settings,
        &scene.lights,
        &cpu_frame,
        &gpu_frame,
        0.0,
    );
    assert_parity("two lights", &p);
    // The second light shows: the frame differs from the sun's alone.
    let sun_only = render(
        &Scene::clear_sky(sky, sun_direction(60.0, 200.0), true),
        &settings,
        &|_| {},
        None,
    )
    .unwrap();
    let brighter = cpu_frame
        .image
        .data
        .iter()
        .zip(&sun_only.image.data)
        .filter(|(a, b)| luminance(a) > 1.01 * luminance(b))
        .count();
    assert!(
        brighter > 1000,
        "{brighter} pixels brighter with the second light"
    );
}

/// The CPU's expected frame with a shadowed length per pixel: each pixel's ray through the
/// sky method's view with `Shadow::Length`, the ground in shadow where its length is > 0.
fn cpu_frame_with_shadow_lengths(
    sky: &Bruneton4d,
    sun: &Light,
    settings: &RenderSettings,
    lengths: &[f32],
) -> Frame {
    let model = &sky.model;
    let (w, h) = (settings.width, settings.height);
    let prepared = settings.camera.prepare(model.bottom_radius_m, w, h);
    let observer = Vec3::new(0.0, 0.0, model.bottom_radius_m + settings.camera.altitude_m);
    let view = sky.view(observer, sun);
    let ground = Sphere::ground(model);
    let colour = model.colour_matrix();
    let mut image = firmament::io::ImageRgbF32::new(w, h);
    let mut mask = vec![false; w * h];
    for y in 0..h {
        for x in 0..w {
            let Some(ray) = prepared.ray(x as f64 + 0.5, y as f64 + 0.5) else {
                continue;
            };
            let length = lengths[y * w + x] as f64;
            let shadow = Shadow::Length(length);
            let (mut l, mut t, mut direct, mut e_sky) = ([0.0; 3], [0.0; 3], [0.0; 3], [0.0; 3]);
            match ground.intersect(&Ray { ..ray }, f64::INFINITY) {
                Some(hit) => {
                    view.sky_radiance_to_point(hit.position, shadow, &mut l, &mut t);
                    view.sun_and_sky_irradiance(hit.position, hit.normal, &mut direct, &mut e_sky);
                    if length > 0.0 {
                        direct = [0.0; 3];
                    }
                    for k in 0..3 {
                        l[k] += model.ground_albedo[k] / std::f64::consts::PI
                            * (direct[k] + e_sky[k])
                            * t[k];
                    }
                }
                None => view.sky_radiance(ray.dir, shadow, &mut l, &mut []),
            }
            let c = colour.to_srgb(&l);
            image.data[y * w + x] = c.map(|v| v as f32);
            mask[y * w + x] = true;
        }
    }
    Frame { image, mask }
}

#[test]
fn shadowed_lengths_per_pixel_match_the_cpu() {
    let Some(gpu) = gpu("shadowed_lengths_per_pixel_match_the_cpu") else {
        return;
    };
    let _guard = serial();
    let sky = earth_rgb();
    let sun = Light::sun(&sky.model, sun_direction(70.0, 180.0), false);
    // From 300 m, looking south-east across the horizon: sky and ground.
    let cam = camera(Projection::Perspective, 300.0, 150.0, 2.0, 60.0);
    let (w, h) = (96usize, 48usize);
    let settings = RenderSettings {
        camera: &cam,
        width: w,
        height: h,
        white_balance: false,
    };
    // Shadowed lengths in bands: none, 2 km, 8 km and 40 km, left to right.
    let lengths: Vec<f32> = (0..w * h)
        .map(|i| [0.0, 2000.0, 8000.0, 40_000.0][(i % w) * 4 / w])
        .collect();
    let texture = gpu.ctx.device().create_texture(&wgpu::TextureDescriptor {
        label: Some("shadowed lengths"),
        size: wgpu::Extent3d {
            width: w as u32,
            height: h as u32,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::R32Float,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    gpu.ctx.queue().write_texture(
        texture.as_image_copy(),
        bytemuck::cast_slice(&lengths),
        wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(4 * w as u32),
            rows_per_image: Some(h as u32),
        },
        wgpu::Extent3d {
            width: w as u32,
            height: h as u32,
            depth_or_array_layers: 1,
        },
    );
    let view = texture.create_view(&Default::default());
    let gpu_sky = GpuSky::from_sky(&gpu.ctx, sky).unwrap();
    let inputs = RenderInputs {
        shadow_lengths: Some(&view),
        ..RenderInputs::default()
    };
    let gpu_frame = gpu
        .renderer
        .render_with(
            &gpu.ctx,
            &gpu_sky,
            std::slice::from_ref(&sun),
            &settings,
            inputs,
        )
        .unwrap();
    let cpu_frame = cpu_frame_with_shadow_lengths(sky, &sun, &settings, &lengths);
    let p = measure(
        "shadowed lengths",
        sky,
        &settings,
        std::slice::from_ref(&sun),
        &cpu_frame,
        &gpu_frame,
        0.0,
    );
    assert_parity("shadowed lengths", &p);
    // The shafts show: a longer shadow darkens the same kind of pixel.
    let band_mean = |band: usize, row: usize| {
        let xs = band * w / 4 + 2..(band + 1) * w / 4 - 2;
        xs.map(|x| luminance(&gpu_frame.image.data[row * w + x]))
            .sum::<f64>()
    };
    for row in [5, h - 5] {
        assert!(
            band_mean(0, row) > band_mean(1, row) && band_mean(2, row) > band_mean(3, row),
            "row {row}: {:?}",
            (0..4).map(|b| band_mean(b, row)).collect::<Vec<_>>()
        );
    }
}

//! A frame on the GPU: the CPU benchmark's 1920×1080 perspective view (1.5 km up, sky,
//! ground lit by sun and sky, aerial perspective, sun disk; `earth`, RGB, default tables
//! computed on the CPU), timed with `GpuRenderer::time_render` (median of 5 dispatches),
//! compared with the CPU frame, and optionally written as PNGs (same automatic exposure and
//! ACES curve for both).
//!
//! `cargo run --release -p firmament-gpu --example gpu_render [WIDTHxHEIGHT] [OUT_DIR]`

use std::time::Instant;

use firmament::atmosphere::Atmosphere;
use firmament::render::{self, tonemap, Frame, RenderSettings, ToneCurve};
use firmament::scene::{sun_direction, Camera, Projection, Scene};
use firmament::sky::bruneton4d::{Bruneton4d, TableConfig, Tables};
use firmament::spectrum::Wavelengths;
use firmament_gpu::{GpuContext, GpuRenderer, GpuSky};

fn luminance(p: &[f32; 3]) -> f64 {
    0.2126 * p[0] as f64 + 0.7152 * p[1] as f64 + 0.0722 * p[2] as f64
}

fn write_png(frame: &Frame, ev100: f64, path: &std::path::Path) -> firmament::Result<()> {
    let rgb8 = frame.to_srgb8(
        tonemap::exposure_from_ev100(ev100, ToneCurve::Aces),
        ToneCurve::Aces,
    );
    firmament::io::write_png_srgb8(path, frame.image.width, frame.image.height, &rgb8)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let (width, height) = match args.next() {
        Some(s) => {
            let (w, h) = s.split_once('x').ok_or("size as WIDTHxHEIGHT")?;
            (w.parse()?, h.parse()?)
        }
        None => (1920, 1080),
    };
    let out_dir = args.next().map(std::path::PathBuf::from);

    let model = Atmosphere::earth().resolve(&Wavelengths::rgb())?;
    let start = Instant::now();
    let tables = Tables::compute(&model, &TableConfig::default())?;
    println!(
        "CPU tables (default sizes): {:.1} s",
        start.elapsed().as_secs_f64()
    );
    let sky = Bruneton4d::new(model, tables)?;

    let ctx = GpuContext::new()?;
    println!(
        "adapter: {} ({}, software: {})",
        ctx.adapter_name(),
        ctx.backend(),
        ctx.is_software()
    );
    let start = Instant::now();
    let renderer = GpuRenderer::new(&ctx)?;
    println!(
        "render pipeline creation: {:.1} ms",
        start.elapsed().as_secs_f64() * 1e3
    );
    let start = Instant::now();
    let gpu_sky = GpuSky::from_sky(&ctx, &sky)?;
    println!(
        "table upload: {:.1} ms",
        start.elapsed().as_secs_f64() * 1e3
    );

    let camera = Camera {
        projection: Projection::Perspective,
        altitude_m: 1500.0,
        heading_deg: 200.0,
        pitch_deg: 20.0,
        roll_deg: 0.0,
        fov_deg: 60.0,
    };
    let settings = RenderSettings {
        camera: &camera,
        width,
        height,
        white_balance: false,
    };
    let scene = Scene::clear_sky(&sky, sun_direction(60.0, 200.0), true);

    let timing = renderer.time_render(&ctx, &gpu_sky, &scene.lights, &settings, 5)?;
    println!(
        "{width}×{height} render dispatch: median {:.2} ms over {} frames ({})",
        timing.seconds * 1e3,
        timing.frames,
        timing.method
    );
    let start = Instant::now();
    let gpu = renderer.render(&ctx, &gpu_sky, &scene.lights, &settings)?;
    println!(
        "{width}×{height} frame with readback: {:.2} ms",
        start.elapsed().as_secs_f64() * 1e3
    );
    let start = Instant::now();
    let cpu = render::render(&scene, &settings, &|_| {}, None)?;
    println!(
        "{width}×{height} CPU frame: {:.2} ms",
        start.elapsed().as_secs_f64() * 1e3
    );

    let (mut sum, mut max, mut n) = (0.0, 0.0f64, 0usize);
    for (c, g) in cpu.image.data.iter().zip(&gpu.image.data) {
        let (c, g) = (luminance(c), luminance(g));
        if c > 0.0 {
            let rel = (g - c).abs() / c;
            sum += rel;
            max = max.max(rel);
            n += 1;
        }
    }
    println!(
        "GPU vs CPU luminance over {n} pixels: mean rel {:.2e}, max rel {max:.2e} (sun-disk edge included)",
        sum / n.max(1) as f64
    );

    if let Some(dir) = out_dir {
        std::fs::create_dir_all(&dir)?;
        let ev100 = tonemap::auto_ev100(cpu.log_average_luminance());
        write_png(&gpu, ev100, &dir.join("gpu.png"))?;
        write_png(&cpu, ev100, &dir.join("cpu.png"))?;
        println!("wrote {0}/gpu.png and {0}/cpu.png", dir.display());
    }
    Ok(())
}

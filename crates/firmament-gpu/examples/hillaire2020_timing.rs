//! Hillaire 2020 on the GPU, pass by pass: the transmittance, multiple-scattering and
//! irradiance passes of a build (`HillairePrecomputer::time_passes`) and the sky-view and
//! pixel passes of the CPU benchmark's 1920×1080 perspective frame (1.5 km up, heading
//! 200°, 20° up, 60° field, the sun 60° from the zenith at azimuth 200°;
//! `GpuHillaireRenderer::time_render`), medians of several runs after a warm-up, for
//! `earth` in RGB and spectral (16 wavelengths), default `HillaireConfig` (or, with
//! `extended`, firmament's harmonics(6) and 4 orders, as `--hillaire-harmonics 6
//! --hillaire-orders 4`); timestamp queries where the adapter has them, else the wall clock
//! of each pass alone.
//!
//! `cargo run --release -p firmament-gpu --example hillaire2020_timing [RUNS] [WIDTHxHEIGHT] [extended]`

use std::time::Instant;

use firmament::atmosphere::Atmosphere;
use firmament::render::RenderSettings;
use firmament::scene::{sun_direction, Camera, Light, Projection};
use firmament::sky::hillaire2020::{HillaireConfig, MultipleScatteringModel};
use firmament::spectrum::Wavelengths;
use firmament_gpu::{GpuContext, GpuHillaire, GpuHillaireRenderer, HillairePrecomputer};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let runs: usize = args.next().map_or(Ok(5), |s| s.parse())?;
    let (width, height) = match args.next() {
        Some(s) => {
            let (w, h) = s.split_once('x').ok_or("size as WIDTHxHEIGHT")?;
            (w.parse()?, h.parse()?)
        }
        None => (1920, 1080),
    };
    let config = match args.next().as_deref() {
        Some("extended") => HillaireConfig {
            multiple_scattering_model: MultipleScatteringModel::Harmonics(6),
            multiple_scattering_orders: 4,
            multiple_scattering_directions: (24, 12),
            ..HillaireConfig::default()
        },
        Some(other) => return Err(format!("unknown configuration {other:?} (extended)").into()),
        None => HillaireConfig::default(),
    };
    let ctx = GpuContext::new()?;
    println!(
        "adapter: {} ({}, software: {})",
        ctx.adapter_name(),
        ctx.backend(),
        ctx.is_software()
    );
    let start = Instant::now();
    let precomputer = HillairePrecomputer::new(&ctx)?;
    let renderer = GpuHillaireRenderer::new(&ctx)?;
    println!(
        "pipeline creation: {:.1} ms",
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
    let ms = |s: f64| s * 1e3;
    for (name, wavelengths) in [
        ("rgb", Wavelengths::rgb()),
        ("spectral", Wavelengths::spectral()),
    ] {
        let model = Atmosphere::earth().resolve(&wavelengths)?;
        let passes = precomputer.time_passes(&ctx, &model, &config, runs)?;
        let start = Instant::now();
        let sky = GpuHillaire::compute(&ctx, &precomputer, &model, &config)?;
        let build = start.elapsed().as_secs_f64();
        let lights = [Light::sun(&model, sun_direction(60.0, 200.0), true)];
        let frame = renderer.time_render(&ctx, &sky, &lights, &settings, runs)?;
        println!(
            "earth {name} ({} wavelengths), medians of {runs} runs ({}):\n  transmittance {:.3} ms, multiple scattering {:.3} ms, irradiance {:.3} ms; whole build with the f_ms readback {:.1} ms (wall clock)\n  {width}×{height}: sky view {:.3} ms, frame {:.3} ms",
            model.channels(),
            passes.method,
            ms(passes.transmittance_s),
            ms(passes.multiple_scattering_s),
            ms(passes.irradiance_s),
            ms(build),
            ms(frame.sky_view_s),
            ms(frame.frame_s),
        );
    }
    Ok(())
}

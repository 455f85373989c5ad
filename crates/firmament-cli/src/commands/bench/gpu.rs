//! GPU timings for `firmament bench`: the precomputation and the 1080p frame on the adapter
//! wgpu opens (`firmament_gpu`).

use std::time::Instant;

use anyhow::Result;
use firmament_gpu::lut::Precomputer;
use firmament_gpu::{GpuContext, GpuRenderer, GpuSky};
use serde_json::json;

use super::cpu as render_bench;
use super::{median, time_runs, BenchArgs};
use crate::backend::{gpu_failure, wait_idle};

/// How the GPU precompute is timed (the `gpu_precompute_timing_method` key).
pub const PRECOMPUTE_METHOD: &str = "wall clock per run: GpuSky::precompute (atmosphere upload, table buffer allocation, encoding, submit) until the device is idle; tables left on the device (no readback); pipelines compiled once beforehand (gpu_pipeline_creation_s)";

/// The GPU keys, null (not measured).
pub const KEYS: [&str; 13] = [
    "gpu_adapter",
    "gpu_backend",
    "gpu_adapter_software",
    "gpu_runs",
    "gpu_pipeline_creation_s",
    "gpu_precompute_s",
    "gpu_precompute_timing_method",
    "gpu_precompute_spectral_s",
    "gpu_frame_1080p_perspective_s",
    "gpu_frame_timing_method",
    "gpu_frame_1080p_perspective_with_readback_s",
    "gpu_precompute_wavelengths",
    "gpu_precompute_orders",
];

/// Add the GPU measurements to the benchmark result; `progress` prints a line per step.
pub fn extend(
    result: &mut serde_json::Value,
    args: &BenchArgs,
    ctx: &GpuContext,
    progress: bool,
) -> Result<()> {
    let runs = args.gpu_runs.unwrap_or(args.runs).max(1);
    let model = args.atmosphere.model()?;
    let config = args.atmosphere.table_config()?;
    let step = |what: &str| {
        if progress {
            eprintln!("gpu: {what}");
        }
    };
    result["gpu_adapter"] = json!(ctx.adapter_name());
    result["gpu_backend"] = json!(ctx.backend());
    result["gpu_adapter_software"] = json!(ctx.is_software());
    result["gpu_runs"] = json!(runs);

    step("compiling the precomputation pipelines");
    let t = Instant::now();
    let precomputer =
        Precomputer::new(ctx).map_err(|e| gpu_failure("compiling the precomputation", e))?;
    result["gpu_pipeline_creation_s"] = json!(t.elapsed().as_secs_f64());

    let precompute = |model: &firmament::atmosphere::Model| -> Result<GpuSky> {
        let sky = GpuSky::precompute(ctx, &precomputer, model, &config)
            .map_err(|e| gpu_failure("precomputing the tables", e))?;
        wait_idle(ctx, "precomputing the tables")?;
        Ok(sky)
    };
    step(&format!(
        "precompute, {} wavelengths, {} orders, {runs} runs",
        model.channels(),
        config.orders
    ));
    let mut sky = None;
    let times = time_runs(runs, || {
        sky = Some(precompute(&model)?);
        Ok(())
    })?;
    let sky = sky.expect("at least one run");
    result["gpu_precompute_s"] = json!(median(times));
    result["gpu_precompute_wavelengths"] = json!(model.channels());
    result["gpu_precompute_orders"] = json!(config.orders);
    result["gpu_precompute_timing_method"] = json!(PRECOMPUTE_METHOD);

    if args.spectral {
        let mut spectral_args = args.atmosphere.clone();
        spectral_args.wavelengths = "spectral".into();
        let spectral_model = spectral_args.model()?;
        step("precompute, spectral");
        let times = time_runs(runs.min(3), || precompute(&spectral_model).map(|_| ()))?;
        result["gpu_precompute_spectral_s"] = json!(median(times));
    }

    // The CPU's 1080p frame, from the tables just precomputed on the GPU.
    let renderer = GpuRenderer::new(ctx).map_err(|e| gpu_failure("compiling the renderer", e))?;
    let camera = render_bench::camera_1080p();
    let settings = render_bench::settings(&camera, 1920, 1080);
    step(&format!("1920×1080 frame, 1 + {runs} frames"));
    let lights = [firmament::scene::Light::sun(
        &model,
        render_bench::sun(),
        true,
    )];
    let timing = renderer
        .time_render(ctx, &sky, &lights, &settings, runs)
        .map_err(|e| gpu_failure("timing frames", e))?;
    result["gpu_frame_1080p_perspective_s"] = json!(timing.seconds);
    result["gpu_frame_timing_method"] = json!(format!(
        "{}: the render dispatch alone, median of {} frames after one warm-up (no upload, readback or tone mapping)",
        timing.method, timing.frames
    ));
    step("1920×1080 frame with readback");
    let times = time_runs(runs, || {
        let frame = renderer
            .render(ctx, &sky, &lights, &settings)
            .map_err(|e| gpu_failure("rendering", e))?;
        let _ = frame.to_srgb8(1e-4, firmament::render::ToneCurve::Aces);
        Ok(())
    })?;
    result["gpu_frame_1080p_perspective_with_readback_s"] = json!(median(times));
    Ok(())
}

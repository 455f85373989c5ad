//! GPU timings for `firmament bench`: the precomputation and the 1080p frame on the adapter
//! wgpu opens. With `crate::backend`, the only place that calls `firmament_gpu`.

use std::time::Instant;

use anyhow::Result;
use firmament::atmosphere::Model;
use firmament::render::ToneCurve;
use firmament::scene::Light;
use firmament::sky::bruneton4d::TableConfig;
use firmament_gpu::Precomputer;
use firmament_gpu::{GpuRenderer, GpuSky};

use super::report::GpuTimings;
use super::scenes;
use super::timing::{median, time_runs};
use crate::backend::{gpu_failure, Gpu};

/// How the GPU precompute is timed (the `gpu_precompute_timing_method` key).
const PRECOMPUTE_METHOD: &str = "wall clock per run: GpuSky::precompute (atmosphere upload, table buffer allocation, encoding, submit) until the device is idle; tables left on the device (no readback); pipelines compiled once beforehand (gpu_pipeline_creation_s)";

/// Time the precomputation of `model` (and of `spectral`, at most 3 runs, when given) and
/// the 1080p frame from those tables, `runs` times each; `progress` prints a line per step
/// on stderr.
pub fn timings(
    gpu: &Gpu,
    model: &Model,
    config: &TableConfig,
    spectral: Option<&Model>,
    runs: usize,
    progress: bool,
) -> Result<GpuTimings> {
    let ctx = &gpu.ctx;
    let step = |what: &str| {
        if progress {
            eprintln!("gpu: {what}");
        }
    };
    let mut timings = GpuTimings {
        gpu_adapter: Some(ctx.adapter_name().to_string()),
        gpu_backend: Some(ctx.backend()),
        gpu_adapter_software: Some(ctx.is_software()),
        gpu_runs: Some(runs),
        ..Default::default()
    };

    step("compiling the precomputation pipelines");
    let started = Instant::now();
    let precomputer =
        Precomputer::new(ctx).map_err(|e| gpu_failure("compiling the precomputation", e))?;
    timings.gpu_pipeline_creation_s = Some(started.elapsed().as_secs_f64());

    let precompute = |model: &Model| -> Result<GpuSky> {
        let sky = GpuSky::precompute(ctx, &precomputer, model, config)
            .map_err(|e| gpu_failure("precomputing the tables", e))?;
        gpu.wait_idle("precomputing the tables")?;
        Ok(sky)
    };
    step(&format!(
        "precompute, {} wavelengths, {} orders, {runs} runs",
        model.channels(),
        config.orders
    ));
    let mut sky = None;
    let seconds = time_runs(runs, || {
        sky = Some(precompute(model)?);
        Ok(())
    })?;
    let sky = sky.expect("at least one run");
    timings.gpu_precompute_s = Some(median(seconds));
    timings.gpu_precompute_wavelengths = Some(model.channels());
    timings.gpu_precompute_orders = Some(config.orders);
    timings.gpu_precompute_timing_method = Some(PRECOMPUTE_METHOD.to_string());

    if let Some(spectral) = spectral {
        step("precompute, spectral");
        let seconds = time_runs(runs.min(3), || precompute(spectral).map(|_| ()))?;
        timings.gpu_precompute_spectral_s = Some(median(seconds));
    }

    // The CPU's 1080p frame, from the tables just precomputed on the GPU.
    let renderer = GpuRenderer::new(ctx).map_err(|e| gpu_failure("compiling the renderer", e))?;
    let frame = scenes::perspective_1080p();
    let settings = frame.settings();
    step(&format!(
        "{}×{} frame, 1 + {runs} frames",
        frame.width, frame.height
    ));
    let lights = [Light::sun(model, scenes::sun(), true)];
    let timing = renderer
        .time_render(ctx, &sky, &lights, &settings, runs)
        .map_err(|e| gpu_failure("timing frames", e))?;
    timings.gpu_frame_1080p_perspective_s = Some(timing.seconds);
    timings.gpu_frame_timing_method = Some(format!(
        "{}: the render dispatch alone, median of {} frames after one warm-up (no upload, readback or tone mapping)",
        timing.method, timing.frames
    ));
    step(&format!(
        "{}×{} frame with readback",
        frame.width, frame.height
    ));
    let seconds = time_runs(runs, || {
        let image = renderer
            .render(ctx, &sky, &lights, &settings)
            .map_err(|e| gpu_failure("rendering", e))?;
        let _ = image.to_srgb8(1e-4, ToneCurve::Aces);
        Ok(())
    })?;
    timings.gpu_frame_1080p_perspective_with_readback_s = Some(median(seconds));
    Ok(timings)
}

//! GPU timings for `firmament bench`: the precomputation and the 1080p frame on the adapter
//! wgpu opens. With `crate::backend`, the only place that calls `firmament_gpu`.

use std::time::Instant;

use anyhow::Result;
use firmament::atmosphere::Model;
use firmament::math::Vec3;
use firmament::render::{RenderSettings, Shader, ToneCurve};
use firmament::scene::{sun_direction, Light, Scene};
use firmament::sky::bruneton4d::{Bruneton4d, TableConfig};
use firmament_gpu::Precomputer;
use firmament_gpu::{GpuRenderer, GpuSky, GpuTerrain, RenderInputs};

use super::clouds::CloudFrame;
use super::report::GpuTimings;
use super::scenes;
use super::timing::{median, time_runs};
use crate::backend::{gpu_failure, Gpu};

/// How the GPU precompute is timed (the `gpu_precompute_timing_method` key).
const PRECOMPUTE_METHOD: &str = "wall clock per run: GpuSky::precompute (atmosphere upload, table buffer allocation, encoding, submit) until the device is idle; tables left on the device (no readback); pipelines compiled once beforehand (gpu_pipeline_creation_s)";

/// Time the precomputation of `model` (and of `spectral`, at most 3 runs, when given) and
/// the 1080p frames from those tables (the cloudy one when `clouds`), `runs` times each;
/// `progress` prints a line per step on stderr.
pub fn timings(
    gpu: &Gpu,
    model: &Model,
    config: &TableConfig,
    spectral: Option<&Model>,
    runs: usize,
    clouds: bool,
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

    // The CPU's parts of the terrain and cloud frames (shadow fields and maps, the air's
    // light) read the GPU's tables.
    let tables = sky
        .tables()
        .read_back(ctx, model, config)
        .map_err(|e| gpu_failure("reading the tables back", e))?;
    let cpu_sky = Bruneton4d::new(model.clone(), tables)?;
    step("1920×1080 terrain frame (the default scene)");
    let (dispatch, whole) = terrain_timings(gpu, &renderer, &sky, &cpu_sky, runs)?;
    timings.gpu_frame_1080p_terrain_s = Some(dispatch);
    timings.gpu_frame_1080p_terrain_with_cpu_parts_s = Some(whole);
    if clouds {
        step("1920×1080 cloudy frame (scenes/clouds-cumulus-noon.toml)");
        let frame = CloudFrame::new(&cpu_sky)?;
        let (dispatch, whole) =
            super::clouds::gpu_seconds(gpu, &renderer, &sky, &cpu_sky, &frame, runs)?;
        timings.gpu_frame_1080p_clouds_s = Some(dispatch);
        timings.gpu_frame_1080p_clouds_with_cpu_parts_s = Some(whole);
    }
    Ok(timings)
}

/// The default scene's frame on the GPU (`cpu_frame_1080p_terrain_s`'s): the dispatch alone
/// (median of `runs` after a warm-up), and the whole frame with the parts the CPU computes
/// for it each time (the sun's shadow field, the air volume from the tables read back,
/// the upload), the readback and the tone mapping.
fn terrain_timings(
    gpu: &Gpu,
    renderer: &GpuRenderer,
    sky: &GpuSky,
    cpu_sky: &Bruneton4d,
    runs: usize,
) -> Result<(f64, f64)> {
    let ctx = &gpu.ctx;
    let model = &cpu_sky.model;
    let default = firmament::scene::SceneFile::default();
    let terrain = default
        .build_terrain(model)?
        .expect("the default scene has a terrain");
    let camera = default.camera_over(Some(&terrain), model.bottom_radius_m);
    let settings = RenderSettings {
        camera: &camera,
        width: 1920,
        height: 1080,
        white_balance: false,
    };
    let sun = sun_direction(default.sun.zenith_deg, default.sun.azimuth_deg);
    let lights = [Light::sun(model, sun, true)];
    let observer = Vec3::new(0.0, 0.0, model.bottom_radius_m + camera.altitude_m);
    let upload = || -> Result<GpuTerrain> {
        // Without its shadow fields, so that each upload computes them as a frame would.
        let terrain = terrain.clone_without_shadows();
        let mut scene = Scene::clear_sky(cpu_sky, sun, true);
        scene.add_terrain(&terrain, terrain.radius_m);
        let shader = Shader::new(&scene, observer)?;
        GpuTerrain::new(ctx, sky, &terrain, &shader)
            .map_err(|e| gpu_failure("uploading the terrain", e))
    };
    dispatch_and_whole(gpu, renderer, sky, &lights, &settings, runs, upload, |t| {
        RenderInputs {
            terrain: Some(t),
            ..RenderInputs::default()
        }
    })
}

/// A frame whose inputs the CPU prepares and uploads (`upload`; `inputs` says what they
/// are to the renderer): the render dispatch alone (median of `runs` after a warm-up,
/// timestamp queries on a hardware adapter), and the whole frame (at most 3 runs): the
/// upload with its CPU parts, the dispatch, the readback and the tone mapping.
#[allow(clippy::too_many_arguments)]
pub fn dispatch_and_whole<T>(
    gpu: &Gpu,
    renderer: &GpuRenderer,
    sky: &GpuSky,
    lights: &[Light],
    settings: &RenderSettings,
    runs: usize,
    upload: impl Fn() -> Result<T>,
    inputs: impl for<'a> Fn(&'a T) -> RenderInputs<'a>,
) -> Result<(f64, f64)> {
    let ctx = &gpu.ctx;
    let uploaded = upload()?;
    let dispatch = renderer
        .time_render_with(ctx, sky, lights, settings, inputs(&uploaded), runs)
        .map_err(|e| gpu_failure("timing frames", e))?;
    let seconds = time_runs(runs.clamp(1, 3), || {
        let uploaded = upload()?;
        let image = renderer
            .render_with(ctx, sky, lights, settings, inputs(&uploaded))
            .map_err(|e| gpu_failure("rendering", e))?;
        let _ = image.to_srgb8(1e-4, ToneCurve::Aces);
        Ok(())
    })?;
    Ok((dispatch.seconds, median(seconds)))
}

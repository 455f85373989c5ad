//! GPU timings of the fast sky methods for `firmament bench`: Hillaire 2020's passes and its
//! 1080p benchmark frame (sky view, pixels), and the 3D table's frame from the CPU's tables
//! uploaded.

use anyhow::Result;
use firmament::atmosphere::Model;
use firmament::scene::Light;
use firmament::sky::elek3d::{Elek3d, Elek3dConfig};
use firmament::sky::hillaire2020::HillaireConfig;
use firmament_gpu::elek3d::{GpuElek3d, GpuElek3dRenderer};
use firmament_gpu::hillaire2020::{GpuHillaire, GpuHillaireRenderer, HillairePrecomputer};

use super::report::GpuMethods;
use super::scenes;
use crate::backend::{gpu_failure, Gpu};

/// Hillaire 2020 on the GPU: each pass of a build (median of `runs`), then the 1080p
/// benchmark frame's sky-view and pixels' passes, into `out`.
pub fn hillaire_timings(gpu: &Gpu, model: &Model, runs: usize, out: &mut GpuMethods) -> Result<()> {
    let ctx = &gpu.ctx;
    let config = HillaireConfig::default();
    let precomputer = HillairePrecomputer::new(ctx)
        .map_err(|e| gpu_failure("compiling Hillaire 2020's passes", e))?;
    let passes = precomputer
        .time_passes(ctx, model, &config, runs)
        .map_err(|e| gpu_failure("timing Hillaire 2020's passes", e))?;
    let sky = GpuHillaire::compute(ctx, &precomputer, model, &config)
        .map_err(|e| gpu_failure("Hillaire 2020's tables", e))?;
    let renderer = GpuHillaireRenderer::new(ctx)
        .map_err(|e| gpu_failure("compiling Hillaire 2020's renderer", e))?;
    let frame = scenes::perspective_1080p();
    let lights = [Light::sun(model, scenes::sun(), true)];
    let timing = renderer
        .time_render(ctx, &sky, &lights, &frame.settings(), runs)
        .map_err(|e| gpu_failure("timing Hillaire 2020's frames", e))?;
    out.gpu_hillaire_transmittance_s = Some(passes.transmittance_s);
    out.gpu_hillaire_multiple_scattering_s = Some(passes.multiple_scattering_s);
    out.gpu_hillaire_irradiance_s = Some(passes.irradiance_s);
    out.gpu_hillaire_sky_view_s = Some(timing.sky_view_s);
    out.gpu_hillaire_frame_1080p_perspective_s = Some(timing.frame_s);
    out.gpu_hillaire_timing_method = Some(format!(
        "passes: {}, median of {}; frame: {}, median of {} after one warm-up",
        passes.method, passes.runs, timing.method, timing.frames
    ));
    Ok(())
}

/// The 3D table's 1080p benchmark frame on the GPU (the compute pass: the per-view slice and
/// the pixels), from the CPU's tables uploaded, into `out`.
pub fn elek3d_timings(gpu: &Gpu, model: &Model, runs: usize, out: &mut GpuMethods) -> Result<()> {
    let ctx = &gpu.ctx;
    let cpu = Elek3d::compute(model.clone(), &Elek3dConfig::default())?;
    let sky =
        GpuElek3d::from_sky(ctx, &cpu).map_err(|e| gpu_failure("uploading the 3D tables", e))?;
    let renderer = GpuElek3dRenderer::new(ctx)
        .map_err(|e| gpu_failure("compiling the 3D tables' renderer", e))?;
    let frame = scenes::perspective_1080p();
    let lights = [Light::sun(model, scenes::sun(), true)];
    let timing = renderer
        .time_render(ctx, &sky, &lights, &frame.settings(), runs)
        .map_err(|e| gpu_failure("timing the 3D tables' frames", e))?;
    out.gpu_elek3d_frame_1080p_perspective_s = Some(timing.seconds);
    Ok(())
}

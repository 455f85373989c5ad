//! CPU timings for `firmament bench`: the precomputation of the tables (with the seconds of
//! each stage), the renderer's frames from precomputed tables, and the reference path
//! tracer's throughput.

use std::collections::BTreeMap;
use std::sync::Mutex;
use std::time::Instant;

use anyhow::Result;
use firmament::atmosphere::Model;
use firmament::math::Vec3;
use firmament::reference::{self, ReferenceSettings};
use firmament::render::{self, ToneCurve};
use firmament::scene::sky_lights::sources_of;
use firmament::scene::{sun_direction, Scene};
use firmament::sky::bruneton4d::precompute::precompute;
use firmament::sky::bruneton4d::{Bruneton4d, TableConfig};

use super::report::{CpuFrames, CpuPrecompute, CpuReference};
use super::scenes::{self, BenchFrame};
use super::timing::{median, time_runs};

/// Median seconds of the precomputation over `runs`, one more run for the stages, and the
/// `spectral` model's precomputation (at most 3 runs) when given.
pub fn precompute_timings(
    model: &Model,
    config: &TableConfig,
    runs: usize,
    spectral: Option<&Model>,
) -> Result<CpuPrecompute> {
    let seconds = time_runs(runs, || {
        precompute(model, config, &|_, _| {}, None)?;
        Ok(())
    })?;
    let mut timings = CpuPrecompute {
        cpu_precompute_s: Some(median(seconds)),
        cpu_precompute_wavelengths: Some(model.channels()),
        cpu_precompute_orders: Some(config.orders),
        cpu_precompute_stages_s: Some(stage_seconds(model, config)?),
        ..Default::default()
    };
    if let Some(spectral) = spectral {
        let seconds = time_runs(runs.min(3), || {
            precompute(spectral, config, &|_, _| {}, None)?;
            Ok(())
        })?;
        timings.cpu_precompute_spectral_s = Some(median(seconds));
        timings.cpu_precompute_spectral_wavelengths = Some(spectral.channels());
    }
    Ok(timings)
}

/// Where the time goes: one precomputation with a timestamp at each progress report, the
/// seconds summed per kind of stage (the progress message up to its first comma).
fn stage_seconds(model: &Model, config: &TableConfig) -> Result<BTreeMap<String, f64>> {
    let current = Mutex::new((Instant::now(), String::from("start")));
    let finished = Mutex::new(Vec::<(String, f64)>::new());
    precompute(
        model,
        config,
        &|stage, _| {
            let mut current = current.lock().unwrap();
            let kind = stage.split(',').next().unwrap_or(stage).to_string();
            let seconds = current.0.elapsed().as_secs_f64();
            let previous = std::mem::replace(&mut current.1, kind);
            finished.lock().unwrap().push((previous, seconds));
            current.0 = Instant::now();
        },
        None,
    )?;
    let mut per_stage = BTreeMap::new();
    // The first entry is the time before the first report.
    for (stage, seconds) in finished.into_inner().unwrap().into_iter().skip(1) {
        *per_stage.entry(stage).or_insert(0.0) += seconds;
    }
    Ok(per_stage)
}

/// Median seconds of the benchmark frames rendered from `sky`.
pub fn frame_timings(sky: &Bruneton4d, runs: usize) -> Result<CpuFrames> {
    Ok(CpuFrames {
        cpu_frame_1080p_perspective_s: Some(frame_seconds(
            sky,
            &scenes::perspective_1080p(),
            runs,
        )?),
        cpu_frame_1024_fisheye_s: Some(frame_seconds(sky, &scenes::fisheye_1024(), runs)?),
        cpu_frame_4096x2048_equirect_s: Some(frame_seconds(
            sky,
            &scenes::equirect_4096x2048(),
            runs,
        )?),
        cpu_frame_1080p_night_s: Some(night_seconds(sky, runs)?),
        cpu_frame_1080p_terrain_s: Some(terrain_seconds(sky, runs)?),
        cpu_frame_1080p_clouds_s: None,
    })
}

/// Median seconds of the default scene's frame: the valley at golden hour, the light
/// shafts' shadow field computed in each run, the terrain built once before.
fn terrain_seconds(sky: &Bruneton4d, runs: usize) -> Result<f64> {
    let default = firmament::scene::SceneFile::default();
    let terrain = default
        .build_terrain(&sky.model)?
        .expect("the default scene has a terrain");
    let camera = default.camera_over(Some(&terrain), sky.model.bottom_radius_m);
    let settings = render::RenderSettings {
        camera: &camera,
        width: 1920,
        height: 1080,
        white_balance: false,
    };
    let sun = sun_direction(default.sun.zenith_deg, default.sun.azimuth_deg);
    let seconds = time_runs(runs.clamp(1, 3), || {
        let terrain = terrain.clone_without_shadows();
        let mut scene = Scene::clear_sky(sky, sun, true);
        let radius = terrain.radius_m;
        scene.add_terrain(terrain, radius);
        let image = render::render(&scene, &settings, &|_| {}, None)?;
        let _ = image.to_srgb8(1e-4, ToneCurve::Aces);
        Ok(())
    })?;
    Ok(median(seconds))
}

/// Median seconds of the night frame: the date's sun, moon and stars computed, then the
/// frame with two lights, the stars and the glow.
fn night_seconds(sky: &Bruneton4d, runs: usize) -> Result<f64> {
    let frame = scenes::perspective_1080p();
    let settings = frame.settings();
    let seconds = time_runs(frame.runs(runs), || {
        let night = scenes::night()?;
        let sources = sources_of(&sky.model, &night, true, true);
        let mut scene = Scene::clear_sky(sky, Vec3::Z, false);
        scene.lights = sources.lights;
        scene.background = sources.background;
        scene.stars = sources.stars;
        let image = render::render(&scene, &settings, &|_| {}, None)?;
        let _ = image.to_srgb8(1.0, ToneCurve::Aces);
        Ok(())
    })?;
    Ok(median(seconds))
}

/// Median seconds of one frame, tone mapped to 8 bits.
fn frame_seconds(sky: &Bruneton4d, frame: &BenchFrame, runs: usize) -> Result<f64> {
    let settings = frame.settings();
    let seconds = time_runs(frame.runs(runs), || {
        let scene = Scene::clear_sky(sky, scenes::sun(), true);
        let image = render::render(&scene, &settings, &|_| {}, None)?;
        let _ = image.to_srgb8(1e-4, ToneCurve::Aces);
        Ok(())
    })?;
    Ok(median(seconds))
}

/// Paths per wavelength of the reference throughput pixel.
const REFERENCE_PATHS: usize = 8192;

/// Median seconds of the reference path tracer on one pixel ([`CpuReference`]) of `model`.
pub fn reference_timings(model: &Model, runs: usize) -> Result<CpuReference> {
    let camera = Vec3::new(0.0, 0.0, model.bottom_radius_m + 1.0);
    let sun = sun_direction(60.0, 180.0);
    let settings = ReferenceSettings::with_samples(REFERENCE_PATHS);
    let seconds = median(time_runs(runs, || {
        reference::sky_radiance(model, camera, Vec3::Z, sun, &settings);
        Ok(())
    })?);
    Ok(CpuReference {
        cpu_reference_zenith_pixel_s: Some(seconds),
        cpu_reference_paths_per_s: Some((REFERENCE_PATHS * model.channels()) as f64 / seconds),
    })
}

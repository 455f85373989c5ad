//! CPU timings of the fast sky methods for `firmament bench`: Hillaire 2020's tables (each
//! pass), its sky-view table (one view), the aerial-perspective volume, and the 1080p
//! benchmark frame drawn with them; the 3D table's precomputation and frame.

use std::collections::BTreeMap;
use std::sync::Mutex;
use std::time::Instant;

use anyhow::Result;
use firmament::atmosphere::Model;
use firmament::render::aerial_volume::{AerialVolume, AerialVolumeConfig};
use firmament::render::{self, ToneCurve};
use firmament::scene::{Light, Scene};
use firmament::sky::elek3d::{Elek3d, Elek3dConfig};
use firmament::sky::hillaire2020::{Hillaire2020, HillaireConfig};
use firmament::sky::SkyMethod;

use super::report::CpuMethods;
use super::scenes;
use super::timing::{median, time_runs};

/// The 3D table's precomputation (median of at most 3 runs) and the 1080p benchmark frame
/// drawn with it, into `out`.
pub fn elek3d_timings(model: &Model, runs: usize, out: &mut CpuMethods) -> Result<()> {
    let config = Elek3dConfig::default();
    out.cpu_elek3d_tables_s = Some(median(time_runs(runs.min(3), || {
        Elek3d::compute(model.clone(), &config)?;
        Ok(())
    })?));
    let sky = Elek3d::compute(model.clone(), &config)?;
    let frame = scenes::perspective_1080p();
    let settings = frame.settings();
    out.cpu_elek3d_frame_1080p_perspective_s =
        Some(median(time_runs(frame.runs(runs).min(3), || {
            let scene = Scene::clear_sky(&sky, scenes::sun(), true);
            let image = render::render(&scene, &settings, &|_| {}, None)?;
            let _ = image.to_srgb8(1e-4, ToneCurve::Aces);
            Ok(())
        })?));
    Ok(())
}

/// Hillaire 2020's costs on `model`, medians of `runs`, and the aerial-perspective volume
/// of `tables` (the 4D method) for comparison, into `out`.
pub fn hillaire_timings(
    model: &Model,
    tables: &dyn SkyMethod,
    runs: usize,
    out: &mut CpuMethods,
) -> Result<()> {
    let config = HillaireConfig::default();
    let seconds = time_runs(runs, || {
        Hillaire2020::compute(model.clone(), &config)?;
        Ok(())
    })?;
    let stages = stage_seconds(model, &config)?;
    let sky = Hillaire2020::compute(model.clone(), &config)?;
    let frame = scenes::perspective_1080p();
    let settings = frame.settings();
    let observer =
        firmament::math::Vec3::new(0.0, 0.0, model.bottom_radius_m + frame.camera.altitude_m);
    let light = Light::sun(model, scenes::sun(), true);
    let sky_view = median(time_runs(runs, || {
        let _ = sky.view(observer, &light);
        Ok(())
    })?);
    let prepared = frame
        .camera
        .prepare(model.bottom_radius_m, frame.width, frame.height);
    let volume_of = |method: &dyn SkyMethod| -> Result<f64> {
        let view = method.view(observer, &light);
        Ok(median(time_runs(runs.min(3), || {
            let _ = AerialVolume::new(
                view.as_ref(),
                observer,
                model.bottom_radius_m,
                &prepared,
                frame.width,
                frame.height,
                AerialVolumeConfig::default(),
                model.channels(),
            );
            Ok(())
        })?))
    };
    let aerial_hillaire = volume_of(&sky)?;
    let aerial_tables = volume_of(tables)?;
    let frame_with = |volume: bool| -> Result<f64> {
        Ok(median(time_runs(frame.runs(runs).min(3), || {
            let mut scene = Scene::clear_sky(&sky, scenes::sun(), true);
            scene.aerial_volume = volume.then(AerialVolumeConfig::default);
            let image = render::render(&scene, &settings, &|_| {}, None)?;
            let _ = image.to_srgb8(1e-4, ToneCurve::Aces);
            Ok(())
        })?))
    };
    let stage = |name: &str| stages.get(name).copied();
    let (transmittance, multiple, irradiance) = (
        stage("transmittance"),
        stage("multiple scattering"),
        stage("irradiance"),
    );
    *out = CpuMethods {
        cpu_hillaire_tables_s: Some(median(seconds)),
        cpu_hillaire_transmittance_s: transmittance,
        cpu_hillaire_multiple_scattering_s: multiple,
        cpu_hillaire_irradiance_s: irradiance,
        cpu_hillaire_sky_view_s: Some(sky_view),
        cpu_hillaire_aerial_volume_s: Some(aerial_hillaire),
        cpu_hillaire_four_luts_s: match (transmittance, multiple) {
            (Some(t), Some(m)) => Some(t + m + sky_view + aerial_hillaire),
            _ => None,
        },
        cpu_hillaire_frame_1080p_perspective_s: Some(frame_with(false)?),
        cpu_hillaire_frame_1080p_perspective_aerial_volume_s: Some(frame_with(true)?),
        cpu_bruneton4d_aerial_volume_s: Some(aerial_tables),
        ..std::mem::take(out)
    };
    Ok(())
}

/// Seconds of each pass of one build, from the build's own stage reports.
fn stage_seconds(model: &Model, config: &HillaireConfig) -> Result<BTreeMap<String, f64>> {
    let current = Mutex::new((Instant::now(), String::new()));
    let per_stage = Mutex::new(BTreeMap::new());
    Hillaire2020::compute_reporting(model.clone(), config, &|stage| {
        let mut current = current.lock().unwrap();
        let seconds = current.0.elapsed().as_secs_f64();
        let previous = std::mem::replace(&mut current.1, stage.to_string());
        if !previous.is_empty() {
            per_stage.lock().unwrap().insert(previous, seconds);
        }
        current.0 = Instant::now();
    })?;
    Ok(per_stage.into_inner().unwrap())
}

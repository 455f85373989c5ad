//! The cloudy benchmark frame (`bench --clouds`): `scenes/clouds-cumulus-noon.toml` (fair-
//! weather cumulus from a meadow, the sun 55° high) at 1920×1080 from the 4D tables, on the
//! CPU (converged, no temporal tricks) and on the GPU (the render dispatch alone, and the
//! whole frame with the clouds' shadow maps computed on the CPU and uploaded).

use anyhow::{Context, Result};
use firmament::math::Vec3;
use firmament::render::{self, RenderSettings, Shader, ToneCurve};
use firmament::scene::clouds::{CloudMedium, ViewFootprint};
use firmament::scene::{sun_direction, Light, Scene, SceneFile};
use firmament::sky::bruneton4d::Bruneton4d;
use firmament_gpu::{GpuClouds, GpuRenderer, GpuSky, RenderInputs};

use super::gpu::dispatch_and_whole;
use super::timing::{median, time_runs};
use crate::backend::{gpu_failure, Gpu};
use crate::common::scene_clouds;

/// The scene measured, embedded so that `bench` needs no file.
const CUMULUS_NOON: &str = include_str!("../../../../../scenes/clouds-cumulus-noon.toml");

/// Runs at most: one CPU frame takes ~30 s on two cores.
const MAX_CPU_RUNS: usize = 3;

/// The benchmark's cloud scene: its layers over a sky's planet (the noise volumes from the
/// user's cache, computed there the first time), its camera and its sun.
pub struct CloudFrame {
    scene: SceneFile,
    media: Vec<CloudMedium>,
    sun: Vec3,
}

impl CloudFrame {
    /// The cumulus scene over the planet of `sky`, its clouds' density filtered over the
    /// pixels' footprint as `render` sets it (the filter's tables made here, once, where
    /// `render` makes them per frame: about 0.4 s).
    pub fn new(sky: &Bruneton4d) -> Result<CloudFrame> {
        let scene: SceneFile =
            toml::from_str(CUMULUS_NOON).context("the embedded cumulus scene")?;
        scene.validate()?;
        let radius = sky.model.bottom_radius_m;
        let mut media = scene_clouds(&scene, radius, false, true)?;
        let (w, h) = (scene.image.width, scene.image.height);
        if let Some((eye, pixel_angle_rad)) = scene.camera.prepare(radius, w, h).pixel_footprint() {
            let view = ViewFootprint {
                eye,
                pixel_angle_rad,
            };
            for m in &mut media {
                m.layer.set_view(view, None);
            }
        }
        let sun = sun_direction(scene.sun.zenith_deg, scene.sun.azimuth_deg);
        Ok(CloudFrame { scene, media, sun })
    }

    fn settings(&self) -> RenderSettings<'_> {
        RenderSettings {
            camera: &self.scene.camera,
            width: self.scene.image.width,
            height: self.scene.image.height,
            white_balance: false,
        }
    }

    fn scene<'a>(&'a self, sky: &'a Bruneton4d) -> Scene<'a> {
        let mut scene = Scene::clear_sky(sky, self.sun, true);
        for m in &self.media {
            scene.volumes.push(Box::new(m));
        }
        scene
    }

    fn observer(&self, sky: &Bruneton4d) -> Vec3 {
        Vec3::new(
            0.0,
            0.0,
            sky.model.bottom_radius_m + self.scene.camera.altitude_m,
        )
    }
}

/// Median seconds of the CPU frame (its shadow maps included), at most [`MAX_CPU_RUNS`].
pub fn cpu_seconds(sky: &Bruneton4d, frame: &CloudFrame, runs: usize) -> Result<f64> {
    let settings = frame.settings();
    let seconds = time_runs(runs.clamp(1, MAX_CPU_RUNS), || {
        let scene = frame.scene(sky);
        let image = render::render(&scene, &settings, &|_| {}, None)?;
        let _ = image.to_srgb8(1e-4, ToneCurve::Aces);
        Ok(())
    })?;
    Ok(median(seconds))
}

/// The GPU frame: the render dispatch alone (median of `runs` after a warm-up, timestamp
/// queries on a hardware adapter), and the whole frame (the shadow maps on the CPU, the
/// upload, the dispatch, the readback and the tone mapping; at most 3 runs). `gpu_sky`
/// holds `sky`'s tables on the device.
pub fn gpu_seconds(
    gpu: &Gpu,
    renderer: &GpuRenderer,
    gpu_sky: &GpuSky,
    sky: &Bruneton4d,
    frame: &CloudFrame,
    runs: usize,
) -> Result<(f64, f64)> {
    let settings = frame.settings();
    let lights = [Light::sun(&sky.model, frame.sun, true)];
    let upload = || -> Result<GpuClouds> {
        let scene = frame.scene(sky);
        let shader = Shader::new(&scene, frame.observer(sky))?;
        GpuClouds::new(&gpu.ctx, gpu_sky, &frame.media, &shader)
            .map_err(|e| gpu_failure("uploading the clouds", e))
    };
    dispatch_and_whole(
        gpu,
        renderer,
        gpu_sky,
        &lights,
        &settings,
        runs,
        upload,
        |c| RenderInputs {
            clouds: Some(c),
            ..RenderInputs::default()
        },
    )
}

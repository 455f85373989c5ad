//! CPU–GPU parity under clouds: scenes of cumulus, a uniform overcast slab, the planet's
//! weather seen from orbit and cumulus over the valley's terrain rendered by `firmament::render::render` and by
//! `firmament_gpu::GpuRenderer` with a `GpuClouds` (and a `GpuTerrain`; the same layers, noise, weather, planetary
//! map, filter tables, two-stream tables and the CPU's shadow maps), compared pixel by pixel
//! in luminance. The GPU marches in f32 with its own per-pixel jitter (a hash of the f32
//! direction where the CPU hashes the f64 one) and looks the air's light up at every sample
//! (the CPU reuses it within 250 m), so single pixels in thin cloud differ by their jitter;
//! the criterion is the frame's mean relative difference (near the ground ≤ 2.5 %, measured
//! 1.9–2.0 % for cumulus, the goal is 1–2 %; from orbit ≤ 2 %, measured 0.07 % where
//! the pixels see the mean density alone and 0.4 % where it is blended with the noise) and
//! the share of pixels over 10 % (≤ 8 %).

mod common;

use std::time::Instant;

use firmament::math::Vec3;
use firmament::render::{render, Frame, RenderSettings, Shader};
use firmament::scene::clouds::{
    cloud_media, CloudKind, CloudLayerConfig, CloudMedium, CloudNoise, ViewFootprint, WeatherWrap,
};
use firmament::scene::terrain::{Heightfield, TerrainConfig};
use firmament::scene::{sun_direction, Camera, Projection, Scene};
use firmament::sky::bruneton4d::Bruneton4d;
use firmament_gpu::{GpuClouds, GpuSky, GpuTerrain, RenderInputs};

use common::*;

/// Mean relative luminance difference and the share of pixels over 10 %.
fn differences(name: &str, cpu: &Frame, gpu: &Frame) -> (f64, f64) {
    let n = cpu.image.data.len();
    let (mut sum, mut over, mut worst, mut at) = (0.0, 0usize, 0.0f64, 0usize);
    for i in 0..n {
        let (c, g) = (luminance(&cpu.image.data[i]), luminance(&gpu.image.data[i]));
        assert!(g.is_finite(), "{name}: pixel {i} is {g} on the GPU");
        let rel = (g - c).abs() / c.max(1e-9);
        sum += rel;
        if rel > 0.1 {
            over += 1;
        }
        if rel > worst {
            (worst, at) = (rel, i);
        }
    }
    let (mean, share) = (sum / n as f64, over as f64 / n as f64);
    // The frames' mean luminances: a bias shows here, the jitter's grain averages out
    // (unless the sun's disk is in view: its pixel outweighs the frame).
    let total = |f: &Frame| f.image.data.iter().map(luminance).sum::<f64>();
    let w = cpu.image.width;
    eprintln!(
        "{name}: mean rel {mean:.3e}, {:.2} % of pixels over 10 %, frame mean GPU/CPU − 1 = {:+.2e}; largest {worst:.2e} at ({}, {}): CPU {:.4e}, GPU {:.4e} cd/m²",
        share * 100.0,
        total(gpu) / total(cpu) - 1.0,
        at % w,
        at / w,
        luminance(&cpu.image.data[at]),
        luminance(&gpu.image.data[at]),
    );
    (mean, share)
}

/// One comparison: `layer` seen by `camera` at `size` pixels, the sun at `sun_zenith_deg`
/// from the zenith; with `filtered`, the clouds' density filtered over the pixels' footprint
/// as `firmament render` sets it (`CloudLayer::set_view` from `pixel_footprint`). Fails when
/// the frame's mean relative difference exceeds `max_mean` or the share of pixels over 10 %
/// exceeds `max_share`.
struct Case {
    name: &'static str,
    layer: CloudLayerConfig,
    camera: Camera,
    sun_zenith_deg: f64,
    size: (usize, usize),
    filtered: bool,
    max_mean: f64,
    max_share: f64,
}

/// A case of the first scenes: 40×24 pixels, no filter, the mean within 2.5 % and 8 % of
/// the pixels over 10 %.
fn near(
    name: &'static str,
    layer: CloudLayerConfig,
    altitude_m: f64,
    pitch_deg: f64,
    sun_zenith_deg: f64,
) -> Case {
    Case {
        name,
        layer,
        camera: camera(Projection::Perspective, altitude_m, 30.0, pitch_deg, 70.0),
        sun_zenith_deg,
        size: (40, 24),
        filtered: false,
        max_mean: 0.025,
        max_share: 0.08,
    }
}

/// The comparison of `case`; the CPU's frame (None without a GPU adapter).
fn check(case: Case) -> Option<Frame> {
    let name = case.name;
    let gpu = gpu(name)?;
    let _guard = serial();
    let sky = earth_rgb();
    let radius = sky.model.bottom_radius_m;
    let (noise, _) = CloudNoise::new([32, 16], None).unwrap();
    let mut media = cloud_media(
        std::slice::from_ref(&case.layer),
        radius,
        (0.0, 0.0),
        &noise,
    )
    .unwrap();
    if case.filtered {
        let prepared = case.camera.prepare(radius, case.size.0, case.size.1);
        let (eye, pixel_angle_rad) = prepared.pixel_footprint().expect("a pinhole camera");
        let view = ViewFootprint {
            eye,
            pixel_angle_rad,
        };
        for m in &mut media {
            m.layer.set_view(view, None);
            assert!(m.layer.filter.is_some(), "{name}: the layer has no filter");
        }
    }
    let sun = sun_direction(case.sun_zenith_deg, 200.0);
    let scene = Scene::clear_sky(sky, sun, true);
    compare(gpu, &case, sky, scene, &media, None)
}

/// `case` in `scene` (its sky and lights; `terrain` added when given) under `media`, on
/// the CPU and the GPU; the CPU's frame.
fn compare<'a>(
    gpu: &Gpu,
    case: &Case,
    sky: &'a Bruneton4d,
    mut scene: Scene<'a>,
    media: &'a [CloudMedium],
    terrain: Option<&'a Heightfield>,
) -> Option<Frame> {
    let name = case.name;
    let settings = RenderSettings {
        camera: &case.camera,
        width: case.size.0,
        height: case.size.1,
        white_balance: false,
    };
    if let Some(t) = terrain {
        scene.add_terrain(t, t.radius_m);
    }
    scene.volumes.push(Box::new(&media[0]));
    let started = Instant::now();
    let cpu = render(&scene, &settings, &|_| {}, None).unwrap();
    let cpu_s = started.elapsed().as_secs_f64();
    let bottom = sky.model.bottom_radius_m;
    let observer = Vec3::new(0.0, 0.0, bottom + case.camera.altitude_m);
    let shader = Shader::new(&scene, observer).unwrap();
    let gpu_sky = GpuSky::from_sky(&gpu.ctx, sky).unwrap();
    let clouds = GpuClouds::new(&gpu.ctx, &gpu_sky, media, &shader).unwrap();
    let gpu_terrain = terrain.map(|t| GpuTerrain::new(&gpu.ctx, &gpu_sky, t, &shader).unwrap());
    let inputs = RenderInputs {
        clouds: Some(&clouds),
        terrain: gpu_terrain.as_ref(),
        ..RenderInputs::default()
    };
    let started = Instant::now();
    let frame = gpu
        .renderer
        .render_with(&gpu.ctx, &gpu_sky, &scene.lights, &settings, inputs)
        .unwrap();
    eprintln!(
        "{name}: CPU {cpu_s:.1} s, GPU {:.1} s (with any shader compile)",
        started.elapsed().as_secs_f64()
    );
    let (mean, share) = differences(name, &cpu, &frame);
    assert!(
        mean <= case.max_mean,
        "{name}: mean relative difference {mean}"
    );
    assert!(
        share <= case.max_share,
        "{name}: {share} of the pixels differ by over 10 %"
    );
    Some(cpu)
}

/// Cumulus over the valley (scenes/clouds-over-the-valley.toml at a coarser grid, the
/// tables' ground lifted to its floor as `render` computes them): the terrain and the
/// clouds' shadows on it, the light shafts through both, the clouds over the ridges. The
/// CPU's frame (None without a GPU adapter).
fn check_over_valley(
    name: &'static str,
    sun_zenith_deg: f64,
    sun_azimuth_deg: f64,
    heading_deg: f64,
    (above_m, pitch_deg): (f64, f64),
) -> Option<Frame> {
    let gpu = gpu(name)?;
    let _guard = serial();
    let (terrain, sky) = valley(TerrainConfig {
        resolution: 257,
        ..TerrainConfig::default()
    });
    let bottom = sky.model.bottom_radius_m;
    // SceneFile::camera_over: `above_m` above the terrain under the observer.
    let altitude = above_m + terrain.height_at(0.0, 0.0) - (bottom - terrain.radius_m);
    // The clouds on the terrain's sphere, over its ridges (~2.8 km).
    let layer = CloudLayerConfig {
        bottom_m: Some(3200.0),
        top_m: Some(5000.0),
        coverage: Some(0.4),
        ..CloudLayerConfig::of_kind(CloudKind::Cumulus)
    };
    let (noise, _) = CloudNoise::new([32, 16], None).unwrap();
    let media = cloud_media(
        std::slice::from_ref(&layer),
        terrain.radius_m,
        (0.0, 0.0),
        &noise,
    )
    .unwrap();
    let case = Case {
        name,
        layer,
        camera: camera(
            Projection::Perspective,
            altitude,
            heading_deg,
            pitch_deg,
            60.0,
        ),
        sun_zenith_deg,
        size: (48, 27),
        filtered: false,
        max_mean: 0.025,
        max_share: 0.08,
    };
    // Without the sun's disk: under 4 pixels here, `render` splats it beside the GPU's
    // frame (backend's gpu_lights), which this comparison does not.
    let sun = sun_direction(sun_zenith_deg, sun_azimuth_deg);
    let scene = Scene::clear_sky(&sky, sun, false);
    compare(gpu, &case, &sky, scene, &media, Some(&terrain))
}

/// The share of a frame's pixels brighter than twice the mean of its darkest tenth: from
/// orbit, the share of cloud over the ground (the test's check of its own scene, so that the
/// parity compares cloud systems and clear skies, not an empty or an overcast frame).
fn cloudy_share(frame: &Frame) -> f64 {
    let mut l: Vec<f64> = frame.image.data.iter().map(luminance).collect();
    l.sort_by(f64::total_cmp);
    let dark = l[..l.len() / 10].iter().sum::<f64>() / (l.len() / 10) as f64;
    l.iter().filter(|&&v| v > 2.0 * dark).count() as f64 / l.len() as f64
}

/// The scenes in one test, on one thread.
#[test]
#[ignore = "run by `clouds_match_the_cpu` in a child process"]
fn clouds_match_the_cpu_child() {
    let _ = check(near(
        "cumulus from the ground",
        CloudLayerConfig::of_kind(CloudKind::Cumulus),
        2.0,
        25.0,
        40.0,
    ));
    let mut slab = CloudLayerConfig::of_kind(CloudKind::Uniform);
    slab.extinction_per_m = Some(0.005);
    let _ = check(near("overcast slab", slab, 2.0, 20.0, 70.0));
    let mut layer = CloudLayerConfig::of_kind(CloudKind::Cumulus);
    layer.multiple_scattering = firmament::scene::clouds::MultipleScattering::Octaves;
    let _ = check(near(
        "cumulus from above (octaves)",
        layer,
        5000.0,
        -30.0,
        30.0,
    ));
    // The planet's weather seen from 700 km straight down, the density filtered over the
    // pixels' footprint: 60° over 48 pixels, 15 km per pixel at the nadir (the mean density
    // alone) ...
    let planet = CloudLayerConfig {
        weather_wrap: WeatherWrap::Planet,
        ..CloudLayerConfig::of_kind(CloudKind::Cumulus)
    };
    let orbit = |name, fov_deg| Case {
        name,
        layer: planet.clone(),
        camera: camera(Projection::Perspective, 700e3, 0.0, -90.0, fov_deg),
        sun_zenith_deg: 30.0,
        size: (48, 48),
        filtered: true,
        max_mean: 0.02,
        max_share: 0.08,
    };
    if let Some(cpu) = check(orbit("planet's cumulus from orbit (60°, the mean)", 60.0)) {
        let share = cloudy_share(&cpu);
        eprintln!("from orbit: {:.0} % of the pixels cloudy", 100.0 * share);
        assert!(
            (0.05..0.95).contains(&share),
            "from orbit the frame is not broken cloud: {share} cloudy"
        );
    }
    // ... and 4° over 48 pixels, 1 km per pixel (the noise blended with the mean).
    let _ = check(orbit("planet's cumulus from orbit (4°, the blend)", 4.0));
}

/// The scenes over the terrain (`main_clouds` compiled with WITH_TERRAIN), on one thread:
/// from 25 m, the afternoon sun in the south behind the camera, and a low sun ahead through
/// the ridges (light shafts cut by the terrain and the clouds); from 7 km above the clouds
/// looking down, the terrain behind them and their shadows on it.
#[test]
#[ignore = "run by `clouds_match_the_cpu` in a child process"]
fn clouds_over_the_valley_match_the_cpu_child() {
    let ground = (25.0, 4.0);
    let _ = check_over_valley(
        "cumulus over the valley, afternoon",
        40.0,
        175.0,
        20.0,
        ground,
    );
    let _ = check_over_valley(
        "cumulus over the valley, low sun ahead",
        80.0,
        237.0,
        250.0,
        ground,
    );
    let _ = check_over_valley(
        "the valley under cumulus from 7 km",
        40.0,
        175.0,
        20.0,
        (7000.0, -35.0),
    );
}

/// Runs `child` (a test of this binary) in a child process, again (up to six times) while
/// it dies of the test driver's heap corruption ([`firmament_gpu::driver_crash`]): before the
/// passes read their uniforms as storage on software adapters (f41b720), Mesa 22.3's
/// lavapipe killed many runs of the cloud shader (glibc aborts, a SIGSEGV in its queue
/// thread, a panic inside gpu-allocator in a CI run of 2026-12-06); the runs that finished
/// gave identical results. A failed comparison (a panic in this file) fails at once.
fn run_child(child: &str) {
    let exe = std::env::current_exe().expect("the test binary");
    for attempt in 1..=6 {
        let o = std::process::Command::new(&exe)
            .args([
                child,
                "--exact",
                "--ignored",
                "--nocapture",
                "--test-threads=1",
            ])
            .output()
            .expect("running the child test");
        let (out, err) = (
            String::from_utf8_lossy(&o.stdout),
            String::from_utf8_lossy(&o.stderr),
        );
        print!("{out}");
        eprint!("{err}");
        if o.status.success() {
            return;
        }
        match firmament_gpu::driver_crash(&o.status, &format!("{out}{err}")) {
            Some(why) => eprintln!(
                "attempt {attempt}: the child {why} ({}): lavapipe's heap corruption, running it again",
                o.status
            ),
            None => panic!("the CPU–GPU cloud comparison {child} failed ({})", o.status),
        }
    }
    panic!("the child test {child} crashed six times");
}

#[test]
fn clouds_match_the_cpu() {
    run_child("clouds_match_the_cpu_child");
}

#[test]
fn clouds_over_the_valley_match_the_cpu() {
    run_child("clouds_over_the_valley_match_the_cpu_child");
}

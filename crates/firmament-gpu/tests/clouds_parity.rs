//! CPU–GPU parity under clouds: scenes of cumulus, a uniform overcast slab and cirrus rendered
//! by `firmament::render::render` and by `firmament_gpu::GpuRenderer` with a `GpuClouds` (the
//! same layers, noise, weather, two-stream tables and the CPU's shadow maps), compared pixel
//! by pixel in luminance. The GPU marches in f32 with its own per-pixel jitter (a hash of the
//! f32 direction where the CPU hashes the f64 one) and looks the air's light up at every
//! sample (the CPU reuses it within 250 m), so single pixels in thin cloud differ by their
//! jitter; the criterion is the frame's mean relative difference (≤ 2.5 %; measured 2.0–2.2 % for
//! cumulus, the goal is 1–2 %) and the share of pixels over 10 % (≤ 8 %).

mod common;

use firmament::math::Vec3;
use firmament::render::{render, Frame, RenderSettings, Shader};
use firmament::scene::clouds::{cloud_media, CloudKind, CloudLayerConfig, CloudNoise};
use firmament::scene::{sun_direction, Projection, Scene};
use firmament_gpu::{GpuClouds, GpuSky, RenderInputs};

use common::*;

/// Mean relative luminance difference and the share of pixels over 10 %.
fn differences(name: &str, cpu: &Frame, gpu: &Frame) -> (f64, f64) {
    let n = cpu.image.data.len();
    let (mut sum, mut over) = (0.0, 0usize);
    for i in 0..n {
        let (c, g) = (luminance(&cpu.image.data[i]), luminance(&gpu.image.data[i]));
        assert!(g.is_finite(), "{name}: pixel {i} is {g} on the GPU");
        let rel = (g - c).abs() / c.max(1e-9);
        sum += rel;
        if rel > 0.1 {
            over += 1;
        }
    }
    let (mean, share) = (sum / n as f64, over as f64 / n as f64);
    eprintln!(
        "{name}: mean rel {mean:.3e}, {:.2} % of pixels over 10 %",
        share * 100.0
    );
    (mean, share)
}

fn check(
    name: &str,
    layer: CloudLayerConfig,
    altitude_m: f64,
    pitch_deg: f64,
    sun_zenith_deg: f64,
) {
    let Some(gpu) = gpu(name) else { return };
    let _guard = serial();
    let sky = earth_rgb();
    let radius = sky.model.bottom_radius_m;
    let (noise, _) = CloudNoise::new([32, 16], None).unwrap();
    let media = cloud_media(std::slice::from_ref(&layer), radius, (0.0, 0.0), &noise).unwrap();
    let camera = camera(Projection::Perspective, altitude_m, 30.0, pitch_deg, 70.0);
    let settings = RenderSettings {
        camera: &camera,
        width: 40,
        height: 24,
        white_balance: false,
    };
    let sun = sun_direction(sun_zenith_deg, 200.0);
    let mut scene = Scene::clear_sky(sky, sun, true);
    scene.volumes.push(Box::new(&media[0]));
    let cpu = render(&scene, &settings, &|_| {}, None).unwrap();
    let observer = Vec3::new(0.0, 0.0, radius + altitude_m);
    let shader = Shader::new(&scene, observer).unwrap();
    let gpu_sky = GpuSky::from_sky(&gpu.ctx, sky).unwrap();
    let clouds = GpuClouds::new(&gpu.ctx, &gpu_sky, &media, &shader).unwrap();
    let inputs = RenderInputs {
        clouds: Some(&clouds),
        ..RenderInputs::default()
    };
    let frame = gpu
        .renderer
        .render_with(&gpu.ctx, &gpu_sky, &scene.lights, &settings, inputs)
        .unwrap();
    let (mean, share) = differences(name, &cpu, &frame);
    assert!(mean < 0.025, "{name}: mean relative difference {mean}");
    assert!(
        share < 0.08,
        "{name}: {share} of the pixels differ by over 10 %"
    );
}

/// The three scenes in one test, on one thread.
#[test]
#[ignore = "run by `clouds_match_the_cpu` in a child process"]
fn clouds_match_the_cpu_child() {
    check(
        "cumulus from the ground",
        CloudLayerConfig::of_kind(CloudKind::Cumulus),
        2.0,
        25.0,
        40.0,
    );
    let mut slab = CloudLayerConfig::of_kind(CloudKind::Uniform);
    slab.extinction_per_m = Some(0.005);
    check("overcast slab", slab, 2.0, 20.0, 70.0);
    let mut layer = CloudLayerConfig::of_kind(CloudKind::Cumulus);
    layer.multiple_scattering = firmament::scene::clouds::MultipleScattering::Octaves;
    check("cumulus from above (octaves)", layer, 5000.0, -30.0, 30.0);
}

/// Runs `clouds_match_the_cpu_child` in a child process, again (up to six times) while it
/// dies of the test driver's heap corruption ([`firmament_gpu::driver_crash`]): before the
/// passes read their uniforms as storage on software adapters (f41b720), Mesa 22.3's
/// lavapipe killed many runs of the cloud shader (glibc aborts, a SIGSEGV in its queue
/// thread, a panic inside gpu-allocator in a CI run of 2026-12-06); the runs that finished
/// gave identical results. A failed comparison (a panic in this file) fails at once.
#[test]
fn clouds_match_the_cpu() {
    let exe = std::env::current_exe().expect("the test binary");
    for attempt in 1..=6 {
        let o = std::process::Command::new(&exe)
            .args([
                "clouds_match_the_cpu_child",
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
            None => panic!("the CPU–GPU cloud comparison failed ({})", o.status),
        }
    }
    panic!("the child test crashed six times");
}

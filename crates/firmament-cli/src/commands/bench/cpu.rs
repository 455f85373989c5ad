//! Frame timings for `firmament bench`: the CPU renderer from precomputed tables.

use std::time::Instant;

use anyhow::Result;
use firmament::math::Vec3;
use firmament::render::{self, RenderSettings};
use firmament::scene::{sun_direction, Camera, Projection, Scene};
use firmament::sky::bruneton4d::Bruneton4d;
use serde_json::json;

use super::{median, BenchArgs};

/// The benchmark cameras: heading 200°, 60° field of view.
pub fn camera(projection: Projection, altitude_m: f64, pitch_deg: f64) -> Camera {
    Camera {
        projection,
        altitude_m,
        heading_deg: 200.0,
        pitch_deg,
        roll_deg: 0.0,
        fov_deg: 60.0,
    }
}

/// The 1080p frame: from 1.5 km, half sky, half ground with aerial perspective, the sun in
/// view (the CPU and GPU frame benchmarks).
pub fn camera_1080p() -> Camera {
    camera(Projection::Perspective, 1500.0, 20.0)
}

/// Settings of every benchmark frame.
pub fn settings(camera: &Camera, width: usize, height: usize) -> RenderSettings<'_> {
    RenderSettings {
        camera,
        width,
        height,
        white_balance: false,
    }
}

/// The sun of every benchmark frame: 60° from the zenith at azimuth 200°, disk drawn.
pub fn sun() -> Vec3 {
    sun_direction(60.0, 200.0)
}

/// Time one kind of frame.
fn frame(
    sky: &Bruneton4d,
    camera: Camera,
    width: usize,
    height: usize,
    runs: usize,
) -> Result<f64> {
    let settings = settings(&camera, width, height);
    let mut times = Vec::new();
    for _ in 0..runs.max(1) {
        let t = Instant::now();
        let f = render::render(
            &Scene::clear_sky(sky, sun(), true),
            &settings,
            &|_| {},
            None,
        )?;
        let _ = f.to_srgb8(1e-4, render::ToneCurve::Aces);
        times.push(t.elapsed().as_secs_f64());
    }
    Ok(median(times))
}

/// The CPU frame keys, null (not measured).
pub const KEYS: [&str; 3] = [
    "cpu_frame_1080p_perspective_s",
    "cpu_frame_1024_fisheye_s",
    "cpu_frame_4096x2048_equirect_s",
];

/// Add render timings to the benchmark result.
pub fn extend(result: &mut serde_json::Value, args: &BenchArgs) -> Result<()> {
    let sky = args.atmosphere.sky(true)?;
    result[KEYS[0]] = json!(frame(&sky, camera_1080p(), 1920, 1080, args.runs)?);
    result[KEYS[1]] = json!(frame(
        &sky,
        camera(Projection::Fisheye, 2.0, 0.0),
        1024,
        1024,
        args.runs
    )?);
    result[KEYS[2]] = json!(frame(
        &sky,
        camera(Projection::Equirect, 2.0, 0.0),
        4096,
        2048,
        args.runs.min(3)
    )?);
    Ok(())
}

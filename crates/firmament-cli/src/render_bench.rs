//! Frame timings for `firmament bench`: the CPU renderer from precomputed tables.

use std::time::Instant;

use anyhow::Result;
use firmament::render::{self, Camera, Projection, RenderSettings, ShadeOptions};
use firmament::sky::Sky;
use serde_json::json;

use crate::bench::{median, BenchArgs};

/// Time one kind of frame.
fn frame(sky: &Sky, camera: Camera, width: usize, height: usize, runs: usize) -> Result<f64> {
    let settings = RenderSettings {
        camera: &camera,
        width,
        height,
        shade: ShadeOptions {
            sun: render::sun_direction(60.0, 200.0),
            sun_disk: true,
        },
        white_balance: false,
    };
    let mut times = Vec::new();
    for _ in 0..runs.max(1) {
        let t = Instant::now();
        let f = render::render(sky, &settings, &|_| {}, None)?;
        let _ = f.to_srgb8(1e-4, render::ToneCurve::Aces);
        times.push(t.elapsed().as_secs_f64());
    }
    Ok(median(times))
}

/// Add render timings to the benchmark result.
pub fn extend(result: &mut serde_json::Value, args: &BenchArgs) -> Result<()> {
    let sky = args.atmosphere.sky(true)?;
    let cam = |projection, altitude_m, pitch_deg| Camera {
        projection,
        altitude_m,
        heading_deg: 200.0,
        pitch_deg,
        roll_deg: 0.0,
        fov_deg: 60.0,
    };
    // Half sky, half ground with aerial perspective, the sun in view.
    result["cpu_frame_1080p_perspective_s"] = json!(frame(
        &sky,
        cam(Projection::Perspective, 1500.0, 20.0),
        1920,
        1080,
        args.runs
    )?);
    result["cpu_frame_1024_fisheye_s"] = json!(frame(
        &sky,
        cam(Projection::Fisheye, 2.0, 0.0),
        1024,
        1024,
        args.runs
    )?);
    result["cpu_frame_4096x2048_equirect_s"] = json!(frame(
        &sky,
        cam(Projection::Equirect, 2.0, 0.0),
        4096,
        2048,
        args.runs.min(3)
    )?);
    Ok(())
}

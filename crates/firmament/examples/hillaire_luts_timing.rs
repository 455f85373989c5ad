//! Time Hillaire 2020's tables on the CPU, pass by pass: transmittance, Ψ_ms, sky
//! irradiance (one build's own stage reports), one sky-view table and the
//! aerial-perspective volume (32³, the camera of `bench`'s 1080p frame), medians of RUNS
//! (default 9), earth, RGB. A quick look for optimising them; the benchmark proper is
//! `firmament bench --method hillaire2020` (BENCHMARKS.md).
//!
//! `cargo run --release -p firmament --example hillaire_luts_timing [RUNS]`
use std::collections::BTreeMap;
use std::sync::Mutex;
use std::time::Instant;

use firmament::atmosphere::Atmosphere;
use firmament::math::Vec3;
use firmament::render::aerial_volume::{AerialVolume, AerialVolumeConfig};
use firmament::scene::{sun_direction, Camera, Light, Projection};
use firmament::sky::hillaire2020::{Hillaire2020, HillaireConfig};
use firmament::sky::SkyMethod;
use firmament::spectrum::Wavelengths;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let runs: usize = std::env::args()
        .nth(1)
        .map(|a| a.parse().expect("RUNS is a count"))
        .unwrap_or(9);
    let model = Atmosphere::earth().resolve(&Wavelengths::rgb()).unwrap();
    let config = HillaireConfig::default();
    let stages: Mutex<BTreeMap<String, Vec<f64>>> = Mutex::new(BTreeMap::new());
    let mut sky = None;
    for _ in 0..runs {
        let current = Mutex::new((Instant::now(), String::new()));
        let built = Hillaire2020::compute_reporting(model.clone(), &config, &|stage| {
            let mut current = current.lock().unwrap();
            let seconds = current.0.elapsed().as_secs_f64();
            let previous = std::mem::replace(&mut current.1, stage.to_string());
            if !previous.is_empty() {
                let mut stages = stages.lock().unwrap();
                stages.entry(previous).or_default().push(seconds);
            }
            current.0 = Instant::now();
        });
        sky = Some(built.unwrap());
    }
    for (name, seconds) in stages.into_inner().unwrap() {
        println!("{name}: {:.2} ms", median(seconds) * 1e3);
    }
    let sky = sky.unwrap();
    let observer = Vec3::new(0.0, 0.0, model.bottom_radius_m + 2.0);
    let camera = Camera {
        projection: Projection::Perspective,
        altitude_m: 1500.0,
        heading_deg: 200.0,
        pitch_deg: 20.0,
        roll_deg: 0.0,
        fov_deg: 60.0,
    };
    let prepared = camera.prepare(model.bottom_radius_m, 1920, 1080);
    let light = Light::sun(&model, sun_direction(60.0, 200.0), true);
    let sky_view: Vec<f64> = (0..runs)
        .map(|_| {
            let t0 = Instant::now();
            let _ = sky.view(observer, &light);
            t0.elapsed().as_secs_f64()
        })
        .collect();
    println!("sky view: {:.2} ms", median(sky_view) * 1e3);
    let eye = Vec3::new(0.0, 0.0, model.bottom_radius_m + camera.altitude_m);
    let view = sky.view(eye, &light);
    let volume: Vec<f64> = (0..runs)
        .map(|_| {
            let t0 = Instant::now();
            let _ = AerialVolume::new(
                view.as_ref(),
                eye,
                model.bottom_radius_m,
                &prepared,
                1920,
                1080,
                AerialVolumeConfig::default(),
                model.channels(),
            );
            t0.elapsed().as_secs_f64()
        })
        .collect();
    println!("aerial-perspective volume: {:.2} ms", median(volume) * 1e3);
}

//! What dropping the view–sun azimuth costs: the 3D table (Elek 2009 with Yusov 2013's
//! parameterisation, `sky::elek3d`) against the 4D tables (`sky::bruneton4d`, default
//! `TableConfig`), both at their default sizes in RGB.
//!
//! For each preset, altitude (0, 1 km, 10 km) and sun elevation (60, 30, 10, 5, 2, 0, −3°):
//! the median, 95th percentile and worst relative error of the luminance
//! (`model.colour_matrix().to_xyz(&radiance)[1]`) of `SkyView::sky_radiance` over a grid of
//! views (elevations −30…90°, azimuths 0…180° from the sun every 15°, views within 1° of
//! the sun left out), with the worst's signed error and view; then the precompute times.
//!
//! The figures in the 3D method's report come from
//! `cargo run --release -p firmament --example elek3d_accuracy -- earth hazy bruneton2008`
//! (no argument: `earth` only).

use std::time::Instant;

use firmament::atmosphere::{Atmosphere, Model};
use firmament::math::Vec3;
use firmament::scene::Light;
use firmament::sky::bruneton4d::{Bruneton4d, TableConfig};
use firmament::sky::elek3d::{Elek3d, Elek3dConfig};
use firmament::sky::{Shadow, SkyMethod};
use firmament::spectrum::Wavelengths;

const ALTITUDES_M: [f64; 3] = [0.0, 1_000.0, 10_000.0];
const SUN_ELEVATIONS_DEG: [f64; 7] = [60.0, 30.0, 10.0, 5.0, 2.0, 0.0, -3.0];
const VIEW_ELEVATIONS_DEG: [f64; 18] = [
    -30.0, -15.0, -5.0, -2.0, -1.0, 0.0, 0.5, 1.0, 2.0, 5.0, 10.0, 15.0, 20.0, 30.0, 45.0, 60.0,
    75.0, 90.0,
];

/// Unit direction at `elevation_deg` and `azimuth_deg` (from +x towards +y), z up.
fn direction(elevation_deg: f64, azimuth_deg: f64) -> Vec3 {
    let (e, a) = (elevation_deg.to_radians(), azimuth_deg.to_radians());
    Vec3::new(e.cos() * a.cos(), e.cos() * a.sin(), e.sin())
}

/// The signed relative luminance errors of every view and the worst one's view.
struct Errors {
    sorted_abs: Vec<f64>,
    worst: (f64, f64, f64),
}

fn errors(
    model: &Model,
    fast: &Elek3d,
    tables: &Bruneton4d,
    altitude: f64,
    sun_deg: f64,
) -> Errors {
    let colour = model.colour_matrix();
    let sun = direction(sun_deg, 0.0);
    let light = Light::sun(model, sun, false);
    let observer = Vec3::new(0.0, 0.0, model.bottom_radius_m + altitude);
    let (v3, v4) = (fast.view(observer, &light), tables.view(observer, &light));
    let n = model.channels();
    let (mut l3, mut l4) = (vec![0.0; n], vec![0.0; n]);
    let mut all = Vec::new();
    let mut worst = (0.0f64, 0.0, 0.0);
    for &e in &VIEW_ELEVATIONS_DEG {
        for a in (0..=12).map(|i| 15.0 * i as f64) {
            let dir = direction(e, a);
            if dir.dot(sun) > 1f64.to_radians().cos() {
                continue;
            }
            v3.sky_radiance(dir, Shadow::None, &mut l3, &mut []);
            v4.sky_radiance(dir, Shadow::None, &mut l4, &mut []);
            let (y3, y4) = (colour.to_xyz(&l3)[1], colour.to_xyz(&l4)[1]);
            if y4 <= 0.0 {
                continue;
            }
            let err = y3 / y4 - 1.0;
            all.push(err.abs());
            if err.abs() > worst.0.abs() {
                worst = (err, e, a);
            }
        }
    }
    all.sort_by(f64::total_cmp);
    Errors {
        sorted_abs: all,
        worst,
    }
}

fn percentile(sorted: &[f64], p: f64) -> f64 {
    let i = ((sorted.len() - 1) as f64 * p).round() as usize;
    sorted[i]
}

fn main() -> firmament::Result<()> {
    let mut presets: Vec<String> = std::env::args().skip(1).collect();
    if presets.is_empty() {
        presets.push("earth".into());
    }
    for preset in &presets {
        let model = Atmosphere::preset(preset)?.resolve(&Wavelengths::rgb())?;
        // Precompute times: the best of three (the machine may be shared).
        let mut fast_s = f64::INFINITY;
        let mut fast = None;
        for _ in 0..3 {
            let t = Instant::now();
            fast = Some(Elek3d::compute(model.clone(), &Elek3dConfig::default())?);
            fast_s = fast_s.min(t.elapsed().as_secs_f64());
        }
        let fast = fast.expect("computed");
        let t = Instant::now();
        let tables = Bruneton4d::compute(model.clone(), &TableConfig::default())?;
        let tables_s = t.elapsed().as_secs_f64();
        let threads = rayon::current_num_threads();
        println!(
            "{preset} (rgb): precompute 3D table {fast_s:.3} s, 4D tables {tables_s:.2} s \
             ({threads} threads)"
        );
        println!("  relative luminance error of the 3D table against the 4D tables");
        println!("  altitude  sun    median    p95     worst (at elevation, azimuth from the sun)");
        for &altitude in &ALTITUDES_M {
            for &sun in &SUN_ELEVATIONS_DEG {
                let e = errors(&model, &fast, &tables, altitude, sun);
                let (w, we, wa) = e.worst;
                println!(
                    "  {:6.0} m {:+5.0}°  {:6.2} %  {:6.2} %  {:+7.2} % ({we:+.1}°, {wa:.0}°)",
                    altitude,
                    sun,
                    100.0 * percentile(&e.sorted_abs, 0.5),
                    100.0 * percentile(&e.sorted_abs, 0.95),
                    100.0 * w,
                );
            }
        }
    }
    Ok(())
}

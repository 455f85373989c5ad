//! Hillaire 2020 against the 4D tables, preset by preset: the relative luminance difference
//! of the sky (views from −30° to the zenith, azimuths 0–180° from the sun, none within 1° of
//! it) from 0, 1 and 10 km under suns from 60° to −3°, for Hillaire's isotropic multiple
//! scattering and for firmament's harmonic second order, with each method's build time.
//! docs/accuracy.md quotes its output ("Hillaire 2020 against the 4D tables").
//!
//! ```text
//! cargo run --release -p firmament --example hillaire_vs_tables -- [PRESET,...] [rgb|spectral] [ORDERS]
//! ```
//!
//! ORDERS (default 2, Hillaire's) is the harmonic column's `multiple_scattering_orders`.

use std::time::Instant;

use firmament::atmosphere::{Atmosphere, Model};
use firmament::math::Vec3;
use firmament::scene::Light;
use firmament::sky::bruneton4d::{Bruneton4d, TableConfig};
use firmament::sky::hillaire2020::{Hillaire2020, HillaireConfig, MultipleScatteringModel};
use firmament::sky::{Shadow, SkyMethod};
use firmament::spectrum::Wavelengths;

/// Median, 95th percentile (nearest rank), signed median and the worst view of
/// `method / reference − 1` in luminance.
fn compare(
    model: &Model,
    method: &dyn SkyMethod,
    tables: &dyn SkyMethod,
    altitude: f64,
    sun_elevation: f64,
) -> (f64, f64, f64, (f64, f64, f64)) {
    let colour = model.colour_matrix();
    let e = sun_elevation.to_radians();
    let sun = Vec3::new(e.cos(), 0.0, e.sin());
    let light = Light::sun(model, sun, false);
    let observer = Vec3::new(0.0, 0.0, model.bottom_radius_m + altitude);
    let (a, b) = (method.view(observer, &light), tables.view(observer, &light));
    let n = model.channels();
    let (mut la, mut lb, mut t) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let mut errors = Vec::new();
    let mut worst = (0.0f64, 0.0, 0.0);
    for elevation in [
        -30.0f64, -5.0, -1.0, 0.5, 2.0, 5.0, 10.0, 25.0, 45.0, 70.0, 90.0,
    ] {
        for azimuth in [0.0f64, 30.0, 60.0, 90.0, 135.0, 180.0] {
            let (el, az) = (elevation.to_radians(), azimuth.to_radians());
            let d = Vec3::new(el.cos() * az.cos(), el.cos() * az.sin(), el.sin());
            if d.dot(sun) > 1f64.to_radians().cos() {
                continue;
            }
            a.sky_radiance(d, Shadow::None, &mut la, &mut t);
            b.sky_radiance(d, Shadow::None, &mut lb, &mut t);
            let (ya, yb) = (colour.to_xyz(&la)[1], colour.to_xyz(&lb)[1]);
            if yb > 0.0 {
                let r = ya / yb - 1.0;
                errors.push(r);
                if r.abs() > worst.0.abs() {
                    worst = (r, elevation, azimuth);
                }
            }
        }
    }
    let mut abs: Vec<f64> = errors.iter().map(|e| e.abs()).collect();
    abs.sort_by(f64::total_cmp);
    errors.sort_by(f64::total_cmp);
    let p95 = abs[((abs.len() as f64 * 0.95).ceil() as usize).clamp(1, abs.len()) - 1];
    (abs[abs.len() / 2], p95, errors[errors.len() / 2], worst)
}

fn main() -> firmament::Result<()> {
    let args: Vec<String> = std::env::args().collect();
    let presets = args
        .get(1)
        .cloned()
        .unwrap_or_else(|| "earth,bruneton2008,hazy,mars".into());
    let wavelengths = match args.get(2).map(String::as_str) {
        Some("spectral") => Wavelengths::spectral(),
        _ => Wavelengths::rgb(),
    };
    let orders = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(2);
    let harmonics = HillaireConfig {
        multiple_scattering_model: MultipleScatteringModel::Harmonics(6),
        multiple_scattering_orders: orders,
        multiple_scattering_directions: (24, 12),
        ..HillaireConfig::default()
    };
    for preset in presets.split(',') {
        let model = Atmosphere::preset(preset)?.resolve(&wavelengths)?;
        let t = Instant::now();
        let tables = Bruneton4d::compute(model.clone(), &TableConfig::default())?;
        let t_tables = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let iso = Hillaire2020::compute(model.clone(), &HillaireConfig::default());
        let t_iso = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let harm = Hillaire2020::compute(model.clone(), &harmonics);
        let t_harm = t.elapsed().as_secs_f64();
        let (iso, harm) = match (iso, harm) {
            (Ok(a), Ok(b)) => (a, b),
            (Err(e), _) | (_, Err(e)) => {
                println!("{preset}: {e}");
                continue;
            }
        };
        println!(
            "{preset}: 4D tables {t_tables:.1} s; hillaire2020 {:.0} ms (f_ms ≤ {:.2}), with harmonics {:.0} ms",
            t_iso * 1e3,
            iso.max_f_ms,
            t_harm * 1e3
        );
        println!("  altitude  sun   | isotropic: median   p95   bias  worst (elev, az) | harmonics(6), {orders} orders: median   p95   bias  worst");
        for altitude in [0.0, 1000.0, 10_000.0] {
            for sun in [60.0, 30.0, 10.0, 5.0, 2.0, 0.0, -3.0] {
                let a = compare(&model, &iso, &tables, altitude, sun);
                let b = compare(&model, &harm, &tables, altitude, sun);
                println!(
                    "  {:6.0} m {:5.1}° | {:6.2}% {:6.2}% {:+6.2}% {:+6.1}% ({}, {}) | {:6.2}% {:6.2}% {:+6.2}% {:+6.1}% ({}, {})",
                    altitude, sun,
                    100.0 * a.0, 100.0 * a.1, 100.0 * a.2, 100.0 * a.3 .0, a.3 .1, a.3 .2,
                    100.0 * b.0, 100.0 * b.1, 100.0 * b.2, 100.0 * b.3 .0, b.3 .1, b.3 .2,
                );
            }
        }
    }
    Ok(())
}

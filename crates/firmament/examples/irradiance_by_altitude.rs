//! The sky's irradiance on a horizontal surface above the ground (terrain, the air lit
//! from below): the 4D tables' irradiance table against the reference, at 550 nm, for a
//! few altitudes (errors and the reference's 1σ noise, %).
//!
//! ```text
//! cargo run --release -p firmament --example irradiance_by_altitude -- PRESET SUN_ELEVATION_DEG [PATHS]
//! ```
//!
//! Environment: `ALTITUDES=0,500,...` (m), `NR` (the irradiance table's r rows).
//! docs/accuracy.md ("The irradiance table along r") shows what it found.

use firmament::atmosphere::Atmosphere;
use firmament::math::{direction_from_zenith_azimuth, Vec3};
use firmament::reference::{irradiance, ReferenceSettings};
use firmament::scene::Light;
use firmament::sky::bruneton4d::{Bruneton4d, TableConfig, Tables};
use firmament::sky::SkyMethod;
use firmament::spectrum::Wavelengths;

fn main() -> firmament::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let preset = args.first().map(String::as_str).unwrap_or("hazy");
    let sun_elevation: f64 = args.get(1).map_or(30.0, |s| s.parse().expect("degrees"));
    let paths: usize = args.get(2).map_or(20000, |s| s.parse().expect("paths"));
    let model = Atmosphere::preset(preset)?.resolve(&Wavelengths::from_list(&[550.0])?)?;
    let sun = direction_from_zenith_azimuth((90.0 - sun_elevation).to_radians(), 0.0);
    let light = Light::sun(&model, sun, false);
    let altitudes: Vec<f64> = std::env::var("ALTITUDES")
        .unwrap_or_else(|_| "0,500,1000,1800,2800,4000,6000,10000".into())
        .split(',')
        .map(|s| s.parse().expect("metres"))
        .collect();
    let config = TableConfig {
        sizes: firmament::sky::bruneton4d::TableSizes {
            irradiance_r: std::env::var("NR").map_or(64, |v| v.parse().expect("NR")),
            ..Default::default()
        },
        ..TableConfig::default()
    };
    let sky = Bruneton4d::new(model.clone(), Tables::compute(&model, &config)?)?;
    println!("{preset}, sun {sun_elevation}°, 550 nm, {paths} paths; sky irradiance on a horizontal surface");
    for &h in &altitudes {
        let point = Vec3::new(0.0, 0.0, model.bottom_radius_m + h);
        let view = sky.view(point, &light);
        let (mut direct, mut diffuse) = (vec![0.0; 1], vec![0.0; 1]);
        view.sun_and_sky_irradiance(point, Vec3::Z, &mut direct, &mut diffuse);
        let truth = irradiance(
            &model,
            point,
            Vec3::Z,
            sun,
            &ReferenceSettings::with_samples(paths),
        );
        let e = 100.0 * (diffuse[0] / truth.irradiance[0] - 1.0);
        let noise = 100.0 * truth.stderr[0] / truth.irradiance[0];
        println!(
            "{h:7.0} m: tables {:.5}, reference {:.5} W m-2 nm-1: {e:+.2} ± {noise:.2} %",
            diffuse[0], truth.irradiance[0]
        );
    }
    Ok(())
}

//! Where a preset's table error enters, order by order: tables of N orders (no tail)
//! against the reference cut at N scattering events, and the default tables (4 orders +
//! tail, N = 0 below) against the full reference, at 550 nm, for a few views from one
//! altitude (errors and the reference's 1σ noise, %).
//!
//! ```text
//! cargo run --release -p firmament --example order_by_order -- PRESET SUN_ELEVATION_DEG [ALTITUDE_M] [PATHS]
//! ```
//!
//! Environment: `ORDERS=1,2,3,0` (the orders compared), `TAIL_AFTER` (the orders before the
//! tail of N = 0, default 4), `VIEWS=ELEVATION/AZIMUTH,...`
//! (degrees, azimuth from the sun), `NMU`, `NNU`, `NMUS`, `NR` (the scattering table's μ, ν,
//! μ_s and r sizes, to see whether a resolution is the cause). docs/accuracy.md ("Haze") shows what it found.

use firmament::atmosphere::Atmosphere;
use firmament::math::{direction_from_zenith_azimuth, Vec3};
use firmament::reference::{sky_radiance, ReferenceSettings};
use firmament::scene::Light;
use firmament::sky::bruneton4d::{Bruneton4d, TableConfig, Tables};
use firmament::sky::{Shadow, SkyMethod};
use firmament::spectrum::Wavelengths;

fn main() -> firmament::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let preset = args.first().map(String::as_str).unwrap_or("hazy");
    let sun_elevation: f64 = args.get(1).map_or(90.0, |s| s.parse().expect("degrees"));
    let altitude: f64 = args.get(2).map_or(0.0, |s| s.parse().expect("metres"));
    let paths: usize = args.get(3).map_or(20000, |s| s.parse().expect("paths"));
    let model = Atmosphere::preset(preset)?.resolve(&Wavelengths::from_list(&[550.0])?)?;
    let observer = Vec3::new(0.0, 0.0, model.bottom_radius_m + altitude);
    let sun = direction_from_zenith_azimuth((90.0 - sun_elevation).to_radians(), 0.0);
    let light = Light::sun(&model, sun, false);
    let views: Vec<(f64, f64)> = std::env::var("VIEWS")
        .unwrap_or_else(|_| "90/0,60/180,30/0,30/90,30/180,10/0,10/180,3/0,3/90,3/180,1/90".into())
        .split(',')
        .map(|v| {
            let (e, a) = v.split_once('/').expect("ELEVATION/AZIMUTH");
            (e.parse().expect("degrees"), a.parse().expect("degrees"))
        })
        .collect();
    println!("{preset}, sun {sun_elevation}°, {altitude} m, 550 nm, {paths} paths");
    let list: Vec<usize> = std::env::var("ORDERS")
        .unwrap_or_else(|_| "1,2,3,0".into())
        .split(',')
        .map(|s| s.parse().expect("orders"))
        .collect();
    let tail_after: usize = std::env::var("TAIL_AFTER").map_or(4, |v| v.parse().expect("orders"));
    for orders in list {
        let config = TableConfig {
            orders: if orders == 0 { tail_after } else { orders },
            order_tail: orders == 0,
            sizes: firmament::sky::bruneton4d::TableSizes {
                scattering_mu: std::env::var("NMU").map_or(128, |v| v.parse().expect("NMU")),
                scattering_nu: std::env::var("NNU").map_or(8, |v| v.parse().expect("NNU")),
                scattering_mu_s: std::env::var("NMUS").map_or(40, |v| v.parse().expect("NMUS")),
                scattering_r: std::env::var("NR").map_or(32, |v| v.parse().expect("NR")),
                ..Default::default()
            },
            ..TableConfig::default()
        };
        let sky = Bruneton4d::new(model.clone(), Tables::compute(&model, &config)?)?;
        let view = sky.view(observer, &light);
        let mut settings = ReferenceSettings::with_samples(paths);
        if orders > 0 {
            settings.max_bounces = orders;
        }
        let mut line = format!(
            "orders {}:",
            if orders == 0 {
                format!("{tail_after}+tail")
            } else {
                orders.to_string()
            }
        );
        let mut errors = Vec::new();
        for &(elevation, azimuth) in &views {
            let dir: Vec3 = direction_from_zenith_azimuth(
                (90.0f64 - elevation).to_radians(),
                azimuth.to_radians(),
            );
            let reference = sky_radiance(&model, observer, dir, sun, &settings);
            let (mut l, mut t) = (vec![0.0; 1], vec![0.0; 1]);
            view.sky_radiance(dir, Shadow::None, &mut l, &mut t);
            let e = 100.0 * (l[0] / reference.radiance[0] - 1.0);
            let noise = 100.0 * reference.stderr[0] / reference.radiance[0];
            errors.push(e);
            line += &format!(" {elevation}/{azimuth}: {e:+.2}±{noise:.2}");
        }
        errors.sort_by(f64::total_cmp);
        println!("{line}\n   median {:+.2} %", errors[errors.len() / 2]);
    }
    Ok(())
}

//! What the 4D tables' μ_s sampling costs in twilight: the sky of the default tables (40 μ_s
//! samples, 11 of them from −12° to 0°) against tables with four times the μ_s samples (and
//! of the irradiance table), at sun elevations between the samples, from the ground and from
//! 10 km, in five directions: the zenith; 80° and 88° from the zenith towards the sun; 80°
//! away from it; 60° at 90° of azimuth. Prints the relative difference at 550 nm (`rgb`,
//! earth) per direction. The interpolation along μ_s is `sky::bruneton4d::mu_s_blend`.
//!
//! `cargo run --release -p firmament --example twilight_interpolation`

use firmament::atmosphere::Atmosphere;
use firmament::math::{direction_from_zenith_azimuth, Vec3};
use firmament::scene::light::Light;
use firmament::sky::bruneton4d::{Bruneton4d, TableConfig, TableSizes, Tables};
use firmament::sky::{Shadow, SkyMethod};
use firmament::spectrum::Wavelengths;

fn main() {
    let model = Atmosphere::preset("earth")
        .unwrap()
        .resolve(&Wavelengths::rgb())
        .unwrap();
    let skies: Vec<Bruneton4d> = [1usize, 4]
        .iter()
        .map(|&factor| {
            let base = TableSizes::default();
            let sizes = TableSizes {
                scattering_mu_s: base.scattering_mu_s * factor,
                irradiance_mu_s: base.irradiance_mu_s * factor,
                ..base
            };
            let config = TableConfig {
                sizes,
                ..TableConfig::default()
            };
            let tables = Tables::compute(&model, &config).unwrap();
            Bruneton4d::new(model.clone(), tables).unwrap()
        })
        .collect();
    let views = [
        (0.0f64, 0.0f64),
        (80.0, 0.0),
        (88.0, 0.0),
        (80.0, 180.0),
        (60.0, 90.0),
    ];
    println!("| altitude | sun | zenith | 80° to sun | 88° to sun | 80° away | 60°, az 90° |");
    println!("|---|---|---|---|---|---|---|");
    for altitude_m in [0.0, 10_000.0] {
        let observer = Vec3::new(0.0, 0.0, model.bottom_radius_m + altitude_m);
        for elevation in [-1.5f64, -2.5, -3.5, -4.5, -5.5, -6.5, -7.5, -9.0, -11.0] {
            let sun = direction_from_zenith_azimuth((90.0 - elevation).to_radians(), 0.0);
            let light = Light::sun(&model, sun, false);
            let mut line = format!("| {} km | {elevation}° |", altitude_m / 1000.0);
            for (zenith, azimuth) in views {
                let dir = direction_from_zenith_azimuth(zenith.to_radians(), azimuth.to_radians());
                let radiance: Vec<f64> = skies
                    .iter()
                    .map(|sky| {
                        let view = sky.view(observer, &light);
                        let (mut l, mut t) = (vec![0.0; 3], vec![0.0; 3]);
                        view.sky_radiance(dir, Shadow::None, &mut l, &mut t);
                        l[1]
                    })
                    .collect();
                line += &format!(" {:+.1} % |", (radiance[0] / radiance[1] - 1.0) * 100.0);
            }
            println!("{line}");
        }
    }
}

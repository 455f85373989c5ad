//! The tables' ground row (ρ = 0) against the reference: its ground-ray texels take the next
//! row's directions (`params::ground_row_rho`), so that the scattering density interpolated
//! between the ground and the next row along a ray down to the ground is that of the ray's
//! direction, not of the nadir. Over `atmospheres/thick-shell.toml` (0.3 of a Titan-sized
//! planet's radius) the next row is 0.92 km up: from there, looking 3° down 30° from a 10°
//! sun, the second order (tables of 2 orders, reference cut at 2 events, 550 nm) read
//! −10.5 % with every ground texel at the nadir, −3.1 % with the ground row mended (10° down
//! at 90°: −5.0 %), −2.6 % / −4.3 % since the sky rows and ΔJ/β_s of 2026-12-06, −2.3 % /
//! −4.1 % with graded ray samples (2026-12-07).

mod common;

use firmament::atmosphere::Atmosphere;
use firmament::math::{direction_from_zenith_azimuth, Vec3};
use firmament::scene::Light;
use firmament::sky::bruneton4d::{params, Bruneton4d, TableConfig, TableSizes, Tables};
use firmament::sky::SkyMethod;
use firmament::spectrum::Wavelengths;

#[test]
fn second_order_down_to_the_ground_from_the_second_row_matches_the_reference() {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../atmospheres/thick-shell.toml");
    let model = Atmosphere::from_file(&path)
        .unwrap()
        .resolve(&Wavelengths::from_list(&[550.0]).unwrap())
        .unwrap();
    let sizes = TableSizes::default();
    let config = TableConfig {
        sizes,
        orders: 2,
        order_tail: false,
        ..TableConfig::default()
    };
    let sky = Bruneton4d::new(model.clone(), Tables::compute(&model, &config).unwrap()).unwrap();
    // The second row's altitude.
    let (bottom, top) = (model.bottom_radius_m, model.top_radius_m);
    let rho = params::ground_row_rho((top * top - bottom * bottom).sqrt(), sizes.scattering_r);
    let observer = Vec3::new(0.0, 0.0, (rho * rho + bottom * bottom).sqrt());
    let sun = direction_from_zenith_azimuth(80f64.to_radians(), 0.0);
    let light = Light::sun(&model, sun, false);
    let view = sky.view(observer, &light);
    for (elevation, azimuth) in [(-3.0f64, 30.0f64), (-10.0, 90.0)] {
        let dir =
            direction_from_zenith_azimuth((90.0 - elevation).to_radians(), azimuth.to_radians());
        let (error, noise) =
            common::error_against_cut_reference(&model, &*view, observer, sun, dir, 2, 40000);
        println!(
            "{elevation}°, azimuth {azimuth}°: {:+.2} % (reference ±{:.2} %)",
            100.0 * error,
            100.0 * noise
        );
        assert!(noise < 0.01);
        assert!(error.abs() < 0.06, "{elevation}°: {error}");
    }
}

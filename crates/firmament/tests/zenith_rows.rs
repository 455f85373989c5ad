//! The scattering table's sky rows near the zenith (`params::sky_x_from_distance_fraction`)
//! against the reference: under a zenith sun the multiple scattering of `hazy` is peaked
//! around the sun like the aerosols' phase function, and with Bruneton's rows (linear in the
//! distance to the top, the first above the zenith at 38° from the ground) the second order
//! read +6.7 % looking 60° up and +5.7 % at 65° (tables of 2 orders, reference cut at 2
//! events, 550 nm); +0.9 % and +0.6 % with them, +0.7 % and +0.5 % with graded ray samples.

mod common;

use firmament::atmosphere::Atmosphere;
use firmament::math::{direction_from_zenith_azimuth, Vec3};
use firmament::scene::Light;
use firmament::sky::bruneton4d::{Bruneton4d, TableConfig, Tables};
use firmament::sky::SkyMethod;
use firmament::spectrum::Wavelengths;

#[test]
fn second_order_of_a_hazy_sky_under_a_zenith_sun_matches_the_reference() {
    let model = Atmosphere::preset("hazy")
        .unwrap()
        .resolve(&Wavelengths::from_list(&[550.0]).unwrap())
        .unwrap();
    let config = TableConfig {
        orders: 2,
        order_tail: false,
        ..TableConfig::default()
    };
    let sky = Bruneton4d::new(model.clone(), Tables::compute(&model, &config).unwrap()).unwrap();
    let observer = Vec3::new(0.0, 0.0, model.bottom_radius_m);
    let sun = Vec3::new(0.0, 0.0, 1.0);
    let light = Light::sun(&model, sun, false);
    let view = sky.view(observer, &light);
    for elevation in [60.0f64, 65.0] {
        let dir = direction_from_zenith_azimuth((90.0 - elevation).to_radians(), 0.0);
        let (error, noise) =
            common::error_against_cut_reference(&model, &*view, observer, sun, dir, 2, 20000);
        println!(
            "{elevation}° up: {:+.2} % (reference ±{:.2} %)",
            100.0 * error,
            100.0 * noise
        );
        assert!(noise < 0.005);
        assert!(error.abs() < 0.025, "{elevation}°: {error}");
    }
}

//! A volume through the seam: a ball of homogeneous medium in the sky, rendered by the ray
//! marcher (render::Shader) and traced by the reference path tracer, which both sample it
//! through the `Volume` trait; and its transmittance against the closed form.

mod common;

use common::sky;

use firmament::math::Vec3;
use firmament::medium::PhaseFunction;
use firmament::reference::{self, ReferenceSettings};
use firmament::scene::{sun_direction, HomogeneousSphere, Ray, Scene, Volume};
use firmament::sky::bruneton4d::Bruneton4d;
use firmament::sky::{Shadow, SkyMethod};

/// A ball 1 km across, 1.5 km up, 5 km north of the observer: optical depth 0.2 through its
/// centre, single-scattering albedo `albedo`, forward-scattering HG phase.
fn puff(sky: &Bruneton4d, albedo: f64) -> HomogeneousSphere {
    let sigma_t = 2e-4;
    HomogeneousSphere {
        centre: Vec3::new(0.0, 5000.0, sky.model.bottom_radius_m + 1500.0),
        radius_m: 500.0,
        extinction: vec![sigma_t; 3],
        scattering: vec![albedo * sigma_t; 3],
        phase: PhaseFunction::HenyeyGreenstein { g: 0.6 },
    }
}

fn observer(sky: &Bruneton4d) -> Vec3 {
    Vec3::new(0.0, 0.0, sky.model.bottom_radius_m + 2.0)
}

/// Through a purely absorbing ball the marcher's transmittance is e^{−σ_t·chord}: what it
/// sees behind (less the air in front of the ball's mean depth) is attenuated by exactly
/// that (to 1e-5: the march's discrete mean depth against the continuous one).
#[test]
fn an_absorbing_ball_attenuates_by_beer_lambert() {
    let sky = sky();
    let ball = puff(sky, 0.0);
    let o = observer(sky);
    let sun = sun_direction(45.0, 180.0);
    let mut with = Scene::clear_sky(sky, sun, false);
    with.volumes.push(Box::new(ball.clone()));
    let without = Scene::clear_sky(sky, sun, false);
    for offset in [0.0, 200.0, 400.0] {
        let target = ball.centre + Vec3::new(offset, 0.0, 0.0);
        let dir = (target - o).normalize();
        let ray = Ray { origin: o, dir };
        let (a, b) = ball.bounds(&ray).unwrap();
        let tau = 2e-4 * (b - a);
        // The air's in-scattering in front of the ball's opacity-weighted mean depth,
        // a + 1/σ − L·e^{−σL}/(1 − e^{−σL}) for a chord L of constant σ.
        let (sigma, chord) = (2e-4, b - a);
        let mean = a + 1.0 / sigma - chord * (-tau).exp() / (1.0 - (-tau).exp());
        let front = {
            let view = sky.view(o, &without.lights[0]);
            let mut l = [0.0; 3];
            view.sky_radiance_to_point(o + mean * dir, Shadow::None, &mut l, &mut [0.0; 3]);
            l
        };
        let (l_with, l_without) = (
            common::shade(&with, o, dir),
            common::shade(&without, o, dir),
        );
        for k in 0..3 {
            let want = front[k] + (-tau).exp() * (l_without[k] - front[k]);
            assert!(
                (l_with[k] - want).abs() <= 1e-5 * want,
                "offset {offset}, channel {k}: {} vs {want}",
                l_with[k]
            );
        }
    }
}

/// The marcher (single scattering of the sun through the ball, an isotropic ambient term)
/// against the reference (every order, the ball's own shadowing of the sky included) for
/// rays through a scattering ball: luminance within the tolerance below; the figures are
/// printed for docs/accuracy.md.
#[test]
fn a_scattering_ball_matches_the_reference() {
    let sky = sky();
    let model = &sky.model;
    let ball = puff(sky, 0.9);
    let o = observer(sky);
    let sun = sun_direction(45.0, 180.0);
    let mut scene = Scene::clear_sky(sky, sun, false);
    scene.volumes.push(Box::new(ball.clone()));
    let volumes: Vec<Box<dyn Volume>> = vec![Box::new(ball.clone())];
    let colour = model.colour_matrix();
    let settings = ReferenceSettings::with_samples(16_384);
    let mut worst: f64 = 0.0;
    for (i, offset) in [(0.0, 0.0), (300.0, 0.0), (0.0, 350.0), (-420.0, 0.0)]
        .into_iter()
        .enumerate()
    {
        let target = ball.centre + Vec3::new(offset.0, 0.0, offset.1);
        let dir = (target - o).normalize();
        let fast = colour.to_xyz(&common::shade(&scene, o, dir))[1];
        let e = reference::scene_radiance(model, &volumes, &[], o, dir, sun, &settings, i as u64);
        let (truth, se) = colour.luminance_and_stderr(&e.radiance, &e.stderr);
        let clear = reference::sky_radiance_keyed(model, o, dir, sun, &settings, 100 + i as u64);
        let (sky_only, _) = colour.luminance_and_stderr(&clear.radiance, &clear.stderr);
        let err = fast / truth - 1.0;
        println!(
            "ray {i} ({:+.0} m, {:+.0} m): marcher {fast:.1} cd/m², reference {truth:.1} ± {se:.1} (clear sky {sky_only:.1}): {:+.2} %",
            offset.0,
            offset.1,
            100.0 * err
        );
        worst = worst.max(err.abs());
        // The ball shows in the reference: brighter than the clear sky behind it (by 4–9 %;
        // ray 3's 4.9 % is within 2σ of the two estimates' noise of 1.05).
        assert!(
            truth > 1.03 * sky_only,
            "ray {i}: {truth} vs clear {sky_only}"
        );
    }
    // Measured: −1.6 to −3.4 % (the reference at 1.0 % noise): the marcher leaves out the
    // ball's own multiple scattering of the sun. Until 2026-12-07 it read +0.4 to +1.3 %,
    // its ambient term taken from an irradiance table 16 rows tall whose sky light 0.5–3 km
    // up was 13–32 % too bright (docs/accuracy.md, "The irradiance table along r"), which
    // hid that deficit.
    assert!(
        worst < 0.04,
        "largest luminance error {:.2} %",
        100.0 * worst
    );
}

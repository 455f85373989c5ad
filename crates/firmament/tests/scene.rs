//! The seams: a second surface and a second light enter a scene through `Scene` alone (the
//! render loop does not change), and the parts of a ray in shadow are left out exactly
//! (`Shadow::Lit`) against an independent quadrature of single scattering.

mod common;

use common::sky;

use firmament::atmosphere::Atmosphere;
use firmament::math::Vec3;
use firmament::render::{self, RenderSettings};
use firmament::scene::{sun_direction, Camera, Light, Projection, Ray, Scene, Sphere, Surface};
use firmament::sky::bruneton4d::{Bruneton4d, TableConfig};
use firmament::sky::{Shadow, SkyMethod};
use firmament::spectrum::Wavelengths;

const CAMERA_ALTITUDE_M: f64 = 2.0;

fn observer(sky: &Bruneton4d) -> Vec3 {
    Vec3::new(0.0, 0.0, sky.model.bottom_radius_m + CAMERA_ALTITUDE_M)
}

/// A grey ball 300 m across, 1 km up, 3 km north of the observer.
fn balloon(sky: &Bruneton4d) -> Sphere {
    Sphere {
        centre: Vec3::new(0.0, 3000.0, sky.model.bottom_radius_m + 1000.0),
        radius_m: 150.0,
        albedo: vec![0.6; 3],
        casts_shadows: true,
    }
}

/// The sun 40° high in the south, behind the observer, and a dimmer, redder light from the
/// west.
fn lights(sky: &Bruneton4d) -> [Light; 2] {
    let sun = Light::sun(&sky.model, sun_direction(50.0, 180.0), true);
    let mut second = Light::sun(&sky.model, sun_direction(70.0, 280.0), false);
    for (k, e) in second.irradiance.iter_mut().enumerate() {
        *e *= [0.3, 0.2, 0.1][k];
    }
    [sun, second]
}

fn scene<'a>(sky: &'a Bruneton4d, lights: &[Light], ball: bool) -> Scene<'a> {
    let mut scene = Scene::clear_sky(sky, Vec3::Z, false);
    scene.lights = lights.to_vec();
    if ball {
        scene.surfaces.push(Box::new(balloon(sky)));
    }
    scene
}

/// The scene's radiance along `dir` from the observer.
fn shade(scene: &Scene, dir: Vec3) -> [f64; 3] {
    let origin = Vec3::new(
        0.0,
        0.0,
        scene.sky.model().bottom_radius_m + CAMERA_ALTITUDE_M,
    );
    common::shade(scene, origin, dir)
}

/// Frames are linear in the lights: the scene with both equals the sum of the scenes with
/// each, pixel by pixel; and the ball appears where its rays hit it.
#[test]
fn a_second_light_and_a_second_surface_enter_through_the_scene() {
    let sky = sky();
    let [a, b] = lights(sky);
    let camera = Camera {
        projection: Projection::Perspective,
        altitude_m: CAMERA_ALTITUDE_M,
        heading_deg: 0.0,
        pitch_deg: 15.0,
        roll_deg: 0.0,
        fov_deg: 40.0,
    };
    let settings = RenderSettings {
        camera: &camera,
        width: 48,
        height: 32,
        white_balance: false,
    };
    let frame = |lights: &[Light]| {
        render::render(&scene(sky, lights, true), &settings, &|_| {}, None).unwrap()
    };
    let (both, only_a, only_b) = (
        frame(&[a.clone(), b.clone()]),
        frame(std::slice::from_ref(&a)),
        frame(std::slice::from_ref(&b)),
    );
    for ((p, q), r) in both
        .image
        .data
        .iter()
        .zip(&only_a.image.data)
        .zip(&only_b.image.data)
    {
        for c in 0..3 {
            let sum = q[c] + r[c];
            assert!(
                (p[c] - sum).abs() <= 1e-5 * sum.abs() + 1e-12,
                "{p:?} vs {q:?} + {r:?}"
            );
        }
    }
    // The pixels whose rays hit the ball, and only those, differ from the clear sky.
    let clear = render::render(
        &scene(sky, &[a.clone(), b.clone()], false),
        &settings,
        &|_| {},
        None,
    )
    .unwrap();
    let prepared = camera.prepare(sky.model.bottom_radius_m, 48, 32);
    let ball = balloon(sky);
    let (mut hits, mut changed) = (0, 0);
    for y in 0..32 {
        for x in 0..48 {
            let ray = prepared.ray(x as f64 + 0.5, y as f64 + 0.5).unwrap();
            let hit = ball.intersect(&ray, f64::INFINITY).is_some();
            let differs = both.image.get(x, y) != clear.image.get(x, y);
            hits += hit as usize;
            changed += differs as usize;
            // Sky rays that pass behind the ball in its shadow also change (light shafts).
            assert!(!hit || differs, "ball pixel ({x}, {y}) unchanged");
        }
    }
    assert!(hits >= 12, "the ball covers {hits} pixels");
    assert!(changed >= hits);
}

/// The light the ball reflects (its radiance minus that of the same ball with albedo 0) is
/// several times larger seen from the sun's side than from the other, where only the sky
/// lights it; the ground in its shadow receives the sky's light only (its radiance is the
/// aerial perspective plus albedo/π·E_sky·T, from the same view).
#[test]
fn the_ball_is_lit_from_the_sun_and_shadows_the_ground() {
    let sky = sky();
    let [sun, _] = lights(sky);
    let scene = scene(sky, std::slice::from_ref(&sun), true);
    let ball = balloon(sky);
    let o = observer(sky);
    let at_ball = (ball.centre - o).normalize();
    let reflected = |light: &Light| {
        let mut lit = self::scene(sky, std::slice::from_ref(light), false);
        let mut black = self::scene(sky, std::slice::from_ref(light), false);
        lit.surfaces.push(Box::new(balloon(sky)));
        black.surfaces.push(Box::new(Sphere {
            albedo: vec![0.0; 3],
            ..balloon(sky)
        }));
        let (a, b) = (shade(&lit, at_ball), shade(&black, at_ball));
        [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
    };
    // The same sun behind the ball (north) instead of behind the observer.
    let mut back = sun.clone();
    back.direction = Vec3::new(0.0, -sun.direction.y, sun.direction.z);
    let (front, behind) = (reflected(&sun), reflected(&back));
    for k in 0..3 {
        assert!(
            behind[k] > 0.0 && front[k] > 3.0 * behind[k],
            "front {front:?} behind {behind:?}"
        );
    }
    // The ground point below the ball along the sun's rays.
    let centre = ball.centre;
    let down = -sun.direction;
    let r_g = sky.model.bottom_radius_m;
    let b = centre.dot(down);
    let t = -b - (b * b - centre.dot(centre) + r_g * r_g).sqrt();
    let shadow_point = centre + t * down;
    let dir = (shadow_point - o).normalize();
    let got = shade(&scene, dir);
    let view = sky.view(o, &sun);
    let (mut ap, mut tr, mut direct, mut e_sky) = ([0.0; 3], [0.0; 3], [0.0; 3], [0.0; 3]);
    let hit = Sphere::ground(&sky.model)
        .intersect(&Ray { origin: o, dir }, f64::INFINITY)
        .unwrap();
    view.sky_radiance_to_point(hit.position, Shadow::None, &mut ap, &mut tr);
    view.sun_and_sky_irradiance(hit.position, hit.normal, &mut direct, &mut e_sky);
    for k in 0..3 {
        let want = ap[k] + sky.model.ground_albedo[k] / std::f64::consts::PI * e_sky[k] * tr[k];
        // The lit interval ends at the ground point in shadow; the air in front is lit up
        // to where the view ray enters the shadow, so the in-scattering is a little lower.
        assert!(
            got[k] <= want * (1.0 + 1e-9) && got[k] > 0.8 * want,
            "channel {k}: {} vs {want}",
            got[k]
        );
    }
    // Next to the shadow the sun adds its direct light.
    let beside = shade(&scene, (shadow_point + 600.0 * Vec3::X - o).normalize());
    assert!(beside[1] > 2.0 * got[1], "beside {beside:?} shadow {got:?}");
}

/// Lit intervals add up: the single scattering over [0, a] plus over [a, ∞) is that of the
/// whole ray, towards the sky and towards a point, and the multiple scattering is the whole
/// ray's whatever is lit (`Shadow::Lit(&[])` gives it alone); the shadowed length (the
/// paper's, which leaves both orders out) lies between the lit interval after it with and
/// without the multiple scattering before it.
#[test]
fn lit_intervals_add_up_to_the_whole_ray() {
    let sky = sky();
    let sun = Light::sun(&sky.model, sun_direction(60.0, 0.0), false);
    let o = Vec3::new(0.0, 0.0, sky.model.bottom_radius_m + 500.0);
    let view = sky.view(o, &sun);
    let mut t = [0.0; 3];
    let radiance = |dir: Vec3, shadow: Shadow| {
        let mut l = [0.0; 3];
        view.sky_radiance(dir, shadow, &mut l, &mut []);
        l
    };
    for elevation in [2.0f64, 10.0, 45.0] {
        let dir = sun_direction(90.0 - elevation, 20.0);
        let whole = radiance(dir, Shadow::None);
        let multiple = radiance(dir, Shadow::Lit(&[]));
        for a in [1_000.0, 10_000.0, 50_000.0] {
            let first = radiance(dir, Shadow::Lit(&[(0.0, a)]));
            let rest = radiance(dir, Shadow::Lit(&[(a, f64::INFINITY)]));
            let length = radiance(dir, Shadow::Length(a));
            for k in 0..3 {
                assert!(multiple[k] > 0.0 && multiple[k] < whole[k]);
                assert!(
                    (first[k] + rest[k] - multiple[k] - whole[k]).abs() <= 1e-6 * whole[k],
                    "elevation {elevation}, a {a}: {} + {} − {} vs {}",
                    first[k],
                    rest[k],
                    multiple[k],
                    whole[k]
                );
                assert!(length[k] <= rest[k] * (1.0 + 1e-9), "{length:?} {rest:?}");
                assert!(length[k] >= rest[k] - multiple[k] - 1e-9 * whole[k]);
            }
        }
        // Towards a point 20 km along the ray.
        let point = o + 20_000.0 * dir;
        let mut to_point = |shadow: Shadow| {
            let mut l = [0.0; 3];
            view.sky_radiance_to_point(point, shadow, &mut l, &mut t);
            l
        };
        let whole = to_point(Shadow::None);
        let multiple = to_point(Shadow::Lit(&[]));
        let near = to_point(Shadow::Lit(&[(0.0, 5_000.0)]));
        let far = to_point(Shadow::Lit(&[(5_000.0, 20_000.0)]));
        let length = to_point(Shadow::Length(15_000.0));
        for k in 0..3 {
            assert!((near[k] + far[k] - multiple[k] - whole[k]).abs() <= 1e-6 * whole[k]);
            assert!(length[k] <= near[k] * (1.0 + 1e-9));
            assert!(length[k] >= near[k] - multiple[k] - 1e-9 * whole[k]);
        }
    }
}

/// Single scattering over a lit interval of a ray against an independent quadrature (the
/// same as tables.rs's: midpoint rule in 5 m steps, the sun's transmittance from the model's
/// columns): tables with one order and default sizes, the ray from 1 km at 10° elevation,
/// lit from 5 to 40 km only. The whole ray is compared too: the lit part must be as
/// accurate as the tables themselves.
#[test]
fn shadowed_single_scattering_matches_a_quadrature_of_the_lit_part() {
    let model = Atmosphere::earth().resolve(&Wavelengths::rgb()).unwrap();
    let config = TableConfig {
        orders: 1,
        ..Default::default()
    };
    let sky = Bruneton4d::compute(model, &config).unwrap();
    let model = &sky.model;
    let sun = Light::sun(model, sun_direction(50.0, 180.0), false);
    let r0 = model.bottom_radius_m + 1000.0;
    let o = Vec3::new(0.0, 0.0, r0);
    let dir = sun_direction(80.0, 30.0);
    let (a, b) = (5_000.0, 40_000.0);
    let view = sky.view(o, &sun);
    let (mut lit, mut whole) = ([0.0; 3], [0.0; 3]);
    view.sky_radiance(dir, Shadow::Lit(&[(a, b)]), &mut lit, &mut []);
    view.sky_radiance(dir, Shadow::None, &mut whole, &mut []);
    // ∫ Σ_c ρ_c β_c P_c(ν) · T(0, s) · T_sun(s) · E ds over the lit part and the whole ray.
    let (mut brute_lit, mut brute_whole) = ([0.0f64; 3], [0.0f64; 3]);
    common::single_scattering_steps(model, o, dir, sun.direction, 5.0, |m, dl| {
        for k in 0..3 {
            brute_whole[k] += dl[k];
            if m > a && m < b {
                brute_lit[k] += dl[k];
            }
        }
    });
    for k in 0..3 {
        let e_lit = lit[k] / brute_lit[k] - 1.0;
        let e_whole = whole[k] / brute_whole[k] - 1.0;
        println!("channel {k}: lit [5, 40] km {e_lit:+.4}, whole ray {e_whole:+.4} (table/quadrature − 1)");
        assert!(e_lit.abs() < 0.015, "channel {k}: lit {e_lit:+.4}");
        assert!(
            (e_lit - e_whole).abs() < 0.01,
            "channel {k}: lit {e_lit:+.4} whole {e_whole:+.4}"
        );
    }
}

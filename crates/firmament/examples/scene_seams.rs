//! A scene built through the seams alone: the 4D tables as the sky method, a ball as a second
//! surface that hides a low sun and casts a shadow through the air (light shafts through
//! `Shadow::Lit`), and a ball of fog as a volume. Nothing in the render loop knows of either.
//!
//! `cargo run --release -p firmament --example scene_seams -- out.png [width]`

use firmament::atmosphere::Atmosphere;
use firmament::math::Vec3;
use firmament::medium::phase::PhaseFunction;
use firmament::render::{self, tonemap, RenderSettings, ToneCurve};
use firmament::scene::{sun_direction, Camera, HomogeneousSphere, Projection, Scene, Sphere};
use firmament::sky::bruneton4d::{Bruneton4d, TableConfig};
use firmament::spectrum::Wavelengths;

fn main() -> firmament::Result<()> {
    let mut args = std::env::args().skip(1);
    let out = args.next().unwrap_or_else(|| "scene_seams.png".into());
    let width: usize = args
        .next()
        .map_or(640, |w| w.parse().expect("width: an integer"));
    let model = Atmosphere::earth().resolve(&Wavelengths::rgb())?;
    let sky = Bruneton4d::compute(model, &TableConfig::default())?;
    let ground = sky.model.bottom_radius_m;

    let camera = Camera {
        projection: Projection::Perspective,
        altitude_m: 2.0,
        heading_deg: 245.0,
        pitch_deg: 7.0,
        roll_deg: 0.0,
        fov_deg: 50.0,
    };
    let observer = Vec3::new(0.0, 0.0, ground + camera.altitude_m);
    // The sun 6° high in the west-south-west.
    let sun = sun_direction(84.0, 250.0);
    let mut scene = Scene::clear_sky(&sky, sun, true);
    // A ball 3 km across, 20 km away, just beside the sun: its shadow through the air passes
    // beside the observer and shows as a dark shaft widening towards the viewer.
    scene.surfaces.push(Box::new(Sphere {
        centre: observer + sun_direction(81.0, 257.0) * 20_000.0,
        radius_m: 1_500.0,
        albedo: vec![0.3; 3],
        casts_shadows: true,
    }));
    // A ball of fog 1.2 km across, 5 km away to the south-west, sitting on the ground; optical
    // thickness 1.2 across its diameter, single-scattering albedo 0.95, forward scattering.
    let fog_dir = sun_direction(90.0, 225.0);
    scene.volumes.push(Box::new(HomogeneousSphere {
        centre: observer + fog_dir * 5_000.0 + Vec3::Z * 300.0,
        radius_m: 600.0,
        extinction: vec![1e-3; 3],
        scattering: vec![0.95e-3; 3],
        phase: PhaseFunction::HenyeyGreenstein { g: 0.7 },
    }));

    let settings = RenderSettings {
        camera: &camera,
        width,
        height: width * 9 / 16,
        white_balance: true,
    };
    let frame = render::render(&scene, &settings, &|_| {}, None)?;
    let ev100 = tonemap::auto_ev100(frame.log_average_luminance());
    let rgb8 = frame.to_srgb8(
        tonemap::exposure_from_ev100(ev100, ToneCurve::Aces),
        ToneCurve::Aces,
    );
    firmament::io::write_png_srgb8(&out, settings.width, settings.height, &rgb8)?;
    eprintln!("{out}: EV100 {ev100:.1}");
    Ok(())
}

//! How many lit intervals the terrain leaves along a view ray: the default scene's valley
//! (its full-resolution terrain, the camera 25 m over the floor looking towards the 5.5° sun
//! behind the ridges), every pixel's ray to the terrain or 300 km, the terrain's shadowed
//! intervals for the sun (`Surface::shadowed_intervals`, exact) turned into lit ones
//! (`scene::surface::lit_intervals`). The GPU's cloud frame walks at most
//! `MAX_TERRAIN_LIT` (256) of them per ray before it counts the rest as shadowed
//! (`shaders/render/cloud_frame.wgsl`); this measures how far real rays are from that cap.
//!
//! `cargo run --release -p firmament --example terrain_lit_intervals -- [width height
//! [above_m pitch_deg]]` (the default camera's 25 m and 6° otherwise).

use firmament::scene::surface::lit_intervals;
use firmament::scene::{sun_direction, SceneFile, Surface};
use firmament::spectrum::Wavelengths;

fn main() -> firmament::Result<()> {
    let mut args = std::env::args().skip(1);
    let mut next = |default: usize| {
        args.next()
            .map_or(default, |a| a.parse().expect("a size: an integer"))
    };
    let (width, height) = (next(480), next(270));
    let mut scene = SceneFile::default();
    if let (Some(above), Some(pitch)) = (args.next(), args.next()) {
        scene.camera.altitude_m = above.parse().expect("above_m: a number");
        scene.camera.pitch_deg = pitch.parse().expect("pitch_deg: a number");
    }
    let config = scene
        .terrain
        .clone()
        .expect("the default scene has a terrain");
    let radius = firmament::atmosphere::Atmosphere::earth()
        .resolve(&Wavelengths::rgb())?
        .bottom_radius_m;
    let terrain = config.build(radius, Wavelengths::rgb().nm())?;
    // The camera `altitude_m` over the terrain under it, on the terrain's sphere.
    let mut camera = scene.camera.clone();
    camera.altitude_m += terrain.height_at(0.0, 0.0);
    let prepared = camera.prepare(terrain.radius_m, width, height);
    let sun = sun_direction(scene.sun.zenith_deg, scene.sun.azimuth_deg);
    let mut counts = Vec::with_capacity(width * height);
    let (mut shadowed, mut lit) = (Vec::new(), Vec::new());
    for y in 0..height {
        for x in 0..width {
            let ray = prepared
                .ray(x as f64 + 0.5, y as f64 + 0.5)
                .expect("a perspective camera");
            let end = terrain
                .intersect(&ray, 300e3)
                .map_or(300e3, |h| h.distance_m);
            shadowed.clear();
            lit.clear();
            terrain.shadowed_intervals(&ray, sun, end, &mut shadowed);
            lit_intervals(&mut shadowed, end, &mut lit);
            counts.push(lit.len());
        }
    }
    counts.sort_unstable();
    let at = |q: f64| counts[((counts.len() - 1) as f64 * q).round() as usize];
    let over = counts.iter().filter(|&&c| c > 256).count();
    println!(
        "{width}×{height} rays: lit intervals per ray median {}, p99 {}, p99.9 {}, max {}; over 256: {over}",
        at(0.5),
        at(0.99),
        at(0.999),
        counts[counts.len() - 1]
    );
    Ok(())
}

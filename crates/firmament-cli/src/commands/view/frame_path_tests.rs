//! The viewer's frame path when the atmosphere changes under it (on the test adapter:
//! lavapipe in CI): the 4D tables' amortised update draws the previous tables until its
//! swap, then what a fresh sky of the new atmosphere draws; Hillaire 2020 re-runs its
//! tables at once with its passes kept.

use super::*;
use crate::backend::Gpu;
use crate::commands::view::progressive::Compare;
use firmament::scene::SceneFile;

/// Set in the child process a GPU test runs in ([`backend`]).
const CHILD: &str = "FIRMAMENT_VIEW_GPU_TEST_CHILD";

/// The test adapter as the viewer's backend, or None: outside CI without an adapter
/// (skipped), and in the test's own process, which runs the test `name` again in a child
/// process (this binary, `--exact name`) and returns None once it passed. A child that dies
/// of the test driver's heap corruption ([`firmament_gpu::driver_crash`]) is run again, up
/// to six times (this binary's GPU tests, in one process, aborted in 8 of 19 runs on
/// 2026-12-05). A child that fails otherwise fails the test with its output.
/// The lock keeps the children one at a time (lavapipe uses every core).
fn backend(name: &str) -> Option<(&'static Backend, std::sync::MutexGuard<'static, ()>)> {
    static LOCK: std::sync::Mutex<()> = std::sync::Mutex::new(());
    let guard = LOCK.lock().unwrap_or_else(|e| e.into_inner());
    if std::env::var_os(CHILD).is_some() {
        let ctx = firmament_gpu::test_context()?;
        let backend: &'static Backend = Box::leak(Box::new(Backend::Gpu(Box::new(Gpu { ctx }))));
        return Some((backend, guard));
    }
    let path = module_path!().split_once("::").map_or("", |(_, rest)| rest);
    let test = format!("{path}::{name}");
    let exe = std::env::current_exe().expect("the test binary");
    for attempt in 1..=6 {
        let out = std::process::Command::new(&exe)
            .args([
                test.as_str(),
                "--exact",
                "--nocapture",
                "--test-threads",
                "1",
            ])
            .env(CHILD, "1")
            .output()
            .expect("running the test binary");
        let text = format!(
            "{}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        );
        if out.status.success() {
            assert!(text.contains("1 passed"), "{test} did not run: {text}");
            eprintln!("{text}");
            return None;
        }
        let Some(why) = firmament_gpu::driver_crash(&out.status, &text) else {
            panic!("{test} failed in its process:\n{text}");
        };
        eprintln!(
            "attempt {attempt}: {test} {why} ({}): lavapipe's heap corruption, running it again",
            out.status
        );
    }
    panic!("{test}: crashed six times");
}

/// A small clear-sky view in RGB under a 30° sun, looking at the horizon.
fn view(method: Method) -> ViewState {
    let mut scene = SceneFile {
        terrain: None,
        clouds: Vec::new(),
        ..SceneFile::default()
    };
    scene.atmosphere.wavelengths = Some("rgb".into());
    scene.sun.zenith_deg = 60.0;
    scene.camera.pitch_deg = 10.0;
    let mut state = ViewState::new(scene, method, true);
    state.render_scale = 1.0;
    state
}

const SIZE: (u32, u32) = (48, 27);

fn frame(path: &mut FramePath, state: &ViewState) -> Vec<[f32; 3]> {
    let display = display_settings(state, 1.0 / 60.0, false);
    path.draw_offscreen(state, SIZE, display)
        .unwrap()
        .0
        .image
        .data
}

/// Mean relative luminance difference of two frames.
fn mean_rel(a: &[[f32; 3]], b: &[[f32; 3]]) -> f64 {
    let y = |p: &[f32; 3]| crate::commands::view::difference::luminance(p);
    let sum: f64 = a
        .iter()
        .zip(b)
        .map(|(p, q)| (y(p) - y(q)).abs() / y(q).max(1e-9))
        .sum();
    sum / a.len() as f64
}

#[test]
fn a_new_atmosphere_reaches_the_4d_view_over_frames_and_never_stalls_it() {
    let Some((backend, _serial)) =
        backend("a_new_atmosphere_reaches_the_4d_view_over_frames_and_never_stalls_it")
    else {
        return;
    };
    if !backend_is_software(backend) {
        // Hardware adapters compute the 4D tables on the device at once (not amortised).
        return;
    }
    let mut state = view(Method::Bruneton4d);
    let mut path = FramePath::new(backend, &state, None, "small").unwrap();
    let before = frame(&mut path, &state);
    state.update_frames = 3;
    state.scene.atmosphere.adjust.aerosol_optical_depth = Some(0.6);
    // Frames 1 and 2 of 3: the previous tables, drawn bit for bit, the update reported.
    for k in 1..=2 {
        let f = frame(&mut path, &state);
        assert_eq!(f, before, "frame {k} of the update drew other tables");
        let line = path.update_line().expect("an update in flight");
        assert!(line.contains("frames left"), "{line}");
    }
    // Frame 3 swaps the new tables in: the haze brightens the sky near the horizon.
    let after = frame(&mut path, &state);
    assert!(path.update_line().is_none());
    let change = mean_rel(&after, &before);
    assert!(change > 0.05, "the haze changed the frame by {change}");
    // What a fresh sky of the hazy atmosphere draws (its tables from the cache or
    // computed directly: the same texels).
    let mut fresh = FramePath::new(backend, &state, None, "small").unwrap();
    let direct = frame(&mut fresh, &state);
    let d = mean_rel(&after, &direct);
    eprintln!("amortised vs fresh: mean |ΔL|/L {d:.2e} (the update changed it by {change:.3})");
    // The cache keeps half floats (docs/accuracy.md): 4.6e-5 here.
    assert!(d < 5e-4, "amortised vs fresh sky: {d}");
}

#[test]
fn hillaire_redraws_a_new_atmosphere_in_the_next_frame() {
    let Some((backend, _serial)) = backend("hillaire_redraws_a_new_atmosphere_in_the_next_frame")
    else {
        return;
    };
    let mut state = view(Method::Hillaire2020);
    let mut path = FramePath::new(backend, &state, None, "small").unwrap();
    let before = frame(&mut path, &state);
    state.scene.atmosphere.adjust.ozone_du = Some(600.0);
    state.scene.atmosphere.adjust.rayleigh_scale = Some(1.5);
    let after = frame(&mut path, &state);
    assert!(path.update_line().is_none());
    let change = mean_rel(&after, &before);
    let mut fresh = FramePath::new(backend, &state, None, "small").unwrap();
    let direct = frame(&mut fresh, &state);
    let d = mean_rel(&after, &direct);
    eprintln!("hillaire retabled vs fresh: mean |ΔL|/L {d:.2e} (the change {change:.3})");
    assert!(
        change > 0.05,
        "more air and ozone changed the frame by {change}"
    );
    assert!(d < 1e-5, "retabled vs fresh sky: {d}");
}

#[test]
fn beside_the_reference_every_pixel_is_marched() {
    let mut state = view(Method::Bruneton4d);
    assert_eq!(super::march_step(&state), 2);
    state.march_step = 4;
    assert_eq!(super::march_step(&state), 4);
    state.compare = Compare::Difference;
    assert_eq!(super::march_step(&state), 1);
}

#[test]
fn the_panel_compares_the_method_with_the_reference_over_the_frame() {
    let Some((backend, _serial)) =
        backend("the_panel_compares_the_method_with_the_reference_over_the_frame")
    else {
        return;
    };
    let mut state = view(Method::Bruneton4d);
    state.compare = Compare::Whole;
    let mut path = FramePath::new(backend, &state, None, "small").unwrap();
    let size = (32, 18);
    let display = display_settings(&state, 1.0 / 60.0, false);
    path.draw_offscreen(&state, size, display).unwrap();
    path.wait_for_reference(4).unwrap();
    // The next frame uploads the passes and compares the method's frame with them.
    let (shown, _) = path.draw_offscreen(&state, size, display).unwrap();
    let (bias, mean_abs) = path.reference_difference().expect("a comparison");
    eprintln!(
        "4D tables against 8 paths/λ of the reference: mean {bias:+.4}, |ΔL|/L {mean_abs:.3}"
    );
    // The small tables are within a few percent of the reference in daylight (`validate
    // --quick`); 8 paths/λ over 576 pixels leave about a percent of noise in the mean, and
    // tens of percent per pixel. The sun's disk, splatted by the method and drawn by centre
    // rays by the tracer, is compared apart (a sliver of its splat at the frame's edge read
    // +5 % over the whole frame before).
    assert!(bias.abs() < 0.05, "{bias}");
    assert!(mean_abs > 0.01 && mean_abs < 0.6, "{mean_abs}");
    // What is shown is the reference's average (whole).
    assert!(path.reference_line().unwrap().contains("passes"));
    assert_eq!(shown.image.width, 32);
}

fn backend_is_software(backend: &Backend) -> bool {
    matches!(backend, Backend::Gpu(g) if g.ctx.is_software())
}

#[test]
fn the_planet_map_is_drawn_and_follows_the_place_without_a_new_texture() {
    let Some((backend, _serial)) =
        backend("the_planet_map_is_drawn_and_follows_the_place_without_a_new_texture")
    else {
        return;
    };
    let text = r#"
        [atmosphere]
        wavelengths = "rgb"
        [camera]
        projection = "orbit"
        altitude_m = 30000000.0
        fov_deg = 23.4
        [sun]
        zenith_deg = 40.0
        azimuth_deg = 90.0
        [surface]
        [location]
        lat_deg = 10.0
        lon_deg = 20.0
        [image]
        width = 32
        height = 32
        [output]
        files = ["unused.png"]
    "#;
    let scene: SceneFile = toml::from_str(text).unwrap();
    let mut state = ViewState::new(scene, Method::Bruneton4d, true);
    state.render_scale = 1.0;
    let size = (32, 32);
    let draw = |path: &mut FramePath, state: &ViewState| {
        let display = display_settings(state, 1.0 / 60.0, false);
        path.draw_offscreen(state, size, display)
            .unwrap()
            .0
            .image
            .data
    };
    let mut path = FramePath::new(backend, &state, None, "small").unwrap();
    let mapped = draw(&mut path, &state);
    let baked = path.planet.as_ref().map(|m| m.key.clone()).expect("a map");
    // The reference refuses the glint (it traces Lambertian surfaces).
    let sources = path.sources(&state).unwrap();
    let camera = state.scene.camera.clone();
    state.compare = Compare::Whole;
    let refused = path.reference_job(&state, &sources, &camera, size).err();
    assert!(refused.is_some_and(|r| r.contains("glint")));
    state.compare = Compare::Off;
    // Elsewhere on the planet: another frame, the same texture.
    state.scene.location.as_mut().unwrap().lon_deg = 140.0;
    let moved = draw(&mut path, &state);
    let m = path.planet.as_ref().unwrap();
    assert_eq!((m.key.as_str(), m.place), (baked.as_str(), (10.0, 140.0)));
    // Without the map: the uniform grey ground.
    state.scene.surface = None;
    let grey = draw(&mut path, &state);
    assert!(path.planet.is_none());
    let (a, b) = (mean_rel(&moved, &mapped), mean_rel(&grey, &mapped));
    eprintln!("planet map: moved 120° east {a:.3}, the grey ground {b:.3} (mean |ΔL|/L)");
    assert!(a > 0.02 && b > 0.05, "{a} {b}");
}

#[test]
fn the_difference_view_shows_the_method_against_the_reference_in_false_colour() {
    let Some((backend, _serial)) =
        backend("the_difference_view_shows_the_method_against_the_reference_in_false_colour")
    else {
        return;
    };
    let mut state = view(Method::Bruneton4d);
    let size = (32, 18);
    let display = display_settings(&state, 1.0 / 60.0, false);
    let mut path = FramePath::new(backend, &state, None, "small").unwrap();
    let (method, _) = path.draw_offscreen(&state, size, display).unwrap();
    state.compare = Compare::Difference;
    path.draw_offscreen(&state, size, display).unwrap();
    path.wait_for_reference(2).unwrap();
    // The frame that takes a pass compares it; the false colour shows from the next one.
    path.draw_offscreen(&state, size, display).unwrap();
    let (shown, _) = path.draw_offscreen(&state, size, display).unwrap();
    let y = |p: &[f32; 3]| crate::commands::view::difference::luminance(p);
    let mean = |f: &[[f32; 3]]| f.iter().map(y).sum::<f64>() / f.len() as f64;
    // White to red or blue at the method's mean luminance (the sun's disk apart, the
    // method's mean is the sky's): the colours' luminances lie between the blue end's
    // (0.29 of white) and white's.
    let (m, s) = (mean(&method.image.data), mean(&shown.image.data));
    let sky = method
        .image
        .data
        .iter()
        .map(y)
        .filter(|&l| l < 1e6)
        .sum::<f64>()
        / method.image.data.iter().filter(|p| y(p) < 1e6).count() as f64;
    eprintln!("difference view: its mean luminance {s:.1}, the sky's {sky:.1} (the frame's with the disk {m:.1})");
    assert!(s < 1.01 * sky && s > 0.25 * sky, "{s} against {sky}");
    // Somewhere the reference's noise (4 paths/λ) colours a pixel red or blue.
    let coloured = shown
        .image
        .data
        .iter()
        .filter(|p| (p[0] - p[2]).abs() > 0.05 * p[1].max(1e-9))
        .count();
    assert!(coloured > 0, "no pixel coloured");
    assert!(path.reference_line().unwrap().contains("red brighter"));
}

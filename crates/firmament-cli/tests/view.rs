//! `firmament view` end to end: the viewer's frame path offscreen against `firmament
//! render` of the scene it saved (same tables, same method), the real window under Xvfb
//! against the offscreen frame, and its refusals.
//!
//! GPU tests open an adapter first (`firmament_gpu::test_context()`): without one they skip,
//! saying so, unless `CI` is set, where they fail. The window test needs `xvfb-run` (Debian's
//! `xvfb`): without it, it skips outside CI and fails in CI.

mod common;

use std::path::Path;
use std::process::Command;
use std::sync::{Mutex, MutexGuard, OnceLock};

use common::{fails_with, run, succeeds, tables_arg, tmp_subdir};

fn gpu() -> Option<MutexGuard<'static, ()>> {
    static AVAILABLE: OnceLock<bool> = OnceLock::new();
    static LOCK: Mutex<()> = Mutex::new(());
    let available = *AVAILABLE.get_or_init(|| firmament_gpu::test_context().is_some());
    available.then(|| LOCK.lock().unwrap_or_else(|e| e.into_inner()))
}

fn luminance(p: &[f32; 3]) -> f64 {
    0.2126 * p[0] as f64 + 0.7152 * p[1] as f64 + 0.0722 * p[2] as f64
}

/// Mean absolute difference of two 8-bit images over columns `from_x..`.
fn mean_code_diff(a: &Path, b: &Path, from_x: usize) -> f64 {
    let (wa, ha, pa) = firmament::io::read_png_srgb8(a).unwrap();
    let (wb, hb, pb) = firmament::io::read_png_srgb8(b).unwrap();
    assert_eq!((wa, ha), (wb, hb));
    let mut sum = 0.0;
    let mut n = 0usize;
    for y in 0..ha {
        for x in from_x..wa {
            let (p, q) = (pa[y * wa + x], pb[y * wa + x]);
            for k in 0..3 {
                sum += (p[k] as f64 - q[k] as f64).abs();
                n += 1;
            }
        }
    }
    sum / n as f64
}

/// The default scene without its terrain and clouds (the clear sky), written to `dir`.
fn clear_scene(dir: &Path) -> std::path::PathBuf {
    let scene = firmament::scene::SceneFile {
        terrain: None,
        clouds: Vec::new(),
        ..Default::default()
    };
    let path = dir.join("clear.toml");
    std::fs::write(&path, toml::to_string(&scene).unwrap()).unwrap();
    path
}

/// The offscreen viewer's frame of `scene`, its scene saved: the second frame, or under
/// clouds or over a terrain the fourth (the viewer marches a quarter of their pixels a
/// frame: a still view is the full frame after four).
fn offscreen(dir: &Path, scene: &Path, size: (u32, u32), method: &str) -> std::process::Output {
    let file = firmament::scene::SceneFile::from_file(scene).unwrap();
    let marched = !file.clouds.is_empty() || file.terrain.is_some();
    run(&[
        "view",
        "--scene",
        scene.to_str().unwrap(),
        "--offscreen",
        "--frames",
        if marched { "4" } else { "2" },
        "--width",
        &size.0.to_string(),
        "--height",
        &size.1.to_string(),
        "--render-scale",
        "1",
        "--method",
        method,
        "--tables",
        tables_arg(),
        "--screenshot",
        dir.join("view.exr").to_str().unwrap(),
        "--screenshot",
        dir.join("view.png").to_str().unwrap(),
        "--save-scene",
        dir.join("scene.toml").to_str().unwrap(),
    ])
}

/// `firmament render` of the scene the viewer saved in `dir`, on the GPU from the same
/// tables: `render.exr` and `render.png`.
fn render_saved_scene(dir: &Path) {
    succeeds(&run(&[
        "render",
        "--scene",
        dir.join("scene.toml").to_str().unwrap(),
        "--tables",
        tables_arg(),
        "--backend",
        "gpu",
        "--method",
        "bruneton4d",
        "--out",
        dir.join("render.exr").to_str().unwrap(),
        "--out",
        dir.join("render.png").to_str().unwrap(),
    ]));
}

#[test]
fn the_viewers_frame_is_what_render_draws_of_its_saved_scene() {
    let Some(_gpu) = gpu() else { return };
    let dir = tmp_subdir("view-vs-render");
    let o = offscreen(&dir, &clear_scene(&dir), (192, 108), "bruneton4d");
    succeeds(&o);
    render_saved_scene(&dir);
    let (mean_rel, mean_ratio, disks) =
        exr_difference(&dir.join("view.exr"), &dir.join("render.exr"));
    eprintln!(
        "view vs render: mean luminance {mean_ratio:+.2e}, mean |ΔL|/L {mean_rel:.2e}; the disk's pixels' sum {disks:+.3}"
    );
    assert!(mean_ratio.abs() <= 0.01, "mean luminance {mean_ratio:+.4}");
    assert!(
        mean_rel <= 0.01,
        "mean relative luminance difference {mean_rel:.4}"
    );
    // Both exposed automatically from the same frame: the displays agree to a code or two
    // (the GPU's curve in f32 against the CPU's dithered one).
    let d = mean_code_diff(&dir.join("view.png"), &dir.join("render.png"), 0);
    eprintln!("view vs render PNG: mean |Δcode| {d:.3}");
    assert!(d <= 1.5, "mean code difference {d}");
    // The saved scene is a scene file render reads, with the viewer's size.
    let text = std::fs::read_to_string(dir.join("scene.toml")).unwrap();
    assert!(text.contains("width = 192"), "{text}");
}

#[test]
fn the_window_draws_and_captures_what_the_offscreen_path_draws() {
    let Some(_gpu) = gpu() else { return };
    let have_xvfb = Command::new("xvfb-run").arg("--help").output().is_ok();
    if !have_xvfb {
        assert!(
            std::env::var_os("CI").is_none(),
            "CI is set but xvfb-run is missing (apt-get install xvfb)"
        );
        eprintln!("skipping the window test: no xvfb-run");
        return;
    }
    let dir = tmp_subdir("view-window");
    let (w, h) = (640u32, 240u32);
    let shot = dir.join("window.png");
    let o = Command::new("xvfb-run")
        .args(["-a", "-s", "-screen 0 1024x768x24"])
        .arg(env!("CARGO_BIN_EXE_firmament"))
        .env("FIRMAMENT_CACHE_DIR", common::cache_dir())
        .args([
            "view",
            "--scene",
            clear_scene(&dir).to_str().unwrap(),
            "--frames",
            "3",
            "--width",
            &w.to_string(),
            "--height",
            &h.to_string(),
            "--render-scale",
            "1",
            "--tables",
            tables_arg(),
            "--screenshot",
            shot.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    succeeds(&o);
    let off = offscreen(&dir, &clear_scene(&dir), (w, h), "bruneton4d");
    succeeds(&off);
    // Not blank: the sky's rows differ from the ground's, and the panel is there.
    let (_, _, px) = firmament::io::read_png_srgb8(&shot).unwrap();
    let lum = |p: [u8; 3]| p.iter().map(|&c| c as f64).sum::<f64>();
    let (lo, hi) = px.iter().fold((f64::MAX, 0f64), |(lo, hi), &p| {
        (lo.min(lum(p)), hi.max(lum(p)))
    });
    assert!(hi - lo > 200.0, "a blank capture: codes {lo}..{hi}");
    // Right of the panel (330 points wide at scale 1) the window shows the offscreen frame.
    let d = mean_code_diff(&shot, &dir.join("view.png"), 400);
    eprintln!("window vs offscreen: mean |Δcode| {d:.3} right of the panel");
    assert!(
        d <= 1.0,
        "the window's view differs from the offscreen frame: {d}"
    );
}

/// Two EXR frames of the same size compared by luminance: the mean |ΔL|/L, the ratio of
/// their mean luminances − 1, and that ratio over the lights' disks' pixels alone. A disk of
/// about a pixel is drawn by the viewer on the GPU, where `render` splats a disk under four
/// pixels as a point on the CPU (no CPU pass in the viewer's frame loop), so the disks'
/// pixels (above 10⁶ cd/m², where no sky is) are compared apart.
fn exr_difference(a: &Path, b: &Path) -> (f64, f64, f64) {
    let v = firmament::io::read_exr(a).unwrap();
    let c = firmament::io::read_exr(b).unwrap();
    assert_eq!((v.width, v.height), (c.width, c.height));
    let disk = 1.0e6;
    let (mut sv, mut sc, mut rel, mut n, mut dv, mut dc) = (0.0, 0.0, 0.0, 0usize, 0.0, 0.0);
    for (p, q) in v.data.iter().zip(&c.data) {
        let (a, b) = (luminance(p), luminance(q));
        if a > disk || b > disk {
            dv += a;
            dc += b;
            continue;
        }
        sv += a;
        sc += b;
        if b > 0.0 {
            rel += (a - b).abs() / b;
            n += 1;
        }
    }
    let disks = if dc > 0.0 { dv / dc - 1.0 } else { 0.0 };
    (rel / n as f64, sv / sc - 1.0, disks)
}

#[test]
fn the_viewer_draws_the_terrain_as_render_does() {
    let Some(_gpu) = gpu() else { return };
    let dir = tmp_subdir("view-terrain");
    // The default scene: the valley at golden hour, its shafts; the sun behind a ridge (its
    // clouds over the terrain: the_viewer_draws_the_clouds_over_the_terrain_as_render_does).
    let defaults = dir.join("default.toml");
    let scene = firmament::scene::SceneFile {
        clouds: Vec::new(),
        ..firmament::scene::SceneFile::default()
    };
    std::fs::write(&defaults, toml::to_string(&scene).unwrap()).unwrap();
    succeeds(&offscreen(&dir, &defaults, (96, 54), "bruneton4d"));
    render_saved_scene(&dir);
    let (rel, mean, disks) = exr_difference(&dir.join("view.exr"), &dir.join("render.exr"));
    eprintln!(
        "terrain: view vs render: mean |ΔL|/L {rel:.2e}, mean luminance {mean:+.2e}; the disks' pixels {disks:+.3}"
    );
    assert!(rel <= 0.01 && mean.abs() <= 0.01, "{rel} {mean}");
}

/// The offscreen viewer's frame of the clear sky at 32×18 with `extra` flags, into
/// `STEM.exr` and `STEM.png`.
fn small_view(dir: &Path, stem: &str, extra: &[&str]) {
    let scene = clear_scene(dir);
    let (exr, png) = (
        dir.join(format!("{stem}.exr")),
        dir.join(format!("{stem}.png")),
    );
    let mut args = vec![
        "view",
        "--scene",
        scene.to_str().unwrap(),
        "--offscreen",
        "--frames",
        "1",
        "--width",
        "32",
        "--height",
        "18",
        "--render-scale",
        "1",
        "--tables",
        tables_arg(),
        "--screenshot",
        exr.to_str().unwrap(),
        "--screenshot",
        png.to_str().unwrap(),
    ];
    args.extend(extra);
    succeeds(&run(&args));
}

#[test]
fn the_reference_traced_in_the_view_agrees_with_the_tables_beside_it() {
    let Some(_gpu) = gpu() else { return };
    let dir = tmp_subdir("view-reference");
    small_view(&dir, "tables", &[]);
    small_view(
        &dir,
        "reference",
        &["--reference", "whole", "--reference-passes", "3"],
    );
    small_view(
        &dir,
        "split",
        &["--reference", "split", "--reference-passes", "1"],
    );
    // The whole frame traced: 6 paths per wavelength a pixel, so each pixel is noisy but
    // their mean is the tables' to their accuracy (0.5 % median in daylight) and the noise.
    let (rel, mean, _) = exr_difference(&dir.join("reference.exr"), &dir.join("tables.exr"));
    eprintln!(
        "reference in the view vs the tables: mean luminance {mean:+.3}, mean |ΔL|/L {rel:.3}"
    );
    assert!(mean.abs() < 0.03, "mean luminance {mean}");
    assert!(
        rel > 0.002 && rel < 0.5,
        "per pixel {rel}: not traced, or wrong"
    );
    // Split: the left half is the tables' frame itself, the right half the tracer's.
    let t = firmament::io::read_exr(dir.join("tables.exr")).unwrap();
    let s = firmament::io::read_exr(dir.join("split.exr")).unwrap();
    let w = t.width;
    for y in 0..t.height {
        for x in 0..w / 2 {
            assert_eq!(s.data[y * w + x], t.data[y * w + x], "left half at {x},{y}");
        }
    }
    let right = (0..t.height)
        .flat_map(|y| (w / 2..w).map(move |x| y * w + x))
        .filter(|&i| s.data[i] != t.data[i])
        .count();
    assert!(
        right > t.height * (w / 2) / 2,
        "only {right} right-half pixels traced"
    );
}

#[test]
fn the_viewer_draws_the_clouds_as_render_does() {
    let Some(_gpu) = gpu() else { return };
    let dir = tmp_subdir("view-clouds");
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/clouds-cumulus-noon.toml");
    succeeds(&offscreen(&dir, &scene, (64, 36), "bruneton4d"));
    // The saved scene keeps the clouds, and render draws them on the GPU from it.
    let text = std::fs::read_to_string(dir.join("scene.toml")).unwrap();
    assert!(text.contains("[[clouds]]"), "{text}");
    render_saved_scene(&dir);
    let (rel, mean, _) = exr_difference(&dir.join("view.exr"), &dir.join("render.exr"));
    eprintln!("clouds: view vs render: mean |ΔL|/L {rel:.2e}, mean luminance {mean:+.2e}");
    assert!(rel <= 0.01 && mean.abs() <= 0.01, "{rel} {mean}");
    // And they are there: the cloudy view is not the clear sky's.
    let clear = dir.join("clear-sky.toml");
    let mut s: firmament::scene::SceneFile =
        toml::from_str(&std::fs::read_to_string(&scene).unwrap()).unwrap();
    s.clouds.clear();
    std::fs::write(&clear, toml::to_string(&s).unwrap()).unwrap();
    let clear_dir = dir.join("clear");
    std::fs::create_dir_all(&clear_dir).unwrap();
    succeeds(&offscreen(&clear_dir, &clear, (64, 36), "bruneton4d"));
    let (rel, _, _) = exr_difference(&dir.join("view.exr"), &clear_dir.join("view.exr"));
    assert!(rel > 0.1, "the clouds changed the view by {rel} only");
}

#[test]
fn the_viewer_draws_the_clouds_over_the_terrain_as_render_does() {
    let Some(_gpu) = gpu() else { return };
    let dir = tmp_subdir("view-valley-clouds");
    let scene =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/clouds-over-the-valley.toml");
    let out = offscreen(&dir, &scene, (64, 36), "bruneton4d");
    succeeds(&out);
    // Nothing of the scene is left out of the view, and after four frames its clouds are
    // the full frame (a quarter of their pixels marched a frame).
    let said = String::from_utf8_lossy(&out.stderr);
    assert!(!said.contains("over a terrain"), "{said}");
    assert!(
        said.contains("march: 1/4 of the pixels a frame; converged"),
        "{said}"
    );
    let text = std::fs::read_to_string(dir.join("scene.toml")).unwrap();
    assert!(
        text.contains("[[clouds]]") && text.contains("[terrain]"),
        "{text}"
    );
    render_saved_scene(&dir);
    let (rel, mean, _) = exr_difference(&dir.join("view.exr"), &dir.join("render.exr"));
    eprintln!(
        "clouds over the terrain: view vs render: mean |ΔL|/L {rel:.2e}, mean luminance {mean:+.2e}"
    );
    assert!(rel <= 0.01 && mean.abs() <= 0.01, "{rel} {mean}");
}

#[test]
fn the_viewer_draws_the_moon_and_the_stars_as_render_does() {
    let Some(_gpu) = gpu() else { return };
    let dir = tmp_subdir("view-night");
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/moonlit.toml");
    succeeds(&offscreen(&dir, &scene, (96, 54), "bruneton4d"));
    render_saved_scene(&dir);
    let (rel, mean, _) = exr_difference(&dir.join("view.exr"), &dir.join("render.exr"));
    eprintln!("night: view vs render: mean |ΔL|/L {rel:.2e}, mean luminance {mean:+.2e}");
    assert!(rel <= 0.01 && mean.abs() <= 0.01, "{rel} {mean}");
    // The points are there: pixels of the sky far brighter than their four neighbours (the
    // moon, splatted as a point at this size, and at least the brightest star).
    let v = firmament::io::read_exr(dir.join("view.exr")).unwrap();
    let (w, h) = (v.width, v.height);
    let y = |x: usize, y: usize| luminance(&v.data[y * w + x]);
    let points = (1..h / 2)
        .flat_map(|j| (1..w - 1).map(move |i| (i, j)))
        .filter(|&(i, j)| {
            let around = (y(i - 1, j) + y(i + 1, j) + y(i, j - 1) + y(i, j + 1)) / 4.0;
            y(i, j) > 2.0 * around
        })
        .count();
    assert!(points >= 2, "{points} point-like pixels in the night sky");
    // The reference traces the sun's light only: at night it is refused, not awaited.
    let o = run(&[
        "view",
        "--scene",
        scene.to_str().unwrap(),
        "--offscreen",
        "--frames",
        "1",
        "--width",
        "32",
        "--height",
        "18",
        "--tables",
        tables_arg(),
        "--reference",
        "whole",
    ]);
    fails_with(&o, &["--reference", "sun's light only"]);
}

#[test]
fn the_viewer_refuses_what_it_cannot_do() {
    let dir = tmp_subdir("view-refusals");
    fails_with(
        &run(&[
            "view",
            "--method",
            "reference",
            "--offscreen",
            "--frames",
            "1",
        ]),
        &["--method", "reference", "bruneton4d, hillaire2020, elek3d"],
    );
    let jpg = dir.join("shot.jpg");
    fails_with(
        &run(&[
            "view",
            "--offscreen",
            "--frames",
            "1",
            "--screenshot",
            jpg.to_str().unwrap(),
        ]),
        &["--screenshot", ".png or .exr"],
    );
    fails_with(&run(&["view", "--offscreen"]), &["--frames"]);
    fails_with(
        &run(&[
            "view",
            "--offscreen",
            "--frames",
            "1",
            "--reference",
            "half",
        ]),
        &["--reference", "off, split, whole"],
    );
    fails_with(
        &run(&[
            "view",
            "--offscreen",
            "--frames",
            "1",
            "--render-scale",
            "3",
        ]),
        &["--render-scale", "0.1 to 1"],
    );
    fails_with(
        &run(&["view", "--offscreen", "--frames", "1", "--march-step", "3"]),
        &["--march-step", "1, 2, 4"],
    );
    assert!(!jpg.exists());
}

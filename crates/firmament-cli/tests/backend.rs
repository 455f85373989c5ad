//! `--backend cpu|gpu|auto` end to end: GPU output matches the CPU's, GPU-baked tables are
//! usable, bad values and impossible combinations are refused clearly, `bench --json`
//! reports the GPU keys.
//!
//! GPU tests open an adapter first with `firmament_gpu::test_context()`: without one they
//! skip (saying so), unless `CI` is set, where they fail. They run one at a time (lavapipe
//! uses every core) on small tables and tiny images.

mod common;

use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard, OnceLock};

use common::{bin, fails_with, run, stderr, succeeds, tables_arg, tmp};

/// Whether GPU tests run: an adapter opens (panics under `CI` when none does). Holds the
/// lock that keeps GPU tests apart.
fn gpu() -> Option<MutexGuard<'static, ()>> {
    static AVAILABLE: OnceLock<bool> = OnceLock::new();
    static LOCK: Mutex<()> = Mutex::new(());
    let available = *AVAILABLE.get_or_init(|| match firmament_gpu::test_context() {
        Some(ctx) => {
            eprintln!(
                "GPU adapter: {} ({}, software: {})",
                ctx.adapter_name(),
                ctx.backend(),
                ctx.is_software()
            );
            true
        }
        None => false,
    });
    available.then(|| LOCK.lock().unwrap_or_else(|e| e.into_inner()))
}

/// Mean absolute difference of two 8-bit PNGs of the same size.
fn png_mean_abs_diff(a: &Path, b: &Path) -> f64 {
    let (wa, ha, pa) = firmament::io::read_png_srgb8(a).unwrap();
    let (wb, hb, pb) = firmament::io::read_png_srgb8(b).unwrap();
    assert_eq!((wa, ha), (wb, hb));
    let sum: u64 = pa
        .iter()
        .zip(&pb)
        .flat_map(|(x, y)| x.iter().zip(y).map(|(u, v)| u.abs_diff(*v) as u64))
        .sum();
    sum as f64 / (3 * pa.len()) as f64
}

/// Mean relative difference of the luminance of two EXRs, over pixels above 1e-6 of the
/// brightest.
fn exr_mean_rel_diff(a: &Path, b: &Path) -> f64 {
    let (ia, ib) = (
        firmament::io::read_exr(a).unwrap(),
        firmament::io::read_exr(b).unwrap(),
    );
    let y = |p: [f32; 3]| 0.2126 * p[0] as f64 + 0.7152 * p[1] as f64 + 0.0722 * p[2] as f64;
    let max = ib.data.iter().map(|p| y(*p)).fold(0.0, f64::max);
    let (mut sum, mut n) = (0.0, 0);
    for (p, q) in ia.data.iter().zip(&ib.data) {
        if y(*q) > 1e-6 * max {
            sum += (y(*p) - y(*q)).abs() / y(*q);
            n += 1;
        }
    }
    assert!(n > 0);
    sum / n as f64
}

/// Render the same view on both backends (fixed exposure); returns the PNG and EXR paths
/// for cpu and gpu.
fn render_both(name: &str, args: &[&str]) -> [(PathBuf, PathBuf); 2] {
    ["cpu", "gpu"].map(|backend| {
        let png = tmp().join(format!("{name}-{backend}.png"));
        let exr = tmp().join(format!("{name}-{backend}.exr"));
        // Without the default scene's terrain and clouds unless a scene brings them (their
        // own tests).
        let mut a = vec!["render", "--backend", backend, "--ev100", "14"];
        if !args.contains(&"--scene") {
            a.extend(["--no-terrain", "--no-clouds"]);
        }
        a.extend_from_slice(args);
        a.extend_from_slice(&["--out", png.to_str().unwrap()]);
        a.extend_from_slice(&["--out", exr.to_str().unwrap()]);
        let o = run(&a);
        succeeds(&o);
        assert!(
            stderr(&o).contains(&format!("backend: {backend}")),
            "{}",
            stderr(&o)
        );
        (png, exr)
    })
}

#[test]
fn backend_values_are_checked() {
    for cmd in ["render", "bake", "query", "gallery"] {
        fails_with(
            &run(&[cmd, "--backend", "bogus"]),
            &["--backend", "bogus", "cpu", "gpu", "auto"],
        );
    }
    fails_with(
        &run(&["bench", "--backend", "bogus"]),
        &["--backend", "bogus", "auto", "all", "cpu", "gpu"],
    );
}

#[test]
fn reference_method_refuses_the_gpu() {
    let out = tmp().join("reference-gpu.png");
    fails_with(
        &run(&[
            "render",
            "--method",
            "reference",
            "--backend",
            "gpu",
            "--width",
            "8",
            "--height",
            "8",
            "--out",
            out.to_str().unwrap(),
        ]),
        &["--method reference", "CPU only", "--backend gpu"],
    );
    assert!(!out.exists());
}

#[test]
fn every_command_says_which_backend() {
    // `auto` is the default; it names what it chose (whatever this machine has).
    let out = tmp().join("auto.png");
    let o = run(&[
        "render",
        "--tables",
        tables_arg(),
        "--width",
        "16",
        "--height",
        "9",
        "--out",
        out.to_str().unwrap(),
    ]);
    succeeds(&o);
    let e = stderr(&o);
    assert!(
        e.contains("backend: cpu (auto: ") || e.contains("backend: gpu (auto: "),
        "{e}"
    );
    // `-q` silences it.
    let o = run(&[
        "render",
        "--tables",
        tables_arg(),
        "--width",
        "16",
        "--height",
        "9",
        "--out",
        out.to_str().unwrap(),
        "-q",
    ]);
    succeeds(&o);
    assert!(!stderr(&o).contains("backend:"), "{}", stderr(&o));
    // query: the views are CPU lookups of the file's tables.
    let o = run(&[
        "query",
        "--tables",
        tables_arg(),
        "--altitude-m",
        "0",
        "--sun-zenith-deg",
        "30",
    ]);
    succeeds(&o);
    assert!(
        stderr(&o).contains("backend: cpu (tables read from"),
        "{}",
        stderr(&o)
    );
}

#[cfg(target_os = "linux")]
#[test]
fn missing_gpu_is_a_clear_error_and_auto_falls_back() {
    // No Vulkan driver manifest: wgpu finds no adapter (Linux only has Vulkan here).
    let no_gpu = |args: &[&str]| {
        bin()
            .args(args)
            .env("VK_ICD_FILENAMES", "/nonexistent/icd.json")
            .env("VK_DRIVER_FILES", "/nonexistent/icd.json")
            .output()
            .unwrap()
    };
    let out = tmp().join("no-gpu.png");
    let lut = tmp().join("no-gpu.lut");
    fails_with(
        &no_gpu(&[
            "render",
            "--backend",
            "gpu",
            "--tables",
            tables_arg(),
            "--width",
            "16",
            "--height",
            "9",
            "--out",
            out.to_str().unwrap(),
        ]),
        &["--backend gpu", "no GPU adapter", "--backend cpu"],
    );
    assert!(!out.exists());
    fails_with(
        &no_gpu(&[
            "bake",
            "--backend",
            "gpu",
            "--table-size",
            "small",
            "--out",
            lut.to_str().unwrap(),
        ]),
        &["--backend gpu", "no GPU adapter", "--backend cpu"],
    );
    assert!(!lut.exists());
    let o = no_gpu(&[
        "render",
        "--tables",
        tables_arg(),
        "--width",
        "16",
        "--height",
        "9",
        "--out",
        out.to_str().unwrap(),
    ]);
    succeeds(&o);
    assert!(
        stderr(&o).contains("backend: cpu (auto: no GPU adapter found"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn gpu_render_from_table_file_matches_cpu() {
    let Some(_lock) = gpu() else { return };
    for (name, camera, w, h) in [
        ("persp", "perspective", "64", "36"),
        ("fisheye", "fisheye", "32", "32"),
    ] {
        let [(cpu_png, cpu_exr), (gpu_png, gpu_exr)] = render_both(
            name,
            &[
                "--tables",
                tables_arg(),
                "--camera",
                camera,
                "--width",
                w,
                "--height",
                h,
                "--sun-zenith-deg",
                "70",
            ],
        );
        let d8 = png_mean_abs_diff(&gpu_png, &cpu_png);
        assert!(d8 <= 1.0, "{name}: mean |Δ| of 8-bit values {d8}");
        let rel = exr_mean_rel_diff(&gpu_exr, &cpu_exr);
        assert!(
            rel <= 0.01,
            "{name}: mean relative luminance difference {rel}"
        );
    }
}

#[test]
fn gpu_precompute_and_render_matches_cpu() {
    let Some(_lock) = gpu() else { return };
    // No --tables: precomputed on each backend (small sizes), the GPU's kept on the device.
    let [(cpu_png, cpu_exr), (gpu_png, gpu_exr)] = render_both(
        "precomputed",
        &[
            "--table-size",
            "small",
            "--wavelengths",
            "rgb",
            "--width",
            "48",
            "--height",
            "27",
            "--sun-zenith-deg",
            "60",
        ],
    );
    let d8 = png_mean_abs_diff(&gpu_png, &cpu_png);
    assert!(d8 <= 1.0, "mean |Δ| of 8-bit values {d8}");
    let rel = exr_mean_rel_diff(&gpu_exr, &cpu_exr);
    assert!(rel <= 0.01, "mean relative luminance difference {rel}");
}

#[test]
fn gpu_hillaire2020_render_matches_cpu() {
    let Some(_lock) = gpu() else { return };
    // Hillaire 2020 on each backend: its tables and the sky-view table on the device.
    let [(cpu_png, cpu_exr), (gpu_png, gpu_exr)] = render_both(
        "hillaire2020",
        &[
            "--method",
            "hillaire2020",
            "--wavelengths",
            "rgb",
            "--width",
            "48",
            "--height",
            "27",
            "--sun-zenith-deg",
            "70",
        ],
    );
    let d8 = png_mean_abs_diff(&gpu_png, &cpu_png);
    assert!(d8 <= 1.0, "mean |Δ| of 8-bit values {d8}");
    let rel = exr_mean_rel_diff(&gpu_exr, &cpu_exr);
    assert!(rel <= 0.01, "mean relative luminance difference {rel}");
    // The higher orders' fields are gathered on the device too.
    let [(_, cpu_exr), (_, gpu_exr)] = render_both(
        "hillaire2020-orders",
        &[
            "--method",
            "hillaire2020",
            "--hillaire-orders",
            "4",
            "--wavelengths",
            "rgb",
            "--width",
            "48",
            "--height",
            "27",
            "--sun-zenith-deg",
            "70",
        ],
    );
    let rel = exr_mean_rel_diff(&gpu_exr, &cpu_exr);
    assert!(
        rel <= 0.01,
        "4 orders: mean relative luminance difference {rel}"
    );
    // The terrain is the CPU's only so far: refused on `--backend gpu`.
    let png = tmp().join("hillaire-terrain.png");
    let o = run(&[
        "render",
        "--method",
        "hillaire2020",
        "--backend",
        "gpu",
        "--width",
        "32",
        "--out",
        png.to_str().unwrap(),
    ]);
    fails_with(&o, &["hillaire2020", "terrain", "--backend cpu"]);
    assert!(!png.exists());
}

#[test]
fn gpu_elek3d_render_matches_cpu() {
    let Some(_lock) = gpu() else { return };
    // The 3D tables computed on the CPU, uploaded, and drawn by the GPU's renderer.
    let [(cpu_png, cpu_exr), (gpu_png, gpu_exr)] = render_both(
        "elek3d",
        &[
            "--method",
            "elek3d",
            "--wavelengths",
            "rgb",
            "--width",
            "48",
            "--height",
            "27",
            "--sun-zenith-deg",
            "80",
        ],
    );
    let d8 = png_mean_abs_diff(&gpu_png, &cpu_png);
    assert!(d8 <= 1.0, "mean |Δ| of 8-bit values {d8}");
    let rel = exr_mean_rel_diff(&gpu_exr, &cpu_exr);
    assert!(rel <= 0.01, "mean relative luminance difference {rel}");
    // The terrain is the CPU's only so far: refused on `--backend gpu`.
    let png = tmp().join("elek3d-terrain.png");
    let o = run(&[
        "render",
        "--method",
        "elek3d",
        "--backend",
        "gpu",
        "--width",
        "32",
        "--out",
        png.to_str().unwrap(),
    ]);
    fails_with(&o, &["elek3d", "terrain", "--backend cpu"]);
    assert!(!png.exists());
}

/// The default scene's valley (coarse) at golden hour, its tables precomputed on each
/// backend with the ground lifted to the valley's floor: the GPU walks the same terrain,
/// shadow fields and light shafts, with the air light computed on the CPU from the tables
/// read back.
#[test]
fn gpu_terrain_render_matches_cpu() {
    let Some(_lock) = gpu() else { return };
    let scene = tmp().join("valley.toml");
    let default = include_str!(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../scenes/valley-sunset.toml"
    ));
    // The terrain alone (its clouds: `firmament-gpu`'s clouds_parity over the valley).
    let clear = format!(
        "{}{}",
        &default[..default.find("[[clouds]]").expect("the default's clouds")],
        &default[default.find("[output]").expect("its output")..]
    );
    let coarse = clear
        .replace("width = 1920", "width = 64")
        .replace("height = 1080", "height = 36")
        .replace("[terrain]", "[terrain]\nresolution = 129");
    assert!(coarse.contains("resolution = 129") && coarse.contains("width = 64"));
    std::fs::write(&scene, coarse).unwrap();
    let [(cpu_png, cpu_exr), (gpu_png, gpu_exr)] = render_both(
        "valley",
        &[
            "--scene",
            scene.to_str().unwrap(),
            "--table-size",
            "small",
            "--wavelengths",
            "rgb",
        ],
    );
    let d8 = png_mean_abs_diff(&gpu_png, &cpu_png);
    assert!(d8 <= 1.0, "mean |Δ| of 8-bit values {d8}");
    let rel = exr_mean_rel_diff(&gpu_exr, &cpu_exr);
    assert!(rel <= 0.01, "mean relative luminance difference {rel}");
}

/// The planet from orbit with the procedural surface map (`[surface]`): the GPU samples
/// the map's weights baked into a texture (coasts blend within a texel, 20 km), the CPU
/// evaluates them per point; the sea's glint on both.
#[test]
fn gpu_planet_map_render_matches_cpu() {
    let Some(_lock) = gpu() else { return };
    let scene = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../scenes/planet-from-space.toml"
    );
    let [(cpu_png, cpu_exr), (gpu_png, gpu_exr)] = render_both(
        "planet",
        &[
            "--scene",
            scene,
            "--tables",
            tables_arg(),
            "--width",
            "64",
            "--height",
            "64",
        ],
    );
    let d8 = png_mean_abs_diff(&gpu_png, &cpu_png);
    let rel = exr_mean_rel_diff(&gpu_exr, &cpu_exr);
    eprintln!("planet map: mean |Δ| of 8-bit values {d8:.3}, mean relative luminance {rel:.2e}");
    assert!(d8 <= 1.0, "mean |Δ| of 8-bit values {d8}");
    assert!(rel <= 0.01, "mean relative luminance difference {rel}");
}

#[test]
fn gpu_baked_tables_work_with_query() {
    let Some(_lock) = gpu() else { return };
    let query = |lut: &Path| {
        let o = run(&[
            "query",
            "--tables",
            lut.to_str().unwrap(),
            "--altitude-m",
            "0",
            "--sun-zenith-deg",
            "30",
            "--view",
            "0,0",
            "--view",
            "80,90",
            "-q",
        ]);
        succeeds(&o);
        let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        let mut out: Vec<f64> = v["views"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x["luminance_cd_m2"].as_f64().unwrap())
            .collect();
        out.push(v["irradiance"]["sky_lux"].as_f64().unwrap());
        out
    };
    let mut answers = Vec::new();
    for backend in ["gpu", "cpu"] {
        let lut = tmp().join(format!("baked-{backend}.lut"));
        let o = run(&[
            "bake",
            "--backend",
            backend,
            "--table-size",
            "small",
            "--orders",
            "1",
            "--wavelengths",
            "rgb",
            "--out",
            lut.to_str().unwrap(),
        ]);
        succeeds(&o);
        assert!(
            stderr(&o).contains(&format!("backend: {backend}")),
            "{}",
            stderr(&o)
        );
        answers.push(query(&lut));
    }
    // View luminances are positive; the sky irradiance is 0 with one order on both.
    assert!(answers[1][0] > 0.0 && answers[1][1] > 0.0, "{answers:?}");
    for (g, c) in answers[0].iter().zip(&answers[1]) {
        assert!((g - c).abs() <= 0.01 * c.abs(), "gpu {g} cpu {c}");
    }
}

#[test]
fn bench_json_reports_the_gpu() {
    let Some(_lock) = gpu() else { return };
    let o = run(&[
        "bench",
        "--json",
        "--backend",
        "gpu",
        "--table-size",
        "small",
        "--orders",
        "1",
        "--runs",
        "1",
    ]);
    succeeds(&o);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    for key in [
        "gpu_precompute_s",
        "gpu_frame_1080p_perspective_s",
        "gpu_frame_1080p_perspective_with_readback_s",
        "gpu_pipeline_creation_s",
    ] {
        let s = v[key].as_f64().unwrap_or_else(|| panic!("{key}: {v}"));
        assert!(s > 0.0, "{key}: {s}");
    }
    for key in [
        "gpu_adapter",
        "gpu_backend",
        "gpu_frame_timing_method",
        "gpu_precompute_timing_method",
    ] {
        assert!(!v[key].as_str().unwrap_or("").is_empty(), "{key}: {v}");
    }
    assert_eq!(v["gpu_precompute_orders"], 1);
    assert_eq!(v["gpu_precompute_wavelengths"], 3);
    // The CPU was not asked for: its keys are there, null.
    for key in [
        "cpu_precompute_s",
        "cpu_frame_1080p_perspective_s",
        "cpu_frame_1024_fisheye_s",
        "cpu_frame_4096x2048_equirect_s",
    ] {
        assert!(v.get(key).is_some_and(|x| x.is_null()), "{key}: {v}");
    }
}

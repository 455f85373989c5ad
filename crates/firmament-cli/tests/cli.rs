//! The `firmament` binary end to end: JSON output, every camera and format, and clear
//! errors (non-zero exit, no output file) for bad input.

mod common;

use std::path::Path;

use common::{fails_with, run, stderr, tables, tmp};
use firmament::io::read_exr;

#[test]
fn query_prints_the_documented_json() {
    let t = tables().to_str().unwrap();
    let o = run(&[
        "query",
        "--tables",
        t,
        "--altitude-m",
        "0",
        "--sun-zenith-deg",
        "30",
        "--sun-azimuth-deg",
        "180",
        "--view",
        "0,0",
        "--view",
        "80,90",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["wavelengths_nm"].as_array().unwrap().len(), 3);
    assert_eq!(v["sun"]["zenith_deg"], 30.0);
    assert_eq!(v["sun"]["azimuth_deg"], 180.0);
    for key in ["rayleigh", "mie", "ozone", "total"] {
        assert_eq!(
            v["optical_depth_zenith"][key].as_array().unwrap().len(),
            3,
            "{key}"
        );
    }
    let tau_r = v["optical_depth_zenith"]["rayleigh"][1].as_f64().unwrap();
    assert!((tau_r - 0.0973).abs() < 0.002, "τ_R(550) {tau_r}");
    let lux = v["solar_illuminance_toa_lux"].as_f64().unwrap();
    assert!(lux > 120_000.0 && lux < 140_000.0, "{lux}");
    let sun_lux = v["irradiance"]["sun_lux"].as_f64().unwrap();
    let sky_lux = v["irradiance"]["sky_lux"].as_f64().unwrap();
    assert!(
        sun_lux > 60_000.0 && sun_lux < 110_000.0 && sky_lux > 5_000.0 && sky_lux < 30_000.0,
        "{sun_lux} {sky_lux}"
    );
    let views = v["views"].as_array().unwrap();
    assert_eq!(views.len(), 2);
    for view in views {
        for key in ["radiance", "xyz", "srgb_linear", "transmittance"] {
            assert_eq!(view[key].as_array().unwrap().len(), 3, "{key}");
        }
        let l = view["luminance_cd_m2"].as_f64().unwrap();
        assert!(l > 500.0 && l < 20_000.0, "{l}");
    }
    // The zenith is bluer than red.
    let rgb = &views[0]["srgb_linear"];
    assert!(rgb[2].as_f64().unwrap() > rgb[0].as_f64().unwrap());
}

#[test]
fn adjusted_atmospheres_have_the_depths_asked_and_refuse_what_they_cannot() {
    let o = run(&[
        "query",
        "--wavelengths",
        "rgb",
        "--table-size",
        "small",
        "--orders",
        "3",
        "--no-cache",
        "--aerosol-optical-depth",
        "0.5",
        "--ozone-du",
        "450",
        "--rayleigh-scale",
        "1.5",
        "--altitude-m",
        "0",
        "--sun-zenith-deg",
        "30",
        "--view",
        "0,0",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let tau = |k: &str| v["optical_depth_zenith"][k][1].as_f64().unwrap();
    // At 550 nm: the aerosols' depth as asked; ozone σ(550)·450 DU; Rayleigh 1.5 × earth's
    // 0.0973 (Bodhaine 1999).
    assert!((tau("mie") - 0.5).abs() < 1e-9, "{}", tau("mie"));
    let ozone = firmament::spectrum::ozone_cross_section_m2(550.0) * 450.0 * 2.6867e20;
    assert!(
        (tau("ozone") / ozone - 1.0).abs() < 1e-6,
        "{} {ozone}",
        tau("ozone")
    );
    assert!(
        (tau("rayleigh") - 1.5 * 0.0973).abs() < 0.003,
        "{}",
        tau("rayleigh")
    );
    let dir = tmp().join("adjust-refused");
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("never.png");
    for (args, words) in [
        (
            vec!["--preset", "mars", "--ozone-du", "300"],
            vec!["adjust.ozone_du", "no absorber"],
        ),
        (
            vec!["--aerosol-optical-depth=4"],
            vec!["adjust.aerosol_optical_depth", "[0, 3]"],
        ),
        (
            vec!["--planet-radius-m", "10"],
            vec!["adjust.planet_radius_m", "[100000, 100000000]"],
        ),
        // Earth's 60 km of air over a planet of 50 000 km: a shell too thin for the tables.
        (
            vec!["--planet-radius-m", "5e7"],
            vec![
                "bottom_radius_m",
                "at most 20000000 m",
                "--method reference",
            ],
        ),
    ] {
        let mut a = vec![
            "render",
            "--no-terrain",
            "--no-clouds",
            "--width",
            "16",
            "--height",
            "9",
        ];
        a.extend(args);
        a.extend(["--out", out.to_str().unwrap()]);
        fails_with(&run(&a), &words);
        assert!(!out.exists());
    }
}

#[test]
fn invalid_query_inputs_are_refused_clearly() {
    let t = tables().to_str().unwrap();
    let base = ["query", "--tables", t, "--sun-zenith-deg", "30"];
    let with = |extra: &[&str]| {
        let mut a: Vec<&str> = base.to_vec();
        a.extend_from_slice(extra);
        run(&a)
    };
    fails_with(
        &with(&["--altitude-m", "-5"]),
        &["--altitude-m", "-5", "[0,"],
    );
    fails_with(
        &run(&[
            "query",
            "--tables",
            t,
            "--altitude-m",
            "0",
            "--sun-zenith-deg",
            "200",
        ]),
        &["--sun-zenith-deg", "200", "[0, 180]"],
    );
    fails_with(
        &with(&["--altitude-m", "0", "--view", "abc"]),
        &["--view", "ZENITH_DEG,AZIMUTH_DEG"],
    );
    fails_with(&with(&["--altitude-m", "nan"]), &["--altitude-m", "NaN"]);
    fails_with(
        &run(&[
            "query",
            "--preset",
            "venus",
            "--altitude-m",
            "0",
            "--sun-zenith-deg",
            "30",
        ]),
        &["unknown preset", "venus", "earth"],
    );
    fails_with(
        &run(&[
            "query",
            "--wavelengths",
            "",
            "--altitude-m",
            "0",
            "--sun-zenith-deg",
            "30",
        ]),
        &["wavelengths"],
    );
    fails_with(
        &with(&["--altitude-m", "0", "--method", "magic"]),
        &["--method", "magic"],
    );
    // Tables for another atmosphere.
    fails_with(
        &run(&[
            "query",
            "--preset",
            "hazy",
            "--tables",
            t,
            "--altitude-m",
            "0",
            "--sun-zenith-deg",
            "30",
        ]),
        &["another atmosphere"],
    );
}

#[test]
fn bad_atmosphere_files_are_refused_with_the_field() {
    let earth = run(&["atmosphere", "show", "earth"]);
    assert!(earth.status.success());
    let text = String::from_utf8(earth.stdout).unwrap();
    let cases = [
        (
            "bottom_radius_m = 6360000.0",
            "bottom_radius_m = -1.0",
            vec!["bottom_radius_m", "-1"],
        ),
        (
            "top_radius_m = 6420000.0",
            "top_radius_m = 6000000.0",
            vec!["top_radius_m", "greater than bottom_radius_m"],
        ),
        (
            "ground_albedo = 0.1",
            "ground_albedo = 2.0",
            vec!["ground_albedo", "[0, 1]"],
        ),
        (
            "top_radius_m = 6420000.0",
            "top_radius_m = 1e12",
            vec!["top_radius_m", "at most bottom_radius_m + 200", "'mie'"],
        ),
        (
            "g = 0.76 }",
            "g = -1.0 }",
            vec!["constituents[1].phase.g", "-1"],
        ),
        (
            "ground_albedo = 0.1",
            "ground_albedo = 0.1\nsky_colour = 3",
            vec!["unknown field", "sky_colour"],
        ),
        ("[sun]", "[sun", vec!["TOML"]),
    ];
    for (i, (from, to, words)) in cases.iter().enumerate() {
        let p = tmp().join(format!("bad{i}.toml"));
        std::fs::write(&p, text.replacen(from, to, 1)).unwrap();
        let o = run(&[
            "query",
            "--atmosphere",
            p.to_str().unwrap(),
            "--altitude-m",
            "0",
            "--sun-zenith-deg",
            "30",
        ]);
        fails_with(&o, words);
    }
    // Shown presets load back as they are.
    let p = tmp().join("earth.toml");
    std::fs::write(&p, &text).unwrap();
    assert!(run(&["atmosphere", "check", p.to_str().unwrap()])
        .status
        .success());
    fails_with(&run(&["atmosphere", "show", "venus"]), &["venus"]);
}

#[test]
fn bad_table_files_are_refused() {
    let t = std::fs::read(tables()).unwrap();
    let p = tmp().join("truncated.lut");
    std::fs::write(&p, &t[..t.len() / 2]).unwrap();
    fails_with(
        &run(&[
            "query",
            "--tables",
            p.to_str().unwrap(),
            "--altitude-m",
            "0",
            "--sun-zenith-deg",
            "30",
        ]),
        &["truncated or corrupt"],
    );
}

#[test]
fn every_camera_and_format_renders() {
    // The default scene's cameras and formats, without its clouds (their own tests).
    let t = tables().to_str().unwrap();
    for (camera, size) in [
        ("perspective", (64, 36)),
        ("fisheye", (48, 48)),
        ("equirect", (64, 32)),
        ("cubemap", (96, 16)),
        ("orbit", (48, 48)),
    ] {
        for ext in ["png", "exr", "hdr"] {
            let out = tmp().join(format!("{camera}.{ext}"));
            let o = run(&[
                "render",
                "--tables",
                t,
                "--no-clouds",
                "--camera",
                camera,
                "--width",
                &size.0.to_string(),
                "--height",
                &size.1.to_string(),
                "--sun-zenith-deg",
                "60",
                "--out",
                out.to_str().unwrap(),
                "-q",
            ]);
            assert!(o.status.success(), "{camera} {ext}: {}", stderr(&o));
            assert!(out.exists() && std::fs::metadata(&out).unwrap().len() > 0);
        }
    }
    // EXR holds physical values untouched by exposure: two exposures give the same file.
    let a = tmp().join("ev-a.exr");
    let b = tmp().join("ev-b.exr");
    for (p, ev) in [(&a, "10"), (&b, "16")] {
        assert!(run(&[
            "render",
            "--tables",
            t,
            "--no-clouds",
            "--width",
            "32",
            "--height",
            "18",
            "--ev100",
            ev,
            "--out",
            p.to_str().unwrap(),
            "-q"
        ])
        .status
        .success());
    }
    // (Their headers differ: the provenance names each file's exposure.)
    let (a, b) = (read_exr(&a).unwrap(), read_exr(&b).unwrap());
    assert_eq!(a.data, b.data);
}

#[test]
fn render_errors_leave_no_file() {
    let t = tables().to_str().unwrap();
    let out = tmp().join("never.png");
    let cases: Vec<(Vec<&str>, Vec<&str>)> = vec![
        (
            vec!["--pitch-deg", "120"],
            vec!["camera.pitch_deg", "120", "[-90, 90]"],
        ),
        (vec!["--fov-deg", "0"], vec!["camera.fov_deg", "(0, 180)"]),
        (
            vec!["--sun-zenith-deg", "-3"],
            vec!["sun.zenith_deg", "[0, 180]"],
        ),
        (vec!["--camera", "pinhole"], vec!["--camera", "pinhole"]),
        (vec!["--tonemap", "reinhard"], vec!["--tonemap", "reinhard"]),
        (vec!["--width", "0"], vec!["--width", "[1, 32768]"]),
    ];
    for (extra, words) in cases {
        let mut a = vec!["render", "--tables", t, "--out", out.to_str().unwrap()];
        a.extend(extra);
        fails_with(&run(&a), &words);
        assert!(!out.exists());
    }
    // Unknown format, unwritable directory.
    fails_with(
        &run(&[
            "render",
            "--tables",
            t,
            "--out",
            tmp().join("x.jpg").to_str().unwrap(),
        ]),
        &["out", ".png, .exr, .hdr, .dds or .ktx2"],
    );
    fails_with(
        &run(&["render", "--tables", t, "--out", "/nonexistent-dir/x.png"]),
        &["/nonexistent-dir", "does not exist"],
    );
    // Scene files: unknown fields and bad values.
    let scene = tmp().join("bad-scene.toml");
    std::fs::write(&scene, "[atmosphere]\n[camera]\nprojection = \"fisheye\"\naltitude_m = 0.0\nzoom = 2\n[image]\nwidth = 8\nheight = 8\n[sun]\nzenith_deg = 30.0\n[output]\n").unwrap();
    fails_with(
        &run(&[
            "render",
            "--tables",
            t,
            "--scene",
            scene.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ]),
        &["unknown field", "zoom"],
    );
    std::fs::write(&scene, "[atmosphere]\n[camera]\nprojection = \"fisheye\"\naltitude_m = -10.0\n[image]\nwidth = 8\nheight = 8\n[sun]\nzenith_deg = 30.0\n[output]\n").unwrap();
    fails_with(
        &run(&[
            "render",
            "--tables",
            t,
            "--scene",
            scene.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ]),
        &["camera.altitude_m", "-10"],
    );
    assert!(!out.exists());
}

#[test]
fn example_scenes_are_valid() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let t = tables().to_str().unwrap();
    let mut count = 0;
    for entry in std::fs::read_dir(dir).unwrap() {
        let p = entry.unwrap().path();
        if p.extension().is_some_and(|e| e == "toml") {
            let out = tmp().join(format!(
                "scene-{}.png",
                p.file_stem().unwrap().to_string_lossy()
            ));
            let text = std::fs::read_to_string(&p).unwrap();
            // Scenes on the baked tables' atmosphere reuse them; others compute small ones.
            // Others compute small ones, RGB unless the scene says spectral.
            let tables_args: Vec<&str> = if !text.contains("spectral") {
                if text.contains("preset = \"earth\"") {
                    vec!["--tables", t]
                } else {
                    vec!["--table-size", "small", "--wavelengths", "rgb"]
                }
            } else {
                vec!["--table-size", "small"]
            };
            // Small frames of the scene's shape (an equirect map is 2:1).
            let size: &[&str] = if text.contains("projection = \"equirect\"") {
                &["--height", "16"]
            } else {
                &["--width", "32", "--height", "32"]
            };
            let mut a = vec!["render", "--scene", p.to_str().unwrap()];
            a.extend_from_slice(size);
            a.extend_from_slice(&["--out", out.to_str().unwrap(), "-q"]);
            a.extend(&tables_args);
            let o = run(&a);
            assert!(o.status.success(), "{}: {}", p.display(), stderr(&o));
            count += 1;
        }
    }
    assert!(count >= 3);
}

/// `--no-order-tail` bakes the plain truncated sum of the orders: less multiple scattering
/// than the default (which adds the geometric tail of the orders not computed), and a
/// zenith sky a little darker through `query --tables`.
#[test]
fn no_order_tail_bakes_the_truncated_sum() {
    let plain = tmp().join("earth-small-no-tail.lut");
    let o = run(&[
        "bake",
        "--table-size",
        "small",
        "--orders",
        "3",
        "--wavelengths",
        "rgb",
        "--no-order-tail",
        "--out",
        plain.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let zenith = |tables: &Path| -> f64 {
        let o = run(&[
            "query",
            "--tables",
            tables.to_str().unwrap(),
            "--altitude-m",
            "0",
            "--sun-zenith-deg",
            "40",
            "--view",
            "0,0",
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        v["views"][0]["luminance_cd_m2"].as_f64().unwrap()
    };
    let (with_tail, without) = (zenith(tables()), zenith(&plain));
    assert!(
        without < with_tail && without > 0.95 * with_tail,
        "zenith luminance {without} without the tail, {with_tail} with"
    );
}

#[test]
fn orders_with_tables_are_refused_not_ignored() {
    // The file fixes its orders: `--orders` and `--no-order-tail` with it are refused.
    let t = tables().to_str().unwrap();
    let out = tmp().join("orders-refused.png");
    let out = out.to_str().unwrap();
    for flag in [&["--orders", "6"][..], &["--no-order-tail"][..]] {
        let mut args = vec!["render", "--tables", t, "--out", out];
        args.extend_from_slice(flag);
        fails_with(&run(&args), &[flag[0], "--tables"]);
        let mut args = vec!["query", "--tables", t, "--altitude-m", "0"];
        args.extend_from_slice(&["--sun-zenith-deg", "30"]);
        args.extend_from_slice(flag);
        fails_with(&run(&args), &[flag[0], "--tables"]);
    }
    assert!(!Path::new(out).exists());
}

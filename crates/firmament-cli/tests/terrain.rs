//! Terrain scenes end to end: `query --scene` with the tables and the reference, `render`
//! over a terrain, and the refusals of bad `[terrain]` input (no output left behind).

mod common;

use std::path::PathBuf;

use common::{fails_with, render_scene, run, stderr, succeeds, tables_arg, tmp_subdir};

/// A small terrain scene (8 km, 65² vertices) in `dir`, with `terrain` lines added.
fn scene(dir: &std::path::Path, name: &str, terrain: &str) -> PathBuf {
    let path = dir.join(format!("{name}.toml"));
    let text = format!(
        r#"[atmosphere]
preset = "earth"

[camera]
projection = "perspective"
altitude_m = 25.0
heading_deg = 250.0
pitch_deg = 5.0
fov_deg = 50.0

[image]
width = 32
height = 18

[sun]
zenith_deg = 80.0
azimuth_deg = 240.0

[terrain]
extent_m = 8000
resolution = 65
feature_size_m = 3000
height_scale_m = 900
{terrain}

[output]
files = ["{name}.png"]
"#
    );
    std::fs::write(&path, text).unwrap();
    path
}

fn query(args: &[&str]) -> serde_json::Value {
    let o = run(args);
    succeeds(&o);
    serde_json::from_slice(&o.stdout).unwrap()
}

#[test]
fn query_scene_answers_the_terrain_with_the_tables_and_the_reference() {
    let dir = tmp_subdir("terrain-query");
    let s = scene(&dir, "valley", "");
    let s = s.to_str().unwrap();
    let views = ["--view", "60,240", "--view", "95,60", "--view", "91,240"];
    let mut args = vec!["query", "--scene", s, "--tables", tables_arg(), "-q"];
    args.extend_from_slice(&views);
    let lut = query(&args);
    let ground = lut["terrain_height_m"].as_f64().unwrap();
    assert!(ground > 0.0, "{lut}");
    assert!((lut["altitude_m"].as_f64().unwrap() - (ground + 25.0)).abs() < 1e-6);
    let v = lut["views"].as_array().unwrap();
    assert_eq!(v.len(), 3);
    for view in v {
        assert!(view["luminance_cd_m2"].as_f64().unwrap() > 0.0, "{view}");
    }
    // Looking down at the terrain: the air's transmittance to it is high; to the sky lower.
    let t = |i: usize| v[i]["transmittance"][1].as_f64().unwrap();
    assert!(t(1) > 0.9 && t(1) > t(0), "{} {}", t(0), t(1));
    args.extend_from_slice(&["--method", "reference", "--samples", "400"]);
    let reference = query(&args);
    for (r, l) in reference["views"].as_array().unwrap().iter().zip(v) {
        let (y, se) = (
            r["luminance_cd_m2"].as_f64().unwrap(),
            r["luminance_cd_m2_stderr"].as_f64().unwrap(),
        );
        assert!(se > 0.0 && se < 0.2 * y, "{r}");
        // The same scene: the two agree to tens of per cent at this noise.
        let lum = l["luminance_cd_m2"].as_f64().unwrap();
        assert!((lum / y - 1.0).abs() < 0.5, "lut {lum} reference {y}");
    }
    // Without --tables the tables' ground is lifted to the terrain's floor (at most the
    // ground under the observer), the observer staying 25 m above the terrain.
    let own = query(&[
        "query",
        "--scene",
        s,
        "--table-size",
        "small",
        "--wavelengths",
        "rgb",
        "-q",
        "--view",
        "95,60",
    ]);
    let floor = own["tables_ground_m"].as_f64().unwrap();
    // (This terrain, 8 km across, fades to the sphere within 10 km: its floor is 0.)
    assert!((0.0..=ground).contains(&floor), "{own}");
    assert!((own["altitude_m"].as_f64().unwrap() - (ground + 25.0)).abs() < 1e-6);
    assert!(lut["tables_ground_m"].is_null());
    // `air_light = false`: the tables' light as over a smooth planet; in this valley under a
    // low sun the terrain's change of it is several per cent of the view across it.
    let plain = scene(&dir, "plain", "air_light = false");
    let mut args = vec![
        "query",
        "--scene",
        plain.to_str().unwrap(),
        "--tables",
        tables_arg(),
    ];
    args.extend_from_slice(&["-q", "--view", "95,60"]);
    let without = query(&args)["views"][0]["luminance_cd_m2"]
        .as_f64()
        .unwrap();
    let with = v[1]["luminance_cd_m2"].as_f64().unwrap();
    assert!((with / without - 1.0).abs() > 0.005, "{with} vs {without}");
    // A scene's observer is the scene's: --altitude-m with --scene is refused.
    fails_with(
        &run(&[
            "query",
            "--scene",
            s,
            "--altitude-m",
            "10",
            "--view",
            "60,0",
        ]),
        &["--scene", "--altitude-m"],
    );
}

#[test]
fn query_scene_no_clouds_leaves_the_scene_clouds_out() {
    let dir = tmp_subdir("terrain-query-clouds");
    // A uniform deck (τ = 10, no noise to build) over the valley, added after [terrain].
    let s = scene(
        &dir,
        "overcast",
        "\n[[clouds]]\nkind = \"uniform\"\ncoverage = 1.0\nbottom_m = 3000.0\ntop_m = 4000.0",
    );
    let s = s.to_str().unwrap();
    let args = [
        "query",
        "--scene",
        s,
        "--tables",
        tables_arg(),
        "-q",
        "--view",
        "30,240",
    ];
    let cloudy = query(&args);
    let clear = query(&[&args[..], &["--no-clouds"]].concat());
    assert_eq!(cloudy["cloud_layers"], 1, "{cloudy}");
    assert_eq!(clear["cloud_layers"], 0, "{clear}");
    // Looking up through 10 optical depths of cloud against the clear sky: the deck's base
    // is no blue sky.
    let lum = |v: &serde_json::Value| v["views"][0]["luminance_cd_m2"].as_f64().unwrap();
    let blue = |v: &serde_json::Value| {
        let r = &v["views"][0]["radiance"];
        r[2].as_f64().unwrap() / r[0].as_f64().unwrap()
    };
    assert!(lum(&cloudy) > 0.0 && lum(&clear) > 0.0);
    assert!(blue(&clear) > 1.3 * blue(&cloudy), "{clear} vs {cloudy}");
    // --no-clouds belongs to --scene.
    fails_with(
        &run(&[
            "query",
            "--altitude-m",
            "0",
            "--sun-zenith-deg",
            "30",
            "--view",
            "0,0",
            "--no-clouds",
        ]),
        &["--no-clouds", "--scene"],
    );
}

#[test]
fn render_draws_a_terrain_and_refuses_bad_terrain_input() {
    let dir = tmp_subdir("terrain-render");
    let good = scene(&dir, "good", "");
    let out = dir.join("good.png");
    let o = render_scene(&good, &out, &[]);
    succeeds(&o);
    assert!(out.exists());
    assert!(
        stderr(&o).contains("terrain: 65×65 vertices"),
        "{}",
        stderr(&o)
    );
    let plain = dir.join("plain.png");
    succeeds(&render_scene(&good, &plain, &["--no-air-light"]));
    assert!(plain.exists());
    // An 8-bit heightmap, a zero extent, a negative height scale, a missing file.
    let png8 = dir.join("grey8.png");
    image::GrayImage::new(4, 4).save(&png8).unwrap();
    let cases = [
        (
            format!(
                "heightmap = \"{}\"\nheight_range_m = [0, 500]",
                png8.display()
            ),
            vec!["terrain.heightmap", "16-bit greyscale"],
        ),
        ("extent_m = 0".to_string(), vec!["terrain.extent_m"]),
        (
            "height_scale_m = -5".to_string(),
            vec!["terrain.height_scale_m"],
        ),
        (
            "heightmap = \"missing.png\"\nheight_range_m = [0, 500]".to_string(),
            vec!["missing.png"],
        ),
    ];
    for (k, (lines, words)) in cases.iter().enumerate() {
        // The keys replace the defaults above (TOML refuses duplicates): a fresh section.
        let text = std::fs::read_to_string(&good)
            .unwrap()
            .replace("extent_m = 8000\n", "")
            .replace("height_scale_m = 900\n", "")
            .replace("[terrain]\n", &format!("[terrain]\n{lines}\n"));
        let bad = dir.join(format!("bad{k}.toml"));
        std::fs::write(&bad, text).unwrap();
        let out = dir.join(format!("bad{k}.png"));
        let o = render_scene(&bad, &out, &[]);
        fails_with(&o, words);
        assert!(!out.exists(), "case {k} left {}", out.display());
    }
}

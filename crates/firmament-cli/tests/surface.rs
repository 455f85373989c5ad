//! The planet's surface map end to end: `render` of the planet from orbit with the
//! procedural Earth and with a user's map, `query --scene` over the sea (the glint), and the
//! refusals of bad `[surface]` input (no output left behind).

mod common;

use std::path::{Path, PathBuf};

use common::{fails_with, render_scene, run, succeeds, tables_arg, tmp_subdir};

/// A scene from `altitude_m` looking straight down, with `surface` lines in `[surface]`.
fn scene(dir: &Path, name: &str, altitude_m: f64, surface: &str) -> PathBuf {
    let path = dir.join(format!("{name}.toml"));
    let text = format!(
        r#"[atmosphere]
preset = "earth"

[camera]
projection = "perspective"
altitude_m = {altitude_m}
pitch_deg = -89.0
fov_deg = 20.0

[image]
width = 16
height = 16

[sun]
zenith_deg = 30.0
azimuth_deg = 180.0

[surface]
{surface}

[output]
files = ["{name}.png"]
"#
    );
    std::fs::write(&path, text).unwrap();
    path
}

fn luminance(args: &[&str]) -> f64 {
    let o = run(args);
    succeeds(&o);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    v["views"][0]["luminance_cd_m2"].as_f64().unwrap()
}

#[test]
fn the_sea_shows_the_suns_glint_and_a_map_its_colour() {
    let dir = tmp_subdir("surface");
    // All sea: from 10 km, the sun 60° high in the south is mirrored 30° from the nadir
    // towards the south; the glint makes it brighter than the nadir, and brighter than with
    // the glint off.
    let sea = scene(&dir, "sea", 10_000.0, "ocean_fraction = 1.0");
    let flat = scene(
        &dir,
        "flat",
        10_000.0,
        "ocean_fraction = 1.0\nglint = false",
    );
    let q = |s: &Path, view: &str| {
        let s = s.to_str().unwrap();
        luminance(&[
            "query",
            "--scene",
            s,
            "--tables",
            tables_arg(),
            "-q",
            "--view",
            view,
        ])
    };
    let (mirror, nadir, mirror_off) = (q(&sea, "150,180"), q(&sea, "180,0"), q(&flat, "150,180"));
    // At the peak the glint's BRDF is F(30°)·P(0)/(4 cos² 30°) ≈ 0.021 · 8.2 / 3 ≈ 0.057
    // sr⁻¹ (wind 7 m/s), 2.6 times the sea's diffuse 0.07/π: under 10 km of air, about
    // twice the view's light.
    assert!(mirror > 1.5 * nadir, "mirror {mirror} nadir {nadir}");
    assert!(
        mirror > 1.5 * mirror_off,
        "glint {mirror} without {mirror_off}"
    );
    // The reference traces the map as a Lambertian surface (the glint off): the sea's
    // nadir agrees with the tables to the small tables' and the ground bounce's error.
    let f = flat.to_str().unwrap();
    let reference = luminance(&[
        "query",
        "--scene",
        f,
        "--view",
        "180,0",
        "-q",
        "--method",
        "reference",
        "--samples",
        "300",
        "--wavelengths",
        "rgb",
    ]);
    let lut = q(&flat, "180,0");
    assert!(
        (lut / reference - 1.0).abs() < 0.15,
        "lut {lut} reference {reference}"
    );
    // A map: a white planet reflects more than the sea.
    let white = dir.join("white.png");
    image::RgbImage::from_pixel(8, 4, image::Rgb([255, 255, 255]))
        .save(&white)
        .unwrap();
    let map = scene(
        &dir,
        "map",
        10_000.0,
        &format!("map = \"{}\"", white.display()),
    );
    assert!(q(&map, "180,0") > 5.0 * nadir);
    // Renders from orbit (CPU); the reference refuses the map.
    let orbit = scene(&dir, "orbit", 20_000_000.0, "");
    let out = dir.join("orbit.png");
    succeeds(&render_scene(&orbit, &out, &[]));
    assert!(out.exists());
    fails_with(
        &run(&[
            "query",
            "--scene",
            orbit.to_str().unwrap(),
            "--view",
            "180,0",
            "--method",
            "reference",
        ]),
        &["[surface]", "reference"],
    );
}

#[test]
fn bad_surface_input_is_refused_naming_the_field() {
    let dir = tmp_subdir("surface-bad");
    let grey = dir.join("grey.png");
    image::GrayImage::new(4, 4).save(&grey).unwrap();
    let cases = [
        (
            format!("map = \"{}\"", grey.display()),
            vec!["surface.map", "8-bit sRGB"],
        ),
        ("map = \"missing.png\"".to_string(), vec!["missing.png"]),
        (
            "ocean_fraction = 2".to_string(),
            vec!["surface.ocean_fraction", "[0, 1]"],
        ),
        ("wind_m_s = -1".to_string(), vec!["surface.wind_m_s"]),
    ];
    for (k, (lines, words)) in cases.iter().enumerate() {
        let s = scene(&dir, &format!("bad{k}"), 10_000.0, lines);
        let out = dir.join(format!("bad{k}.png"));
        let o = render_scene(&s, &out, &[]);
        fails_with(&o, words);
        assert!(!out.exists(), "{} left behind", out.display());
    }
}

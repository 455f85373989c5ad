//! Honest defaults (issue 16, item 3): `--help` names every default, `render`, `query` and
//! scene files share them, flags a projection would ignore are refused, sizes follow the
//! map's aspect, and the automatic exposure shows a noon sky bright and blue; a reference
//! render estimates its time and reports its noise (item 7).

mod common;

use common::{fails_with, run, stderr, succeeds, tables_arg, tmp};
use std::path::Path;

use firmament::scene::SceneFile;

/// The help text of `--flag` in `firmament COMMAND --help` (up to the next flag).
fn help_of(command: &str, flag: &str) -> Option<String> {
    let o = run(&[command, "--help"]);
    succeeds(&o);
    let text = String::from_utf8_lossy(&o.stdout).into_owned();
    let start = text.find(&format!("      {flag} "))?;
    let rest = &text[start + flag.len() + 6..];
    let end = rest.find("\n      --").unwrap_or(rest.len());
    Some(rest[..end].to_string())
}

#[test]
fn render_help_names_every_default_and_they_are_the_scenes() {
    let d = SceneFile::default();
    for (flag, value) in [
        ("--camera", "perspective".to_string()),
        ("--width", d.image.width.to_string()),
        ("--height", d.image.height.to_string()),
        ("--altitude-m", d.camera.altitude_m.to_string()),
        ("--heading-deg", d.camera.heading_deg.to_string()),
        ("--pitch-deg", d.camera.pitch_deg.to_string()),
        ("--roll-deg", d.camera.roll_deg.to_string()),
        ("--fov-deg", d.camera.fov_deg.to_string()),
        ("--sun-zenith-deg", d.sun.zenith_deg.to_string()),
        ("--sun-azimuth-deg", d.sun.azimuth_deg.to_string()),
        ("--preset", d.atmosphere.preset.clone()),
        (
            "--wavelengths",
            firmament::scene::file::DEFAULT_WAVELENGTHS.to_string(),
        ),
        ("--pressure-hpa", "1013.25".to_string()),
        ("--temperature-c", "15".to_string()),
        ("--ev100", "automatic".to_string()),
        ("--tonemap", "aces".to_string()),
        ("--gamut", "rec709".to_string()),
        ("--out", d.output.files[0].display().to_string()),
        ("--table-size", "default".to_string()),
        ("--method", "bruneton4d".to_string()),
        ("--samples", "1024".to_string()),
        ("--backend", "auto".to_string()),
    ] {
        let help = help_of("render", flag).unwrap_or_else(|| panic!("{flag} in render --help"));
        let at = help
            .find("[default: ")
            .unwrap_or_else(|| panic!("{flag} names no default: {help}"));
        assert!(
            help[at..].contains(&value),
            "{flag}: default should say {value}: {help}"
        );
    }
    // `bake` lists no flag it refuses.
    assert!(
        help_of("bake", "--tables").is_none(),
        "bake --help lists --tables"
    );
    // `query`'s sun azimuth is `render`'s.
    let q = help_of("query", "--sun-azimuth-deg").unwrap();
    assert!(
        q.contains(&format!("[default: {}", d.sun.azimuth_deg)),
        "{q}"
    );
}

#[test]
fn a_scene_files_sun_without_azimuth_takes_the_default_scenes() {
    let scene = tmp().join("no-azimuth.toml");
    std::fs::write(
        &scene,
        "[atmosphere]\npreset = \"earth\"\n[camera]\nprojection = \"perspective\"\naltitude_m = 10\n\
         [image]\nwidth = 8\nheight = 8\n[sun]\nzenith_deg = 60\n[output]\n",
    )
    .unwrap();
    let parsed = SceneFile::from_file(&scene).unwrap();
    assert_eq!(parsed.sun.azimuth_deg, SceneFile::default().sun.azimuth_deg);
}

#[test]
fn flags_a_projection_would_ignore_are_refused_and_sizes_follow_the_aspect() {
    let t = tables_arg();
    let base = ["render", "--tables", t, "--no-terrain", "--no-clouds", "-q"];
    let with = |extra: &[&str]| {
        let mut a = base.to_vec();
        a.extend_from_slice(extra);
        run(&a)
    };
    fails_with(&with(&["--width", "-5"]), &["--width", "[1, 32768]"]);
    fails_with(
        &with(&["--camera", "equirect", "--pitch-deg", "10"]),
        &["--pitch-deg", "equirect"],
    );
    fails_with(
        &with(&["--camera", "fisheye", "--fov-deg", "90"]),
        &["--fov-deg", "fisheye"],
    );
    fails_with(
        &with(&["--camera", "cubemap", "--heading-deg", "10"]),
        &["--heading-deg", "cubemap"],
    );
    fails_with(&with(&["--size", "16"]), &["--size", "cube map"]);
    fails_with(
        &with(&["--camera", "equirect", "--width", "64", "--height", "64"]),
        &["--width 64", "--height 64", "2:1"],
    );
    fails_with(
        &with(&["--camera", "cubemap", "--width", "100"]),
        &["--width 100", "multiple of 6"],
    );
    fails_with(
        &with(&["--ev100", "12", "--auto-exposure"]),
        &["--ev100", "--auto-exposure"],
    );
    // One size gives the other (the image's aspect); --size gives a cube map's faces.
    for (extra, want) in [
        (vec!["--camera", "equirect", "--width", "64"], (64, 32)),
        (vec!["--camera", "equirect", "--height", "20"], (40, 20)),
        (vec!["--camera", "cubemap", "--height", "8"], (48, 8)),
        (vec!["--camera", "cubemap", "--size", "10"], (60, 10)),
        // A perspective view keeps its aspect (the default 1920×1080), a fisheye is square.
        (vec!["--width", "64"], (64, 36)),
        (vec!["--height", "18"], (32, 18)),
        (vec!["--camera", "fisheye", "--width", "24"], (24, 24)),
        (
            vec![
                "--camera",
                "equirect",
                "--height",
                "16",
                "--heading-deg",
                "90",
            ],
            (32, 16),
        ),
    ] {
        let out = tmp().join(format!("size-{}-{}.png", want.0, want.1));
        let mut e = extra.clone();
        e.extend_from_slice(&["--out", out.to_str().unwrap()]);
        let o = with(&e);
        succeeds(&o);
        let img = image::open(&out).unwrap();
        assert_eq!((img.width(), img.height()), want, "{extra:?}");
    }
}

#[test]
fn automatic_exposure_shows_a_noon_sky_bright_and_blue() {
    let out = tmp().join("noon.png");
    let o = run(&[
        "render",
        "--tables",
        tables_arg(),
        "--no-terrain",
        "--no-clouds",
        "--sun-zenith-deg",
        "30",
        "--sun-azimuth-deg",
        "180",
        "--heading-deg",
        "0",
        "--pitch-deg",
        "25",
        "--fov-deg",
        "70",
        "--width",
        "96",
        "--height",
        "54",
        "--no-dither",
        "--out",
        out.to_str().unwrap(),
    ]);
    succeeds(&o);
    assert!(stderr(&o).contains("automatic"), "{}", stderr(&o));
    let img = image::open(&out).unwrap().to_rgb8();
    // The upper third of the frame is sky: bright blue as in a photograph (a camera's
    // meter puts the frame's average at mid-grey), not navy.
    let (mut r, mut b, mut n) = (0.0, 0.0, 0.0);
    for y in 0..img.height() / 3 {
        for x in 0..img.width() {
            let p = img.get_pixel(x, y);
            r += p[0] as f64;
            b += p[2] as f64;
            n += 1.0;
        }
    }
    let (r, b) = (r / n, b / n);
    assert!(b > 130.0, "sky too dark: blue {b:.0}");
    assert!(b - r > 45.0, "sky not blue: red {r:.0}, blue {b:.0}");
}

#[test]
fn a_reference_render_says_how_long_it_will_take_and_how_noisy_it_is() {
    // Item 7: an estimate before it starts (from a pilot), the noise reached at the end.
    let out = tmp().join("reference.png");
    let o = run(&[
        "render",
        "--method",
        "reference",
        "--backend",
        "cpu",
        "--no-terrain",
        "--no-clouds",
        "--samples",
        "16",
        "--width",
        "24",
        "--height",
        "12",
        "--sun-zenith-deg",
        "60",
        "--out",
        out.to_str().unwrap(),
    ]);
    succeeds(&o);
    let e = stderr(&o);
    assert!(e.contains("about") && e.contains("pilot"), "{e}");
    assert!(e.contains("mean relative standard error"), "{e}");
}

/// The default scene has a few cumulus over its ridges (the written-out default,
/// scenes/valley-sunset.toml, has the same), drawn where the cluster is (the upper right of
/// the frame); `--no-clouds` leaves them out, and only them.
#[test]
fn the_default_scene_has_a_few_cumulus_and_no_clouds_leaves_them_out() {
    let written = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/valley-sunset.toml");
    let written = SceneFile::from_file(&written).unwrap();
    assert_eq!(written.clouds, SceneFile::default().clouds);
    assert_eq!(SceneFile::default().clouds.len(), 1);
    let t = tables_arg();
    let frame = |extra: &[&str], name: &str| {
        let out = tmp().join(name);
        let mut a = vec!["render", "--tables", t, "--width", "64", "--height", "36"];
        a.extend_from_slice(extra);
        a.extend(["--out", out.to_str().unwrap()]);
        let o = run(&a);
        succeeds(&o);
        (stderr(&o), firmament::io::read_exr(&out).unwrap())
    };
    let (said, cloudy) = frame(&[], "default-clouds.exr");
    assert!(
        said.contains("clouds: 1 layer (cumulus 3200–5000 m)"),
        "{said}"
    );
    let (said, clear) = frame(&["--no-clouds"], "default-clear.exr");
    assert!(!said.contains("clouds:"), "{said}");
    // Per pixel, |ΔL|/L: the cluster's rectangle (the upper right, x 38–61 and y 6–17 of
    // 64×36) changes from sky to cloud pixel by pixel; the valley (the lower third, under the
    // ridges' shadow, dimmed by the clouds' shadows in the air) less (11.5 % and 4.8 % when
    // written; 12.0 % and 8.5 % since the air in a cloud's shadow keeps its lit share T of
    // each step instead of all of it where T > ½, docs/accuracy.md).
    let change = |xs: std::ops::Range<usize>, ys: std::ops::Range<usize>| {
        let l = |p: [f32; 3]| 0.2126 * p[0] as f64 + 0.7152 * p[1] as f64 + 0.0722 * p[2] as f64;
        let mut sum = 0.0;
        for y in ys.clone() {
            for x in xs.clone() {
                let i = y * clear.width + x;
                sum += (l(cloudy.data[i]) - l(clear.data[i])).abs() / l(clear.data[i]);
            }
        }
        sum / (xs.len() * ys.len()) as f64
    };
    let (cluster, valley) = (change(38..62, 6..18), change(0..64, 24..36));
    eprintln!(
        "the cumulus change the cluster's pixels by {:.1} %, the valley's by {:.1} % (mean |ΔL|/L)",
        100.0 * cluster,
        100.0 * valley
    );
    assert!(
        cluster > 0.1,
        "the clouds changed the sky by {cluster} only"
    );
    assert!(
        valley < 0.8 * cluster,
        "the valley changed by {valley}, the sky by {cluster}"
    );
}

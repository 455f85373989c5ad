//! Image files other programs load as they are: no negative component in any EXR or
//! Radiance file (colours outside the gamut mapped at their luminance), the EXR's colour
//! space named in its `chromaticities`, no infinity in a half-float EXR (the sun's disk
//! clamped, with a warning).

mod common;

use std::path::Path;

use common::{run, stderr, succeeds, tables_arg, tmp};
use firmament::spectrum::gamut::Gamut;

/// A telephoto view of the sun 1° above the horizon (its disk deep orange: outside Rec. 709
/// in the tables' three wavelengths), written to `out` with `extra` flags.
fn sunset_sun(out: &Path, extra: &[&str]) -> std::process::Output {
    let mut args = vec![
        "render",
        "--tables",
        tables_arg(),
        "--no-terrain",
        "--no-clouds",
        "--camera",
        "perspective",
        "--width",
        "48",
        "--height",
        "48",
        "--fov-deg",
        "1.2",
        "--heading-deg",
        "270",
        "--pitch-deg",
        "1",
        "--sun-zenith-deg",
        "89",
        "--sun-azimuth-deg",
        "270",
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    run(&args)
}

fn luminance(image: &firmament::io::ImageRgbF32, gamut: Gamut) -> f64 {
    let w = gamut.luminance_weights();
    (image.data.iter())
        .map(|p| w[0] * p[0] as f64 + w[1] * p[1] as f64 + w[2] * p[2] as f64)
        .sum()
}

#[test]
fn exr_files_hold_no_negative_and_name_their_gamut() {
    let rec709 = tmp().join("sun-709.exr");
    let rec2020 = tmp().join("sun-2020.exr");
    let aces = tmp().join("sun-aces.exr");
    let hdr = tmp().join("sun.hdr");
    succeeds(&sunset_sun(&rec709, &["-q"]));
    succeeds(&sunset_sun(&rec2020, &["--gamut", "rec2020", "-q"]));
    succeeds(&sunset_sun(&aces, &["--gamut", "acescg", "-q"]));
    succeeds(&sunset_sun(&hdr, &["-q"]));
    for (path, gamut) in [
        (&rec709, Gamut::Rec709),
        (&rec2020, Gamut::Rec2020),
        (&aces, Gamut::AcesCg),
    ] {
        let image = firmament::io::read_exr(path).unwrap();
        assert!(
            image
                .data
                .iter()
                .flatten()
                .all(|&v| v >= 0.0 && v.is_finite()),
            "{}: a negative or non-finite sample",
            path.display()
        );
        let c = firmament::io::read_exr_chromaticities(path).unwrap();
        let expected = gamut.chromaticities();
        let c = c.expect("a chromaticities attribute");
        for (a, b) in [
            (c.red, expected.red),
            (c.green, expected.green),
            (c.blue, expected.blue),
            (c.white, expected.white),
        ] {
            assert!((a[0] - b[0]).abs() < 1e-6 && (a[1] - b[1]).abs() < 1e-6);
        }
    }
    // The sun's disk was outside Rec. 709: mapped there (a component at exactly 0 in its
    // brightest pixels), kept in Rec. 2020 (below); the same light in every file.
    let image = firmament::io::read_exr(&rec709).unwrap();
    let brightest = (image.data.iter())
        .max_by(|a, b| a[0].total_cmp(&b[0]))
        .unwrap();
    assert_eq!(
        brightest[2], 0.0,
        "the disk's blue is mapped to 0: {brightest:?}"
    );
    let wide = firmament::io::read_exr(&rec2020).unwrap();
    // In Rec. 2020 the disk keeps its red and green; its blue sits on the gamut's red–green
    // edge (the dense-spectrum truth of the sun's beam: +2 % of Y in Rec. 2020 blue at 1°
    // elevation, −0.4 % at 0°; `examples/luminance_weights`), so it is mapped at most a hair.
    assert!(wide
        .data
        .iter()
        .any(|p| p[0] > 1e6 && p[1] > 0.1 * p[0] && p[2] >= 0.0));
    // Rec. 2020 shares Rec. 709's white: Y is the same; ACEScg's white is the ACES one, and
    // the Bradford adaptation moves the luminance of saturated colours a little.
    let y709 = luminance(&image, Gamut::Rec709);
    for (path, gamut, tolerance) in [
        (&rec2020, Gamut::Rec2020, 1e-3),
        (&aces, Gamut::AcesCg, 0.02),
    ] {
        let y = luminance(&firmament::io::read_exr(path).unwrap(), gamut);
        assert!(
            (y / y709 - 1.0).abs() < tolerance,
            "{}: {y} vs {y709}",
            path.display()
        );
    }
    let radiance = firmament::io::read_hdr(&hdr).unwrap();
    assert!(radiance.data.iter().flatten().all(|&v| v >= 0.0));
}

#[test]
fn half_float_exr_clamps_the_sun_with_a_warning() {
    let half = tmp().join("sun-half.exr");
    let o = sunset_sun(&half, &["--exr-half"]);
    succeeds(&o);
    assert!(
        stderr(&o).contains("half-float range"),
        "no warning: {}",
        stderr(&o)
    );
    let image = firmament::io::read_exr(&half).unwrap();
    let max = image.data.iter().flatten().fold(0.0f32, |m, &v| m.max(v));
    assert!(image.data.iter().flatten().all(|v| v.is_finite()));
    assert_eq!(max, firmament::io::HALF_MAX);
    // Without the disk nothing is clamped and nothing is said.
    let o = sunset_sun(&half, &["--exr-half", "--no-sun-disk"]);
    succeeds(&o);
    assert!(!stderr(&o).contains("half-float range"), "{}", stderr(&o));
}

#[test]
fn a_bad_gamut_is_refused() {
    let o = sunset_sun(&tmp().join("bad.exr"), &["--gamut", "p3"]);
    assert!(!o.status.success());
    let e = stderr(&o);
    assert!(e.contains("--gamut") && e.contains("rec2020"), "{e}");
    assert!(!tmp().join("bad.exr").exists());
}

//! Environment maps as engines read them (issue 16, items 1 and 2): each cube layout's
//! faces meet seamlessly and the sun lands on the face and pixel that docs/conventions.md
//! says (checked here with the OpenGL face table written out independently of the
//! library), the DDS file holds the same faces, an equirect map's sun sits where the
//! Blender note puts it, and the lamps' JSON agrees with `query`. The DDS and KTX2 files
//! hold the standard faces.

mod common;

use std::path::{Path, PathBuf};

use common::{run, stderr, succeeds, tables_arg, tmp};
use firmament::io::{
    read_dds_cube, read_exr, read_exr_text_attributes, read_ktx2_cube, ImageRgbF32,
};

/// Sun 30° high at azimuth 100° (off every face's centre line and edge).
const SUN: (f64, f64) = (60.0, 100.0);
const FACE: usize = 32;

/// The direction towards (zenith, azimuth) in degrees: x east, y north, z up.
fn enu(zenith_deg: f64, azimuth_deg: f64) -> [f64; 3] {
    let (z, a) = (zenith_deg.to_radians(), azimuth_deg.to_radians());
    [z.sin() * a.sin(), z.sin() * a.cos(), z.cos()]
}

/// OpenGL 4.6 §8.13 (Vulkan's "Cube Map Face and Coordinate Selection"): the face of cube
/// direction c and its (s, t) in [0, 1], t = 0 on the first row of the face image.
fn gl_face(c: [f64; 3]) -> (usize, f64, f64) {
    let [x, y, z] = c;
    let (ax, ay, az) = (x.abs(), y.abs(), z.abs());
    let (face, sc, tc, ma) = if ax >= ay && ax >= az {
        if x > 0.0 {
            (0, -z, -y, ax)
        } else {
            (1, z, -y, ax)
        }
    } else if ay >= az {
        if y > 0.0 {
            (2, x, z, ay)
        } else {
            (3, x, -z, ay)
        }
    } else if z > 0.0 {
        (4, x, -y, az)
    } else {
        (5, -x, -y, az)
    };
    (face, (sc / ma + 1.0) / 2.0, (tc / ma + 1.0) / 2.0)
}

/// The inverse: the cube direction of face `f` at (s, t).
fn gl_direction(f: usize, s: f64, t: f64) -> [f64; 3] {
    let (sc, tc) = (2.0 * s - 1.0, 2.0 * t - 1.0);
    match f {
        0 => [1.0, -tc, -sc],
        1 => [-1.0, -tc, sc],
        2 => [sc, 1.0, tc],
        3 => [sc, -1.0, -tc],
        4 => [sc, -tc, 1.0],
        _ => [-sc, -tc, -1.0],
    }
}

/// docs/conventions.md: the cube axes of each layout from east, north, up.
fn cube_axes(layout: &str, d: [f64; 3]) -> [f64; 3] {
    let [e, n, u] = d;
    match layout {
        "y-up" | "cross" => [e, u, n],
        "unreal" => [n, e, u],
        other => panic!("{other}"),
    }
}

fn render_cube(layout: &str) -> PathBuf {
    let dir = tmp().join(format!("cube-{layout}"));
    std::fs::create_dir_all(&dir).unwrap();
    let exr = dir.join("sky.exr");
    let o = run(&[
        "render",
        "--tables",
        tables_arg(),
        "--no-terrain",
        "--no-clouds",
        "--camera",
        "cubemap",
        "--size",
        &FACE.to_string(),
        "--sun-zenith-deg",
        &SUN.0.to_string(),
        "--sun-azimuth-deg",
        &SUN.1.to_string(),
        "--layout",
        layout,
        "--out",
        exr.to_str().unwrap(),
        "--out",
        dir.join("sky.dds").to_str().unwrap(),
        "--out",
        dir.join("sky.ktx2").to_str().unwrap(),
    ]);
    succeeds(&o);
    assert!(stderr(&o).contains("sky.lights.json"), "{}", stderr(&o));
    dir
}

fn luminance(p: [f32; 3]) -> f64 {
    0.2126 * p[0] as f64 + 0.7152 * p[1] as f64 + 0.0722 * p[2] as f64
}

/// Face `f` of a strip (6 × 1) or a horizontal cross (4 × 3).
fn face_of(image: &ImageRgbF32, layout: &str, f: usize) -> ImageRgbF32 {
    let (cx, cy) = if layout == "cross" {
        [(2, 1), (0, 1), (1, 0), (1, 2), (1, 1), (3, 1)][f]
    } else {
        (f, 0)
    };
    let mut face = ImageRgbF32::new(FACE, FACE);
    for y in 0..FACE {
        for x in 0..FACE {
            face.data[y * FACE + x] = image.data[(cy * FACE + y) * image.width + cx * FACE + x];
        }
    }
    face
}

/// The pixel of the six faces that sees cube direction c.
fn sample(faces: &[ImageRgbF32], c: [f64; 3]) -> [f32; 3] {
    let (f, s, t) = gl_face(c);
    let n = FACE as f64;
    let (x, y) = (
        ((s * n) as usize).min(FACE - 1),
        ((t * n) as usize).min(FACE - 1),
    );
    faces[f].data[y * FACE + x]
}

/// Across every face edge, neighbouring pixels differ no more than neighbours inside a
/// face do (a mirrored or turned face would break this at its edges).
fn assert_seamless(faces: &[ImageRgbF32], layout: &str) {
    let n = FACE as f64;
    let (mut edge, mut inner, mut count_e, mut count_i) = (0.0, 0.0, 0.0, 0.0);
    for (f, face) in faces.iter().enumerate() {
        for k in 0..FACE {
            for (i, j, di, dj) in [
                (k, 0, 0.0, -1.0),
                (k, FACE - 1, 0.0, 1.0),
                (0, k, -1.0, 0.0),
                (FACE - 1, k, 1.0, 0.0),
            ] {
                let here = face.data[j * FACE + i];
                // The pixel centre one step beyond the edge, on the neighbouring face.
                let (s, t) = ((i as f64 + 0.5 + di) / n, (j as f64 + 0.5 + dj) / n);
                let there = sample(faces, gl_direction(f, s, t));
                edge += (luminance(here) - luminance(there)).abs();
                count_e += 1.0;
                // One step inwards, on the same face.
                let (ii, jj) = ((i as f64 - di) as usize, (j as f64 - dj) as usize);
                inner += (luminance(here) - luminance(face.data[jj * FACE + ii])).abs();
                count_i += 1.0;
            }
        }
    }
    let (edge, inner) = (edge / count_e, inner / count_i);
    assert!(
        edge < 2.0 * inner,
        "{layout}: mean step across edges {edge:.2} vs inside {inner:.2} cd/m²"
    );
}

#[test]
fn every_cube_layout_is_seamless_and_puts_the_sun_where_the_docs_say() {
    let yup_faces: Vec<ImageRgbF32>;
    {
        let dir = render_cube("y-up");
        let strip = read_exr(dir.join("sky.exr")).unwrap();
        yup_faces = (0..6).map(|f| face_of(&strip, "y-up", f)).collect();
    }
    for layout in ["y-up", "cross", "unreal"] {
        let dir = render_cube(layout);
        let image = read_exr(dir.join("sky.exr")).unwrap();
        let want = if layout == "cross" {
            (4 * FACE, 3 * FACE)
        } else {
            (6 * FACE, FACE)
        };
        assert_eq!((image.width, image.height), want, "{layout}");
        let faces: Vec<_> = (0..6).map(|f| face_of(&image, layout, f)).collect();
        assert_seamless(&faces, layout);
        // The sun: the brightest pixel is where the face table puts its direction.
        let (f, s, t) = gl_face(cube_axes(layout, enu(SUN.0, SUN.1)));
        let (x, y) = ((s * FACE as f64) as usize, (t * FACE as f64) as usize);
        let brightest = (0..6)
            .flat_map(|g| (0..FACE * FACE).map(move |i| (g, i)))
            .max_by(|a, b| {
                luminance(faces[a.0].data[a.1]).total_cmp(&luminance(faces[b.0].data[b.1]))
            })
            .unwrap();
        assert_eq!(
            brightest,
            (f, y * FACE + x),
            "{layout}: the sun should be on face {f} at ({x}, {y})"
        );
        // The DDS file holds the standard faces: unreal's, else y-up's (the cross's too).
        let dds = read_dds_cube(dir.join("sky.dds")).unwrap();
        let expected = if layout == "unreal" {
            &faces
        } else {
            &yup_faces
        };
        for (g, (a, b)) in dds.iter().zip(expected).enumerate() {
            assert_eq!(a.data, b.data, "{layout}: DDS face {g}");
        }
        // The KTX2 file (parsed by the `ktx2` crate's reader) holds the same faces.
        let ktx = read_ktx2_cube(dir.join("sky.ktx2")).unwrap();
        assert_eq!(ktx, dds, "{layout}: KTX2 faces");
        // The EXR carries the provenance.
        let attributes = read_exr_text_attributes(dir.join("sky.exr")).unwrap();
        let get = |k: &str| {
            attributes
                .iter()
                .find(|(n, _)| n == k)
                .map(|(_, v)| v.clone())
        };
        assert_eq!(get("firmament:atmosphere.name").as_deref(), Some("earth"));
        assert!(get("firmament:version").is_some() && get("firmament:tables.orders").is_some());
        assert_eq!(
            get("firmament:camera.projection").as_deref(),
            Some("cubemap")
        );
    }
    // The same cube's two layouts hold the same pixels: y-up's faces are the cross's.
    let cross = read_exr(tmp().join("cube-cross").join("sky.exr")).unwrap();
    for (f, face) in yup_faces.iter().enumerate() {
        assert_eq!(
            face_of(&cross, "cross", f).data,
            face.data,
            "cross face {f}"
        );
    }
}

fn lamps(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

#[test]
fn an_equirect_maps_sun_is_where_the_blender_note_says_and_its_lamp_matches_query() {
    for heading in [0.0, 30.0] {
        let dir = tmp().join(format!("equirect-{heading}"));
        std::fs::create_dir_all(&dir).unwrap();
        let exr = dir.join("sky.exr");
        let o = run(&[
            "render",
            "--tables",
            tables_arg(),
            "--no-terrain",
            "--no-clouds",
            "--camera",
            "equirect",
            "--width",
            "360",
            "--heading-deg",
            &heading.to_string(),
            "--sun-zenith-deg",
            "60",
            "--sun-azimuth-deg",
            "90",
            "--out",
            exr.to_str().unwrap(),
        ]);
        succeeds(&o);
        let image = read_exr(&exr).unwrap();
        let (mut best, mut at) = (0.0, 0);
        for (i, p) in image.data.iter().enumerate() {
            if luminance(*p) > best {
                (best, at) = (luminance(*p), i);
            }
        }
        // docs/conventions.md: the centre column faces the heading, columns turn
        // clockwise: azimuth 90° is at u = 0.5 + (90 − heading)/360; elevation 30° is a
        // third of the way from the middle row to the top.
        let (x, y) = (at % image.width, at / image.width);
        let u = 0.5 + (90.0 - heading) / 360.0;
        assert!(
            ((x as f64 + 0.5) / 360.0 - u).abs() < 1.5 / 360.0,
            "column {x}, u {u}"
        );
        assert!(((y as f64 + 0.5) - 60.0).abs() < 1.5, "row {y}");
        // In Blender (centre column on +X, turning towards −Y) the sun is at
        // (cos(90° − h)·cos 30°, −sin(90° − h)·cos 30°, sin 30°).
        let l = lamps(&dir.join("sky.lights.json"));
        let sun = &l["lamps"][0];
        assert_eq!(sun["name"], "sun");
        let rel = (90.0 - heading).to_radians();
        let c30 = 30f64.to_radians().cos();
        let want = [rel.cos() * c30, -rel.sin() * c30, 0.5];
        for (k, w) in want.iter().enumerate() {
            let got = sun["blender"]["direction"][k].as_f64().unwrap();
            assert!(
                (got - w).abs() < 1e-9,
                "blender direction {k}: {got} vs {w}"
            );
        }
        assert_eq!(sun["disk_in_map"], true);
    }
    // The lamp's illuminance is query's direct beam (its horizontal sun irradiance over
    // cos 60°), from the model's exact transmittance rather than the tables'.
    let q = run(&[
        "query",
        "--tables",
        tables_arg(),
        "--altitude-m",
        "25",
        "--sun-zenith-deg",
        "60",
        "--sun-azimuth-deg",
        "90",
        "--view",
        "0,0",
    ]);
    succeeds(&q);
    let q: serde_json::Value = serde_json::from_slice(&q.stdout).unwrap();
    // Its provenance (item 6): program, atmosphere, method, tables, wavelengths.
    let p = &q["provenance"];
    assert_eq!(p["program"], "firmament");
    assert_eq!(p["atmosphere"]["name"], "earth");
    assert_eq!(p["atmosphere"]["hash"].as_str().map(str::len), Some(16));
    assert!(p["method"].as_str().unwrap().contains("bruneton4d"));
    assert_eq!(p["tables"]["orders"], 3);
    assert_eq!(p["wavelengths_nm"].as_array().map(Vec::len), Some(3));
    assert!(
        q["notes"].as_array().unwrap().len() >= 2,
        "notes say what was approximated"
    );
    let normal = q["irradiance"]["sun_lux"].as_f64().unwrap() / 0.5;
    let l = lamps(&tmp().join("equirect-0").join("sky.lights.json"));
    let lux = l["lamps"][0]["illuminance_lux"].as_f64().unwrap();
    assert!(
        (lux / normal - 1.0).abs() < 0.005,
        "lamp {lux:.0} lx, query {normal:.0} lx"
    );
    // Without the disk the lamp says so: the map holds the sky alone.
    let exr = tmp().join("nodisk.exr");
    succeeds(&run(&[
        "render",
        "--tables",
        tables_arg(),
        "--no-terrain",
        "--no-clouds",
        "--camera",
        "equirect",
        "--width",
        "64",
        "--no-sun-disk",
        "--out",
        exr.to_str().unwrap(),
        "-q",
    ]));
    assert_eq!(
        lamps(&tmp().join("nodisk.lights.json"))["lamps"][0]["disk_in_map"],
        false
    );
}

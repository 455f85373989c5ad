use super::*;
use crate::io::atomic::{temp_path, write_atomic};
use std::io::Write;
use std::path::PathBuf;

/// A fresh scratch directory, removed on drop.
struct Scratch(PathBuf);

impl Scratch {
    fn new(name: &str) -> Self {
        let dir = std::env::temp_dir().join(format!("firmament-io-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        Scratch(dir)
    }
    fn path(&self, name: &str) -> PathBuf {
        self.0.join(name)
    }
    fn entries(&self) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(&self.0)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// Deterministic pseudo-random values spanning `lo..hi` logarithmically.
fn log_image(w: usize, h: usize, lo: f32, hi: f32, seed: u64) -> ImageRgbF32 {
    let mut s = seed;
    let mut next = || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((s >> 11) as f64 / (1u64 << 53) as f64) as f32
    };
    let mut img = ImageRgbF32::new(w, h);
    let (a, b) = (lo.ln(), hi.ln());
    for y in 0..h {
        for x in 0..w {
            img.set(x, y, [0; 3].map(|_| (a + (b - a) * next()).exp()));
        }
    }
    img
}

#[test]
fn image_get_set() {
    let mut img = ImageRgbF32::new(3, 2);
    assert_eq!(img.data.len(), 6);
    img.set(2, 1, [1.0, 2.0, 3.0]);
    assert_eq!(img.get(2, 1), [1.0, 2.0, 3.0]);
    assert_eq!(img.data[5], [1.0, 2.0, 3.0]);
    assert_eq!(img.get(0, 0), [0.0; 3]);
}

#[test]
fn output_format_from_path() {
    assert_eq!(
        OutputFormat::from_path("a/b/sky.png").unwrap(),
        OutputFormat::Png
    );
    assert_eq!(
        OutputFormat::from_path("sky.EXR").unwrap(),
        OutputFormat::Exr
    );
    assert_eq!(
        OutputFormat::from_path("sky.hdr").unwrap(),
        OutputFormat::Hdr
    );
    for bad in ["sky.jpg", "sky", "sky.png.bak", ".png"] {
        match OutputFormat::from_path(bad) {
            Err(Error::InvalidParameter {
                field,
                value,
                expected,
            }) => {
                assert_eq!(field, "out");
                assert_eq!(value, bad);
                assert!(expected.contains(".png, .exr, .hdr, .dds or .ktx2"));
            }
            other => panic!("{bad}: {other:?}"),
        }
    }
}

#[test]
fn png_round_trip_and_no_temp_files() {
    let dir = Scratch::new("png");
    let (w, h) = (5, 3);
    let px: Vec<[u8; 3]> = (0..w * h)
        .map(|i| [i as u8, (i * 7) as u8, 255 - i as u8])
        .collect();
    let p = dir.path("out.png");
    write_png_srgb8(&p, w, h, &px).unwrap();
    assert_eq!(read_png_srgb8(&p).unwrap(), (w, h, px.clone()));
    assert_eq!(dir.entries(), vec!["out.png"]);
    // Overwrite in place.
    let px2 = vec![[1, 2, 3]; w * h];
    write_png_srgb8(&p, w, h, &px2).unwrap();
    assert_eq!(read_png_srgb8(&p).unwrap().2, px2);
    assert_eq!(dir.entries(), vec!["out.png"]);
    // Wrong length refused, nothing written.
    assert!(write_png_srgb8(dir.path("bad.png"), w, h, &px[1..]).is_err());
    assert_eq!(dir.entries(), vec!["out.png"]);
}

#[test]
fn exr_f32_round_trip_is_exact() {
    let dir = Scratch::new("exr32");
    let mut img = log_image(37, 23, 1e-6, 1e9, 1);
    img.set(0, 0, [0.0, 1.0, 123.456]);
    let p = dir.path("sky.exr");
    write_exr(&p, &img, ExrPrecision::F32).unwrap();
    let back = read_exr(&p).unwrap();
    assert_eq!(back, img);
    assert_eq!(dir.entries(), vec!["sky.exr"]);
}

#[test]
fn exr_f16_round_trip_within_half_precision() {
    let dir = Scratch::new("exr16");
    let img = log_image(41, 19, 1e-4, 6e4, 2);
    let p = dir.path("sky.exr");
    write_exr(&p, &img, ExrPrecision::F16).unwrap();
    let back = read_exr(&p).unwrap();
    assert_eq!((back.width, back.height), (img.width, img.height));
    for (a, b) in img.data.iter().zip(&back.data) {
        for c in 0..3 {
            let rel = ((a[c] - b[c]) / a[c]).abs();
            assert!(rel <= 1e-3, "{} -> {} (rel {rel})", a[c], b[c]);
        }
    }
    // Half samples are half the size of float samples (ZIP-compressed noise, roughly).
    let p32 = dir.path("sky32.exr");
    write_exr(&p32, &img, ExrPrecision::F32).unwrap();
    assert!(std::fs::metadata(&p).unwrap().len() < std::fs::metadata(&p32).unwrap().len());
    assert_eq!(dir.entries(), vec!["sky.exr", "sky32.exr"]);
}

#[test]
fn exr_text_attributes() {
    let dir = Scratch::new("exrattr");
    let img = log_image(8, 4, 0.1, 10.0, 3);
    let p = dir.path("a.exr");
    write_exr_with_attributes(
        &p,
        &img,
        ExrPrecision::F16,
        &[("firmament:preset", "clear"), ("sun", "30 deg")],
    )
    .unwrap();
    let attrs = read_exr_text_attributes(&p).unwrap();
    assert!(
        attrs.contains(&("firmament:preset".into(), "clear".into())),
        "{attrs:?}"
    );
    assert!(
        attrs.contains(&("sun".into(), "30 deg".into())),
        "{attrs:?}"
    );
    assert_eq!(read_exr(&p).unwrap().width, 8);
}

fn assert_rgbe_close(a: &ImageRgbF32, b: &ImageRgbF32) {
    assert_eq!((a.width, a.height), (b.width, b.height));
    for (pa, pb) in a.data.iter().zip(&b.data) {
        let max = pa[0].max(pa[1]).max(pa[2]);
        for c in 0..3 {
            assert!((pa[c] - pb[c]).abs() <= max / 128.0, "{pa:?} -> {pb:?}");
        }
    }
}

#[test]
fn rgbe_encoding_matches_ward() {
    // 1.0 = 0.5 * 2^1: exponent 129, mantissa 128.
    assert_eq!(rgbe_encode([1.0, 0.5, 0.0]), [128, 64, 0, 129]);
    assert_eq!(rgbe_encode([0.0; 3]), [0; 4]);
    assert_eq!(rgbe_encode([1e-33, 0.0, -5.0]), [0; 4]);
    assert_eq!(rgbe_encode([f32::NAN, 0.0, 0.0]), [0; 4]);
    // Just below a power of two: mantissa 255, exponent of the power.
    assert_eq!(rgbe_encode([0.999_999_9, 0.0, 0.0]), [255, 0, 0, 128]);
    assert_eq!(rgbe_decode([0, 0, 0, 0]), [0.0; 3]);
    assert_eq!(
        rgbe_decode([128, 64, 0, 129]),
        [128.5 / 128.0, 64.5 / 128.0, 0.5 / 128.0]
    );
    // Extremes stay representable.
    let big = rgbe_encode([f32::INFINITY, 1e38, 1.0]);
    assert_eq!(big, [150, 150, 0, 255]);
    for v in [1e-30f32, 3.3e-7, 0.75, 1.0, 1.5, 6e4, 1e30] {
        let d = rgbe_decode(rgbe_encode([v, v / 3.0, v / 200.0]));
        assert!((d[0] - v).abs() <= v / 256.0, "{v} -> {d:?}");
        assert!((d[1] - v / 3.0).abs() <= v / 256.0, "{v} -> {d:?}");
    }
}

#[test]
fn hdr_round_trip_within_rgbe_precision() {
    let dir = Scratch::new("hdr");
    let mut img = log_image(300, 7, 1e-5, 1e6, 4);
    // Long runs (sky gradients, black borders) exercise the RLE run path.
    for x in 0..100 {
        img.set(x, 3, [0.0; 3]);
        img.set(x, 4, [2.0, 1.0, 0.5]);
    }
    let p = dir.path("sky.hdr");
    write_hdr(&p, &img).unwrap();
    let bytes = std::fs::read(&p).unwrap();
    assert!(bytes.starts_with(b"#?RADIANCE\n"));
    let text = String::from_utf8_lossy(&bytes[..80]);
    assert!(
        text.contains("FORMAT=32-bit_rle_rgbe\n\n-Y 7 +X 300\n"),
        "{text}"
    );
    let back = read_hdr(&p).unwrap();
    assert_rgbe_close(&img, &back);

    // Flat scanlines decode to the same pixels.
    let flat = dir.path("flat.hdr");
    write_hdr_uncompressed(&flat, &img).unwrap();
    assert_eq!(read_hdr(&flat).unwrap(), back);
    // Widths without RLE (< 8) use flat scanlines.
    let small = log_image(5, 3, 0.01, 100.0, 5);
    let ps = dir.path("small.hdr");
    write_hdr(&ps, &small).unwrap();
    assert_rgbe_close(&small, &read_hdr(&ps).unwrap());
    assert_eq!(dir.entries(), vec!["flat.hdr", "sky.hdr", "small.hdr"]);
}

#[test]
fn hdr_reads_old_rle_bottom_up_and_exposure() {
    let dir = Scratch::new("hdrold");
    let mut bytes = b"#?RGBE\nEXPOSURE=2\n\n+Y 2 +X 4\n".to_vec();
    // Bottom row (stored first): one pixel then an old-style run of 3.
    bytes.extend_from_slice(&[128, 64, 0, 129, 1, 1, 1, 3]);
    // Top row: flat.
    for _ in 0..4 {
        bytes.extend_from_slice(&[128, 128, 128, 130]);
    }
    let p = dir.path("old.hdr");
    std::fs::write(&p, &bytes).unwrap();
    let img = read_hdr(&p).unwrap();
    let top = rgbe_decode([128, 128, 128, 130]).map(|c| c / 2.0);
    let bottom = rgbe_decode([128, 64, 0, 129]).map(|c| c / 2.0);
    assert_eq!(img.get(3, 0), top);
    assert_eq!(img.get(0, 1), bottom);
    assert_eq!(img.get(3, 1), bottom);
    // Truncated file refused.
    std::fs::write(&p, &bytes[..bytes.len() - 2]).unwrap();
    let err = read_hdr(&p).unwrap_err().to_string();
    assert!(err.contains("truncated"), "{err}");
}

#[test]
fn unwritable_path_errors_and_leaves_no_file() {
    let dir = Scratch::new("unwritable");
    let img = log_image(8, 8, 0.1, 1.0, 6);
    let missing = dir.path("no-such-dir");
    type Writer<'a> = Box<dyn Fn(&Path) -> Result<()> + 'a>;
    let cases: [(&str, Writer); 4] = [
        (
            "a.png",
            Box::new(|p| write_png_srgb8(p, 1, 1, &[[0, 0, 0]])),
        ),
        ("a.exr", Box::new(|p| write_exr(p, &img, ExrPrecision::F32))),
        ("b.exr", Box::new(|p| write_exr(p, &img, ExrPrecision::F16))),
        ("a.hdr", Box::new(|p| write_hdr(p, &img))),
    ];
    for (name, write) in &cases {
        let p = missing.join(name);
        match write(&p) {
            Err(Error::File { path, reason }) => {
                assert_eq!(path, p.display().to_string());
                assert!(reason.contains("does not exist"), "{reason}");
            }
            other => panic!("{name}: {other:?}"),
        }
        assert!(!p.exists());
        assert!(!missing.exists());
    }
    assert!(dir.entries().is_empty(), "{:?}", dir.entries());

    // A directory in place of the file: refused, no temporary left behind.
    std::fs::create_dir(dir.path("d.hdr")).unwrap();
    assert!(write_hdr(dir.path("d.hdr"), &img).is_err());
    assert_eq!(dir.entries(), vec!["d.hdr"]);

    // Bad image data: refused before anything is created.
    let bad = ImageRgbF32 {
        width: 4,
        height: 4,
        data: vec![[0.0; 3]; 3],
    };
    assert!(write_exr(dir.path("x.exr"), &bad, ExrPrecision::F32).is_err());
    assert!(write_hdr(dir.path("x.hdr"), &bad).is_err());
    assert_eq!(dir.entries(), vec!["d.hdr"]);
}

#[cfg(unix)]
#[test]
fn permission_denied_is_reported() {
    use std::os::unix::fs::PermissionsExt;
    let dir = Scratch::new("perm");
    let ro = dir.path("ro");
    std::fs::create_dir(&ro).unwrap();
    std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o555)).unwrap();
    // Root ignores directory permissions; only check when the probe fails.
    let probe = std::fs::File::create(ro.join("probe"));
    if probe.is_err() {
        let err = write_hdr(ro.join("a.hdr"), &ImageRgbF32::new(2, 2))
            .unwrap_err()
            .to_string();
        assert!(err.contains("permission denied"), "{err}");
    }
    std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o755)).unwrap();
}

#[test]
fn failed_write_keeps_previous_file_and_removes_temporary() {
    let dir = Scratch::new("keep");
    let p = dir.path("sky.exr");
    std::fs::write(&p, b"previous").unwrap();
    let r = write_atomic(&p, |w| {
        w.write_all(b"partial").unwrap();
        Err(file_error(&p, "simulated failure"))
    });
    assert!(r.is_err());
    assert_eq!(std::fs::read(&p).unwrap(), b"previous");
    assert_eq!(dir.entries(), vec!["sky.exr"]);
    // A panic inside the writer also removes the temporary.
    let p2 = p.clone();
    let caught = std::panic::catch_unwind(move || {
        let _ = write_atomic(&p2, |w| {
            w.write_all(b"partial").unwrap();
            panic!("simulated panic");
        });
    });
    assert!(caught.is_err());
    assert_eq!(dir.entries(), vec!["sky.exr"]);
    assert_eq!(
        temp_path(&p)
            .unwrap()
            .file_name()
            .unwrap()
            .to_string_lossy(),
        format!(".sky.exr.tmp-{}", std::process::id())
    );
}

#[test]
fn reading_missing_files_reports_clearly() {
    let dir = Scratch::new("missing");
    for r in [
        read_exr(dir.path("none.exr")).map(|_| ()),
        read_hdr(dir.path("none.hdr")).map(|_| ()),
        read_png_srgb8(dir.path("none.png")).map(|_| ()),
    ] {
        match r {
            Err(Error::File { reason, .. }) => {
                assert!(reason.contains("does not exist"), "{reason}")
            }
            other => panic!("{other:?}"),
        }
    }
    // Garbage is refused, not panicked on.
    let g = dir.path("garbage.exr");
    std::fs::write(&g, b"not an image").unwrap();
    assert!(read_exr(&g).is_err());
    let g = dir.path("garbage.hdr");
    std::fs::write(&g, b"not an image").unwrap();
    assert!(read_hdr(&g).is_err());
}

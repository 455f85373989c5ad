//! The table cache seen from the command line: a second render reads the tables the first
//! computed (its line on stderr, the file untouched), a corrupt file is deleted and computed
//! again with a warning, `--no-cache` writes nothing. Each test has a cache directory of its
//! own (`FIRMAMENT_CACHE_DIR`), never the user's.

mod common;

use std::os::unix::fs::MetadataExt;
use std::path::{Path, PathBuf};
use std::process::Output;

use common::{bin, stderr, succeeds, tmp_subdir};

/// `render` of a small, terrain-free RGB sky with small tables, its cache in `cache`.
fn render(cache: &Path, extra: &[&str]) -> Output {
    let out = cache.with_extension("png");
    bin()
        .env("FIRMAMENT_CACHE_DIR", cache)
        .args([
            "render",
            "--no-terrain",
            "--no-clouds",
            "--wavelengths",
            "rgb",
            "--table-size",
            "small",
        ])
        .args(["--width", "24", "--height", "16", "--out"])
        .arg(&out)
        .args(extra)
        .output()
        .expect("run the firmament binary")
}

/// The table files in `dir`.
fn cached_files(dir: &Path) -> Vec<PathBuf> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    entries
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "firmlut"))
        .collect()
}

#[test]
fn a_second_render_reads_the_tables_the_first_cached() {
    let cache = tmp_subdir("hit");
    let first = render(&cache, &[]);
    succeeds(&first);
    let e = stderr(&first);
    assert!(
        e.contains("; cached at ") && !e.contains("from cache"),
        "{e}"
    );
    let files = cached_files(&cache);
    assert_eq!(files.len(), 1, "{files:?}");
    assert!(e.contains(&files[0].display().to_string()), "{e}");
    let before = std::fs::metadata(&files[0]).unwrap();

    let second = render(&cache, &[]);
    succeeds(&second);
    let e = stderr(&second);
    assert!(
        e.contains(&format!("tables: from cache {}", files[0].display())),
        "{e}"
    );
    assert!(!e.contains("cached at"), "{e}");
    let after = std::fs::metadata(&files[0]).unwrap();
    assert_eq!(
        (after.ino(), after.mtime(), after.mtime_nsec(), after.len()),
        (
            before.ino(),
            before.mtime(),
            before.mtime_nsec(),
            before.len()
        ),
        "the cached file was written again"
    );
    assert_eq!(cached_files(&cache), files);
    // Other tables (spectral) are another file; the first stays.
    let spectral = bin()
        .env("FIRMAMENT_CACHE_DIR", &cache)
        .args([
            "query",
            "--table-size",
            "small",
            "--orders",
            "2",
            "--altitude-m",
            "0",
        ])
        .args([
            "--sun-zenith-deg",
            "40",
            "--view",
            "0,0",
            "--backend",
            "cpu",
        ])
        .output()
        .unwrap();
    succeeds(&spectral);
    assert!(stderr(&spectral).contains("wavelengths: spectral (16 samples 365–815 nm)"));
    let mut now = cached_files(&cache);
    now.sort();
    assert_eq!(now.len(), 2, "{now:?}");
    assert!(now.contains(&files[0]));
}

#[test]
fn a_corrupt_cached_file_is_deleted_and_computed_again() {
    for (name, damage) in [
        (
            "flipped",
            (|b: &mut Vec<u8>| {
                let at = b.len() / 3;
                b[at] ^= 0x10
            }) as fn(&mut Vec<u8>),
        ),
        ("truncated", |b: &mut Vec<u8>| b.truncate(b.len() / 2)),
        ("empty", |b: &mut Vec<u8>| b.clear()),
    ] {
        let cache = tmp_subdir(&format!("corrupt-{name}"));
        succeeds(&render(&cache, &[]));
        let file = cached_files(&cache).pop().unwrap();
        let good = std::fs::read(&file).unwrap();
        let mut bad = good.clone();
        damage(&mut bad);
        std::fs::write(&file, &bad).unwrap();

        let o = render(&cache, &[]);
        succeeds(&o);
        let e = stderr(&o);
        assert!(
            e.contains(&format!(
                "warning: the cached tables {} were unusable",
                file.display()
            )) && e.contains("deleted, computing them again"),
            "{name}: {e}"
        );
        assert!(
            e.contains("; cached at ") && !e.contains("from cache"),
            "{name}: {e}"
        );
        // Rebuilt whole: as long as the first time, and read back the next time.
        assert_eq!(
            std::fs::metadata(&file).unwrap().len(),
            good.len() as u64,
            "{name}"
        );
        let o = render(&cache, &[]);
        assert!(
            stderr(&o).contains("tables: from cache"),
            "{name}: {}",
            stderr(&o)
        );
    }
}

#[test]
fn no_cache_neither_reads_nor_writes() {
    let cache = tmp_subdir("none");
    let o = render(&cache, &["--no-cache"]);
    succeeds(&o);
    let e = stderr(&o);
    assert!(
        e.contains("tables: ") && !e.contains("cached at") && !e.contains("from cache"),
        "{e}"
    );
    assert_eq!(
        std::fs::read_dir(&cache).unwrap().count(),
        0,
        "nothing written"
    );
    // With a cached file present, --no-cache computes anyway.
    succeeds(&render(&cache, &[]));
    let o = render(&cache, &["--no-cache"]);
    assert!(!stderr(&o).contains("from cache"), "{}", stderr(&o));
}

#[test]
fn a_bad_cache_limit_is_refused_with_the_variable_named() {
    let cache = tmp_subdir("limit");
    let o = bin()
        .env("FIRMAMENT_CACHE_DIR", &cache)
        .env("FIRMAMENT_CACHE_LIMIT_MB", "lots")
        .args(["query", "--table-size", "small", "--wavelengths", "rgb"])
        .args([
            "--altitude-m",
            "0",
            "--sun-zenith-deg",
            "40",
            "--backend",
            "cpu",
        ])
        .output()
        .unwrap();
    common::fails_with(&o, &["FIRMAMENT_CACHE_LIMIT_MB", "lots", "MiB"]);
    // A limit below one file's size: computed, not cached, with a warning.
    let o = bin()
        .env("FIRMAMENT_CACHE_DIR", &cache)
        .env("FIRMAMENT_CACHE_LIMIT_MB", "0")
        .args(["query", "--table-size", "small", "--wavelengths", "rgb"])
        .args([
            "--altitude-m",
            "0",
            "--sun-zenith-deg",
            "40",
            "--backend",
            "cpu",
        ])
        .output()
        .unwrap();
    succeeds(&o);
    assert!(
        stderr(&o).contains("warning: tables not cached"),
        "{}",
        stderr(&o)
    );
    assert!(cached_files(&cache).is_empty());
}

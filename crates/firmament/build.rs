//! The tables' code fingerprint: an FNV-1a hash of the library sources and data that
//! determine the precomputed tables (the atmosphere, media, spectra, maths and the 4D-table
//! method), handed to the crate as `FIRMAMENT_TABLES_FINGERPRINT`. The table cache
//! (`sky/bruneton4d/cache.rs`) keys its files by it, so that tables computed by other code
//! (a fix in a precompute pass, a new spectrum table) are never read back as if current.

use std::path::{Path, PathBuf};

/// What the tables depend on, relative to the crate's root.
const INPUTS: &[&str] = &[
    "src/atmosphere",
    "src/medium",
    "src/spectrum",
    "src/math",
    "src/sky/bruneton4d",
    "data/presets",
    "data/astm_g173_extraterrestrial.csv",
    "data/cie1931_2deg.csv",
    "data/ozone_cross_section.csv",
];

fn files_under(path: &Path, out: &mut Vec<PathBuf>) {
    if path.is_dir() {
        let mut entries: Vec<PathBuf> = std::fs::read_dir(path)
            .expect("readable source directory")
            .map(|e| e.expect("readable directory entry").path())
            .collect();
        entries.sort();
        for entry in entries {
            files_under(&entry, out);
        }
    } else {
        out.push(path.to_path_buf());
    }
}

fn main() {
    let mut hash: u64 = 0xcbf2_9ce4_8422_2325;
    let mut eat = |bytes: &[u8]| {
        for b in bytes {
            hash ^= *b as u64;
            hash = hash.wrapping_mul(0x0000_0100_0000_01b3);
        }
    };
    for input in INPUTS {
        println!("cargo:rerun-if-changed={input}");
        let mut files = Vec::new();
        files_under(Path::new(input), &mut files);
        for file in files {
            // The path (with `/` on every system) and the contents.
            eat(file.to_string_lossy().replace('\\', "/").as_bytes());
            eat(&std::fs::read(&file).expect("readable source file"));
        }
    }
    println!("cargo:rustc-env=FIRMAMENT_TABLES_FINGERPRINT={hash:016x}");
}

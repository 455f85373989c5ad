//! Helpers shared by the integration tests: the binary (with a table cache of its own per
//! test binary, never the user's), a temporary directory per test binary, running a command
//! and reading its stderr, the checks on success and failure, and small RGB tables baked
//! once.
//!
//! Each test file compiles its own copy (`mod common;`) and uses only some of these.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::OnceLock;

/// The `firmament` binary under test, its table cache in [`cache_dir`]: the tests of one
/// binary that compute the same tables compute them once, and never touch the user's cache.
pub fn bin() -> Command {
    let mut command = Command::new(env!("CARGO_BIN_EXE_firmament"));
    command.env("FIRMAMENT_CACHE_DIR", cache_dir());
    command
}

/// This test binary's table cache.
pub fn cache_dir() -> PathBuf {
    tmp().join("cache")
}

/// A directory of this test binary (`backend`, `cli`, `validate`) and process, created once.
pub fn tmp() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let d = std::env::temp_dir().join(format!(
            "firmament-cli-{}-test-{}",
            env!("CARGO_CRATE_NAME"),
            std::process::id()
        ));
        std::fs::create_dir_all(&d).unwrap();
        d
    })
}

/// A fresh subdirectory `name` of [`tmp`].
pub fn tmp_subdir(name: &str) -> PathBuf {
    let dir = tmp().join(name);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Run the binary with `args` and wait for it. A run that draws on the GPU (`--backend
/// gpu`, or `view`) is run again, up to six times, while it dies of the test driver's known
/// heap corruption ([`firmament_gpu::driver_crash`]); an exit code of firmament's own is
/// returned at once.
pub fn run(args: &[&str]) -> Output {
    let once = || bin().args(args).output().expect("run the firmament binary");
    if !(args.contains(&"gpu") || args.first() == Some(&"view")) {
        return once();
    }
    for attempt in 1..=6 {
        let o = once();
        match firmament_gpu::driver_crash(&o.status, &stderr(&o)) {
            None => return o,
            Some(why) => eprintln!(
                "attempt {attempt}: {args:?} {why} ({}): lavapipe's heap corruption, running it again",
                o.status
            ),
        }
    }
    panic!("crashed six times: {args:?}");
}

/// `firmament render --scene SCENE --tables (the small tables) --out OUT`, and `extra`.
pub fn render_scene(scene: &Path, out: &Path, extra: &[&str]) -> Output {
    let mut args = vec![
        "render",
        "--scene",
        scene.to_str().unwrap(),
        "--tables",
        tables_arg(),
    ];
    args.extend_from_slice(&["--out", out.to_str().unwrap()]);
    args.extend_from_slice(extra);
    run(&args)
}

/// What the command printed on stderr.
pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// The command succeeded without a panic.
pub fn succeeds(o: &Output) {
    assert!(o.status.success(), "{}", stderr(o));
    assert!(!stderr(o).contains("panicked"), "{}", stderr(o));
}

/// The command failed, without a panic, with every one of `words` in its message.
pub fn fails_with(o: &Output, words: &[&str]) {
    assert!(!o.status.success(), "should fail: {}", stderr(o));
    let e = stderr(o);
    for w in words {
        assert!(e.contains(w), "missing {w:?} in: {e}");
    }
    assert!(!e.contains("panicked"), "{e}");
}

/// Small RGB tables for the earth preset (3 orders), baked once on the CPU.
pub fn tables() -> &'static Path {
    static T: OnceLock<PathBuf> = OnceLock::new();
    T.get_or_init(|| {
        let p = tmp().join("earth-small.lut");
        let o = bin()
            .args([
                "bake",
                "--backend",
                "cpu",
                "--table-size",
                "small",
                "--wavelengths",
                "rgb",
            ])
            .args(["--orders", "3", "--out"])
            .arg(&p)
            .output()
            .unwrap();
        succeeds(&o);
        p
    })
}

/// [`tables`] as a command-line argument.
pub fn tables_arg() -> &'static str {
    tables().to_str().unwrap()
}

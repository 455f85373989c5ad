//! Dates and places end to end: `firmament astro`'s JSON against the independent cases,
//! `render --time` and its refusals, scene files with `[time]`, and time-lapses that
//! resume.

mod common;

use common::{fails_with, run, stderr, succeeds, tables, tmp_subdir};

fn astro(time: &str, lat: &str, lon: &str) -> serde_json::Value {
    let o = run(&["astro", "--time", time, "--lat-deg", lat, "--lon-deg", lon]);
    succeeds(&o);
    serde_json::from_slice(&o.stdout).unwrap()
}

#[test]
fn astro_prints_the_sun_the_moon_and_the_days_events() {
    // Paris at the June solstice; sunrise and sunset from skyfield/DE421
    // (tests/data/astro/sun_events.csv of the library): 03:46:56.7 and 19:57:51.8 UTC.
    let v = astro("2026-06-21T16:30:00+02:00", "48.8566", "2.3522");
    assert_eq!(v["time_utc"], "2026-06-21T14:30:00Z");
    for key in ["zenith_deg", "apparent_zenith_deg", "azimuth_deg"] {
        assert!(v["sun"][key].is_f64(), "sun.{key}");
    }
    for key in [
        "zenith_deg",
        "altitude_deg",
        "apparent_zenith_deg",
        "azimuth_deg",
        "distance_km",
        "angular_radius_deg",
        "phase_angle_deg",
        "illuminated_fraction",
    ] {
        assert!(v["moon"][key].is_f64(), "moon.{key}");
    }
    let z = v["sun"]["zenith_deg"].as_f64().unwrap();
    let za = v["sun"]["apparent_zenith_deg"].as_f64().unwrap();
    assert!((z - 40.0).abs() < 0.5 && za < z, "{z} {za}");
    let secs = |s: &serde_json::Value| {
        let t: chrono::DateTime<chrono::Utc> = s.as_str().unwrap().parse().unwrap();
        t.timestamp()
    };
    let rise: chrono::DateTime<chrono::Utc> = "2026-06-21T03:46:56Z".parse().unwrap();
    let set: chrono::DateTime<chrono::Utc> = "2026-06-21T19:57:52Z".parse().unwrap();
    assert!((secs(&v["events"]["sunrise"]) - rise.timestamp()).abs() <= 10);
    assert!((secs(&v["events"]["sunset"]) - set.timestamp()).abs() <= 10);
    assert!(
        v["events"]["astronomical_dusk"].is_null(),
        "no astronomical night in Paris in June"
    );
}

#[test]
fn bad_times_and_places_are_refused_with_the_flag_named() {
    let bad = |args: &[&str], words: &[&str]| {
        let mut all = vec!["astro"];
        all.extend_from_slice(args);
        fails_with(&run(&all), words);
    };
    bad(
        &[
            "--time",
            "2026-06-21 16:30",
            "--lat-deg",
            "0",
            "--lon-deg",
            "0",
        ],
        &["--time"],
    );
    bad(
        &[
            "--time",
            "2026-06-21T16:30:00",
            "--lat-deg",
            "0",
            "--lon-deg",
            "0",
        ],
        &["--time", "offset"],
    );
    bad(
        &[
            "--time",
            "2026-06-21T16:30:00Z",
            "--lat-deg",
            "90.5",
            "--lon-deg",
            "0",
        ],
        &["--lat-deg", "90"],
    );
    bad(
        &[
            "--time",
            "2026-06-21T16:30:00Z",
            "--lat-deg",
            "0",
            "--lon-deg",
            "360",
        ],
        &["--lon-deg", "360"],
    );
    bad(
        &[
            "--time",
            "2026-06-21T16:30:00Z",
            "--lat-deg",
            "0",
            "--lon-deg",
            "-181",
        ],
        &["--lon-deg"],
    );
    // 350° east is 10° west.
    let east = astro("2026-06-21T12:00:00Z", "10", "350");
    let west = astro("2026-06-21T12:00:00Z", "10", "-10");
    assert_eq!(east["sun"]["azimuth_deg"], west["sun"]["azimuth_deg"]);
}

#[test]
fn render_takes_a_date_and_refuses_it_with_sun_angles() {
    let dir = tmp_subdir("render-time");
    let t = tables().to_str().unwrap();
    let out = dir.join("both.png");
    let o = run(&[
        "render",
        "--no-clouds",
        "--tables",
        t,
        "--time",
        "2026-06-21T12:00:00Z",
        "--lat-deg",
        "46",
        "--lon-deg",
        "8",
        "--sun-zenith-deg",
        "30",
        "--width",
        "16",
        "--height",
        "9",
        "--out",
        out.to_str().unwrap(),
    ]);
    fails_with(&o, &["--time", "--sun-zenith-deg"]);
    assert!(!out.exists());
    let o = run(&[
        "render",
        "--no-clouds",
        "--tables",
        t,
        "--time",
        "2026-06-21T12:00:00Z",
        "--width",
        "16",
        "--height",
        "9",
        "--out",
        out.to_str().unwrap(),
    ]);
    fails_with(&o, &["--lat-deg", "--lon-deg"]);
    assert!(!out.exists());
    // A night: the moon, the glow and the stars, on the CPU.
    let night = dir.join("night.png");
    let o = run(&[
        "render",
        "--no-clouds",
        "--tables",
        t,
        "--time",
        "2026-01-03T21:00:00+01:00",
        "--lat-deg",
        "46.5",
        "--lon-deg",
        "8",
        "--camera",
        "fisheye",
        "--width",
        "64",
        "--height",
        "64",
        "--backend",
        "cpu",
        "--out",
        night.to_str().unwrap(),
    ]);
    succeeds(&o);
    assert!(night.exists());
    // A scene file with [time] and [location]; with the sun's angles as well it is refused.
    let scene = dir.join("dated.toml");
    let body = "[atmosphere]\n[camera]\nprojection = \"fisheye\"\naltitude_m = 2.0\n[image]\nwidth = 32\nheight = 32\n[location]\nlat_deg = 46.5\nlon_deg = 8.0\n[time]\nat = \"2026-06-21T19:00:00+02:00\"\n[output]\nfiles = [\"dated.png\"]\n";
    std::fs::write(&scene, body).unwrap();
    let o = run(&[
        "render",
        "--no-clouds",
        "--tables",
        t,
        "--scene",
        scene.to_str().unwrap(),
        "--backend",
        "cpu",
        "--out",
        dir.join("dated.png").to_str().unwrap(),
    ]);
    succeeds(&o);
    std::fs::write(
        &scene,
        body.replace("[location]", "[sun]\nzenith_deg = 40.0\n[location]"),
    )
    .unwrap();
    let o = run(&["render", "--tables", t, "--scene", scene.to_str().unwrap()]);
    fails_with(&o, &["sun.zenith_deg", "[time]"]);
    std::fs::write(&scene, body.replace("lat_deg = 46.5", "lat_deg = 95.0")).unwrap();
    let o = run(&["render", "--tables", t, "--scene", scene.to_str().unwrap()]);
    fails_with(&o, &["location.lat_deg"]);
}

#[test]
fn a_time_lapse_renders_resumes_and_follows_the_sun() {
    let dir = tmp_subdir("timelapse");
    let t = tables().to_str().unwrap();
    let pattern = dir.join("frames").join("sky_%04d.png");
    let args = |resume: bool| {
        let mut a = vec![
            "render",
            "--no-clouds",
            "--tables",
            t,
            "--time",
            "2026-06-21T02:30:00Z",
            "--until",
            "2026-06-21T06:20:00Z",
            "--every",
            "10m",
            "--lat-deg",
            "46.5",
            "--lon-deg",
            "8",
            "--camera",
            "perspective",
            "--heading-deg",
            "50",
            "--pitch-deg",
            "10",
            "--width",
            "24",
            "--height",
            "16",
            "--ev100",
            "10",
            "--backend",
            "cpu",
            "--out",
            pattern.to_str().unwrap(),
        ];
        if resume {
            a.push("--resume");
        }
        run(&a)
    };
    let o = args(false);
    succeeds(&o);
    assert!(stderr(&o).contains("24 frames rendered"), "{}", stderr(&o));
    let frames = dir.join("frames");
    let frame = |i: usize| frames.join(format!("sky_{i:04}.png"));
    assert!((0..24).all(|i| frame(i).exists()) && !frame(24).exists());
    // An interrupted run leaves frames 0–9: the resumed one renders only the rest.
    for i in 10..24 {
        std::fs::remove_file(frame(i)).unwrap();
    }
    let o = args(true);
    succeeds(&o);
    assert!(
        stderr(&o).contains("14 frames rendered, 10 skipped"),
        "{}",
        stderr(&o)
    );
    // The sun's track is `astro`'s, and at a fixed exposure the sky brightens through
    // sunrise (03:35 UTC).
    let list: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(frames.join("frames.json")).unwrap())
            .unwrap();
    let list = list.as_array().unwrap();
    assert_eq!(list.len(), 24);
    for i in [0, 7, 23] {
        let at = list[i]["time_utc"].as_str().unwrap();
        let a = astro(at, "46.5", "8");
        let z = list[i]["sun"]["apparent_zenith_deg"].as_f64().unwrap();
        assert!(
            (z - a["sun"]["apparent_zenith_deg"].as_f64().unwrap()).abs() < 1e-9,
            "{at}"
        );
    }
    let brightness = |i: usize| {
        let (_, _, rgb) = firmament::io::read_png_srgb8(frame(i)).unwrap();
        rgb.iter()
            .map(|p| p[0] as f64 + p[1] as f64 + p[2] as f64)
            .sum::<f64>()
    };
    let b: Vec<f64> = [0, 6, 12, 18, 23].iter().map(|&i| brightness(i)).collect();
    assert!(b.windows(2).all(|w| w[1] > w[0]), "{b:?}");
}

#[test]
fn ctrl_c_stops_a_time_lapse_cleanly_and_resume_finishes_it() {
    let dir = tmp_subdir("timelapse-interrupted");
    let t = tables().to_str().unwrap();
    let pattern = dir.join("sky_%03d.png");
    let args = [
        "render",
        "--no-clouds",
        "--tables",
        t,
        "--time",
        "2026-06-21T00:00:00Z",
        "--until",
        "2026-06-21T23:00:00Z",
        "--every",
        "1h",
        "--lat-deg",
        "46.5",
        "--lon-deg",
        "8",
        "--width",
        "240",
        "--height",
        "135",
        "--ev100",
        "10",
        "--backend",
        "cpu",
        "--out",
        pattern.to_str().unwrap(),
    ];
    let frame = |i: usize| dir.join(format!("sky_{i:03}.png"));
    let child = common::bin()
        .args(args)
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    // Interrupt once a few frames are written (SIGINT, as Ctrl-C sends).
    let start = std::time::Instant::now();
    while !frame(2).exists() && start.elapsed().as_secs() < 120 {
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    let killed = std::process::Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(killed.success());
    let o = child.wait_with_output().unwrap();
    let done = (0..24).filter(|&i| frame(i).exists()).count();
    if done < 24 {
        // Stopped: a non-zero exit that says how to go on, and no partial file.
        assert!(!o.status.success());
        assert!(stderr(&o).contains("interrupted"), "{}", stderr(&o));
    }
    let leftovers: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains(".tmp"))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
    let mut resumed = args.to_vec();
    resumed.push("--resume");
    let o = run(&resumed);
    succeeds(&o);
    assert!(
        stderr(&o).contains(&format!("{} frames rendered, {done} skipped", 24 - done)),
        "{}",
        stderr(&o)
    );
    assert!((0..24).all(|i| frame(i).exists()));
}

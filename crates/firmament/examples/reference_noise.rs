//! The reference path tracer's efficiency: relative standard error of luminance per path
//! (σ·√N / mean) and wall time per path, for a few views of the `earth` preset from 0, 1
//! and 10 km with the sun at 30°, −3°, −6° and −12°.
//!
//! ```text
//! RAYON_NUM_THREADS=1 cargo run --release -p firmament --example reference_noise -- \
//!     [--samples N] [--sun DEG,...] [--altitudes KM,...] [--plain] [--bounces N]
//! ```
//!
//! `--plain` traces with `lit_sampling` off (next-event estimation at the collisions only,
//! the estimator before twilight sampling). The cost of reaching a relative error ε is
//! N·t = (noise per path / ε)² · time per path; the last column gives it for ε = 1 %, in
//! seconds per wavelength. Time is the process's CPU time (wall time for runs under 0.2 s):
//! run it with one thread for a per-path figure.

use std::time::Instant;

use firmament::atmosphere::Atmosphere;
use firmament::math::{direction_from_zenith_azimuth, Vec3};
use firmament::reference::{self, ReferenceSettings};
use firmament::spectrum::{ColourMatrix, Wavelengths};

fn dir(elevation_deg: f64, azimuth_deg: f64) -> Vec3 {
    direction_from_zenith_azimuth(
        (90.0 - elevation_deg).to_radians(),
        azimuth_deg.to_radians(),
    )
}

/// CPU time of the process (all threads), from /proc/self/stat (clock ticks of 10 ms).
fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let after = stat.rsplit(')').next().unwrap_or("");
    let f: Vec<&str> = after.split_whitespace().collect();
    let ticks = |i: usize| f.get(i).and_then(|v| v.parse::<f64>().ok()).unwrap_or(0.0);
    // Fields 14 and 15 of stat (utime, stime) are 12 and 13 after the name.
    (ticks(11) + ticks(12)) / 100.0
}

fn list(s: &str) -> Vec<f64> {
    s.split(',')
        .map(|v| v.trim().parse().expect("a number"))
        .collect()
}

fn main() -> firmament::Result<()> {
    let mut samples = 4096;
    let mut suns = vec![30.0, -3.0, -6.0, -12.0];
    let mut altitudes_km = vec![0.0, 1.0, 10.0];
    let mut plain = false;
    let mut bounces = None;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--samples" => samples = args.next().expect("N").parse().expect("an integer"),
            "--sun" => suns = list(&args.next().expect("DEG,...")),
            "--altitudes" => altitudes_km = list(&args.next().expect("KM,...")),
            "--plain" => plain = true,
            "--bounces" => bounces = Some(args.next().expect("N").parse().expect("an integer")),
            other => panic!("unknown argument {other}"),
        }
    }
    let model = Atmosphere::preset("earth")?.resolve(&Wavelengths::rgb())?;
    let colour = ColourMatrix::new(model.wavelengths.nm());
    let channels = model.channels() as f64;
    // (elevation, azimuth from the sun) of the views; below the horizon from above 0 km.
    let views: [(f64, f64); 6] = [
        (90.0, 0.0),
        (10.0, 0.0),
        (2.0, 0.0),
        (10.0, 180.0),
        (30.0, 90.0),
        (-10.0, 0.0),
    ];
    let mut settings = ReferenceSettings::with_samples(samples);
    if plain {
        settings.lit_sampling = false;
    }
    if let Some(b) = bounces {
        settings.max_bounces = b;
    }
    println!(
        "estimator: {}, {samples} paths per wavelength, {} wavelengths",
        if plain { "plain" } else { "lit sampling" },
        model.channels()
    );
    println!("sun°  alt km  view (el°, az°)   Y cd/m²      noise/path  µs/path  s for 1 %");
    for &sun_deg in &suns {
        let sun = dir(sun_deg, 0.0);
        for &alt in &altitudes_km {
            let camera = Vec3::new(0.0, 0.0, model.bottom_radius_m + alt * 1e3);
            let (mut log_noise, mut log_cost, mut n) = (0.0, 0.0, 0.0);
            for &(el, az) in &views {
                if el < 0.0 && alt <= 0.0 {
                    continue;
                }
                let (t0, c0) = (Instant::now(), cpu_seconds());
                let e = reference::sky_radiance(&model, camera, dir(el, az), sun, &settings);
                let cpu = cpu_seconds() - c0;
                let wall = t0.elapsed().as_secs_f64();
                // CPU time when the ticks resolve it (other jobs on the machine inflate wall time).
                let per_path = if cpu > 0.2 { cpu } else { wall } / (samples as f64 * channels);
                let (y, se) = colour.luminance_and_stderr(&e.radiance, &e.stderr);
                let noise = se / y * (samples as f64).sqrt();
                let cost = (noise / 0.01).powi(2) * per_path;
                println!(
                    "{sun_deg:>4}  {alt:>6}  ({el:>5}, {az:>5})     {y:<11.4e}  {noise:>9.3}  {:>7.2}  {cost:>9.3}",
                    per_path * 1e6
                );
                log_noise += noise.ln();
                log_cost += cost.ln();
                n += 1.0;
            }
            println!(
                "{sun_deg:>4}  {alt:>6}  geometric mean                   {:>9.3}           {:>9.3}",
                (log_noise / n).exp(),
                (log_cost / n).exp()
            );
        }
    }
    Ok(())
}

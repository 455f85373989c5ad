//! Amortised table updates (Hillaire 2016 §2 "Our approach"): a day on `earth` whose haze
//! thickens (Ångström turbidity β 0.04 → 0.12) while the sun climbs, the 4D tables' update
//! spread over N frames by `AmortisedTables`. Prints each frame's time in the update and the
//! sky it shows, the per-frame median and maximum next to the direct precomputation's time,
//! and checks that the tables swapped in equal the direct ones bit for bit.
//!
//! ```text
//! cargo run --release -p firmament --example amortised_frames -- [--frames N] [--spectral] [--small] [--units REPEATS]
//! ```
//!
//! `--units` times every unit of a direct job instead and prints, per pass, the time
//! measured against the plan's estimate (the cost model of `precompute::plan`, calibrated
//! from this table with `RAYON_NUM_THREADS=1`).

use std::time::Instant;

use firmament::atmosphere::Atmosphere;
use firmament::math::{direction_from_zenith_azimuth, Vec3};
use firmament::medium::{Coefficient, ConstituentKind};
use firmament::scene::{sun_direction, Light};
use firmament::sky::bruneton4d::precompute::{Pass, PrecomputeJob};
use firmament::sky::bruneton4d::{AmortisedTables, TableConfig, TableSizes, Tables};
use firmament::sky::{Shadow, SkyMethod};
use firmament::spectrum::{luminance_from_spectrum, Wavelengths};

/// `earth` with its aerosols' Ångström turbidity set to `beta`.
fn earth_with_turbidity(beta: f64) -> Atmosphere {
    let mut a = Atmosphere::earth();
    for c in &mut a.constituents {
        if c.kind == ConstituentKind::Aerosols {
            for coefficient in [&mut c.scattering, &mut c.absorption] {
                if let Coefficient::Angstrom { beta: b, .. } = coefficient {
                    *b = beta;
                }
            }
        }
    }
    a
}

fn same_tables(a: &Tables, b: &Tables) -> bool {
    a.optical_depth == b.optical_depth
        && a.transmittance == b.transmittance
        && a.irradiance == b.irradiance
        && a.single_rayleigh == b.single_rayleigh
        && a.single_mie == b.single_mie
        && a.multiple == b.multiple
        && a.order_means == b.order_means
}

fn median(v: &[f64]) -> f64 {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    s[s.len() / 2]
}

/// Per pass: units, the time measured (the least of `repeats` runs, as other work on the
/// machine only adds to it) and the estimated weight.
fn time_units(model: firmament::atmosphere::Model, config: &TableConfig, repeats: usize) {
    let mut rows: Vec<(String, usize, f64, f64)> = Vec::new();
    let (mut total, mut count) = (0.0, 0);
    for repeat in 0..repeats {
        let mut job = PrecomputeJob::new(model.clone(), config).expect("valid model");
        (total, count) = (job.total_weight(), job.units().len());
        let mut times: Vec<(String, usize, f64, f64)> = Vec::new();
        while let Some(unit) = job.next_unit().cloned() {
            let t0 = Instant::now();
            job.run_unit();
            let dt = t0.elapsed().as_secs_f64();
            let name = match unit.pass {
                Pass::ScatteringDensity { order } if order > 2 => {
                    "scattering density, order ≥ 3".into()
                }
                Pass::IndirectIrradiance { order } if order > 1 => {
                    "indirect irradiance, order ≥ 2".into()
                }
                Pass::MultipleScattering { .. } => "multiple scattering".into(),
                p => p.label(),
            };
            match times.iter_mut().find(|r| r.0 == name) {
                Some(r) => (r.1, r.2, r.3) = (r.1 + 1, r.2 + dt, r.3 + unit.weight),
                None => times.push((name, 1, dt, unit.weight)),
            }
        }
        if repeat == 0 {
            rows = times;
        } else {
            for (r, t) in rows.iter_mut().zip(times) {
                r.2 = r.2.min(t.2);
            }
        }
    }
    let measured: f64 = rows.iter().map(|r| r.2).sum();
    println!(
        "{} channels, {count} units, {measured:.2} s (least of {repeats} runs per pass)",
        model.channels()
    );
    println!("pass                             units  measured s  share  estimated share");
    for (name, count, dt, w) in &rows {
        println!(
            "{name:<32} {count:5} {dt:10.3}  {:5.1} %  {:5.1} %",
            100.0 * dt / measured,
            100.0 * w / total,
        );
    }
}

fn main() -> firmament::Result<()> {
    let mut frames = 30;
    let (mut spectral, mut small, mut units) = (false, false, None);
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--frames" => {
                frames = args
                    .next()
                    .and_then(|v| v.parse().ok())
                    .expect("--frames N")
            }
            "--spectral" => spectral = true,
            "--small" => small = true,
            "--units" => {
                units = Some(
                    args.next()
                        .and_then(|v| v.parse().ok())
                        .expect("--units REPEATS"),
                )
            }
            other => panic!("unknown argument {other}"),
        }
    }
    let wavelengths = if spectral {
        Wavelengths::spectral()
    } else {
        Wavelengths::rgb()
    };
    let config = TableConfig {
        sizes: if small {
            TableSizes::small()
        } else {
            TableSizes::default()
        },
        ..TableConfig::default()
    };
    let clear = earth_with_turbidity(0.04).resolve(&wavelengths)?;
    let hazy = earth_with_turbidity(0.12).resolve(&wavelengths)?;
    if let Some(repeats) = units {
        time_units(hazy, &config, repeats);
        return Ok(());
    }

    // The direct precomputation of the new atmosphere: the reference, and the cost one
    // frame would pay without amortisation.
    let t0 = Instant::now();
    let direct = Tables::compute(&hazy, &config)?;
    let direct_s = t0.elapsed().as_secs_f64();

    let mut sky = AmortisedTables::compute(clear.clone(), &config, frames)?;
    let nm = clear.wavelengths.nm().to_vec();
    let observer = Vec3::new(0.0, 0.0, clear.bottom_radius_m + 100.0);
    let n = nm.len();
    let (mut radiance, mut transmittance) = (vec![0.0; n], vec![0.0; n]);
    let toward_sun_30 = direction_from_zenith_azimuth(60f64.to_radians(), 180f64.to_radians());
    sky.request(hazy.clone())?;
    println!("update over {frames} frames; direct precomputation {direct_s:.3} s");
    println!("frame  sun zenith°  update ms  units  done   set  sky 30° up towards the sun cd/m²");
    let mut update_s = Vec::new();
    let after = 3;
    for frame in 0..frames + after {
        // The time of day: the sun climbs from 80° to 40° from the zenith (the tables do
        // not depend on it, the view does).
        let sun_zenith = 80.0 - 40.0 * frame as f64 / (frames + after) as f64;
        let t = Instant::now();
        let report = sky.frame();
        let dt = t.elapsed().as_secs_f64();
        if frame < frames {
            update_s.push(dt);
        }
        let light = Light::sun(sky.model(), sun_direction(sun_zenith, 180.0), true);
        sky.view(observer, &light).sky_radiance(
            toward_sun_30,
            Shadow::None,
            &mut radiance,
            &mut transmittance,
        );
        let done = report.running.map_or(1.0, |p| p.fraction);
        println!(
            "{frame:5} {sun_zenith:11.1} {:10.1} {:6} {:5.1}% {:>5} {:10.0}{}",
            dt * 1e3,
            report.units,
            100.0 * done,
            if report.atmosphere_hash == hazy.hash {
                "new"
            } else {
                "old"
            },
            luminance_from_spectrum(&nm, &radiance),
            if report.swapped { "  <- swapped" } else { "" }
        );
    }
    let (med, max) = (
        median(&update_s),
        update_s.iter().copied().fold(0.0, f64::max),
    );
    let sum: f64 = update_s.iter().sum();
    println!(
        "per frame: median {:.1} ms, max {:.1} ms ({:.1} % of the direct {:.0} ms; 1/N = {:.1} %)",
        med * 1e3,
        max * 1e3,
        100.0 * max / direct_s,
        direct_s * 1e3,
        100.0 / frames as f64,
    );
    // Against the frames' own sum, which other work on the machine slows as it slows them.
    println!(
        "all frames {:.0} ms; the largest frame is {:.2}x their mean",
        sum * 1e3,
        max * frames as f64 / sum
    );
    let equal = same_tables(&sky.front().tables, &direct);
    println!(
        "tables after the swap {} the direct precomputation's",
        if equal {
            "equal (bit for bit)"
        } else {
            "DIFFER from"
        }
    );
    assert!(equal);
    Ok(())
}

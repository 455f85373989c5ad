//! `firmament bench`: medians of the main costs, printed as text or one JSON object.

use std::time::Instant;

use anyhow::Result;
use clap::Args;
use serde_json::json;

use crate::common::AtmosphereArgs;

/// Arguments of `firmament bench`.
#[derive(Args, Debug)]
pub struct BenchArgs {
    #[command(flatten)]
    pub atmosphere: AtmosphereArgs,
    /// Repetitions per measurement (the median is reported).
    #[arg(long, default_value_t = 5)]
    pub runs: usize,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
    /// Also time the spectral (16-wavelength) precomputation.
    #[arg(long)]
    pub spectral: bool,
}

/// Median of a sample (seconds).
pub fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

fn time_runs(runs: usize, mut f: impl FnMut() -> Result<()>) -> Result<Vec<f64>> {
    let mut times = Vec::with_capacity(runs);
    for _ in 0..runs.max(1) {
        let t = Instant::now();
        f()?;
        times.push(t.elapsed().as_secs_f64());
    }
    Ok(times)
}

/// Run the benchmarks.
pub fn run(args: &BenchArgs) -> Result<()> {
    let model = args.atmosphere.model()?;
    let config = args.atmosphere.table_config()?;
    let cpu = cpu_name();
    let threads = rayon::current_num_threads();
    if !args.json {
        eprintln!(
            "machine: {cpu}, {threads} threads; {} runs per measurement",
            args.runs
        );
    }
    let mut stages: Vec<(String, f64)> = Vec::new();
    let precompute = time_runs(args.runs, || {
        let _ = firmament::lut::precompute::precompute(&model, &config, &|_, _| {}, None)?;
        Ok(())
    })?;
    // Where the time goes: one more run with stage timestamps.
    {
        let last = std::sync::Mutex::new((Instant::now(), String::from("start")));
        let acc = std::sync::Mutex::new(Vec::<(String, f64)>::new());
        firmament::lut::precompute::precompute(
            &model,
            &config,
            &|stage, _| {
                let mut l = last.lock().unwrap();
                let kind = stage.split(',').next().unwrap_or(stage).to_string();
                let dt = l.0.elapsed().as_secs_f64();
                let prev = std::mem::replace(&mut l.1, kind);
                acc.lock().unwrap().push((prev, dt));
                l.0 = Instant::now();
            },
            None,
        )?;
        for (name, dt) in acc.into_inner().unwrap().into_iter().skip(1) {
            match stages.iter_mut().find(|(n, _)| *n == name) {
                Some(e) => e.1 += dt,
                None => stages.push((name, dt)),
            }
        }
    }
    let mut result = json!({
        "machine": { "cpu": cpu, "threads": threads },
        "runs": args.runs,
        "cpu_precompute_s": median(precompute.clone()),
        "cpu_precompute_wavelengths": model.channels(),
        "cpu_precompute_orders": config.orders,
        "cpu_precompute_stages_s": stages.iter().map(|(n, t)| (n.clone(), json!(t))).collect::<serde_json::Map<_, _>>(),
    });
    if args.spectral {
        let mut spectral_args = args.atmosphere.clone();
        spectral_args.wavelengths = "spectral".into();
        let spectral_model = spectral_args.model()?;
        let times = time_runs(args.runs.min(3), || {
            let _ =
                firmament::lut::precompute::precompute(&spectral_model, &config, &|_, _| {}, None)?;
            Ok(())
        })?;
        result["cpu_precompute_spectral_s"] = json!(median(times));
        result["cpu_precompute_spectral_wavelengths"] = json!(spectral_model.channels());
    }
    crate::render_bench::extend(&mut result, args)?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&result)?);
    } else {
        for (k, v) in result.as_object().unwrap() {
            println!("{k}: {v}");
        }
    }
    Ok(())
}

/// The CPU model name from /proc/cpuinfo (Linux), or "unknown".
pub fn cpu_name() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .map(|l| l.split(':').nth(1).unwrap_or("").trim().to_string())
        })
        .unwrap_or_else(|| "unknown".into())
}

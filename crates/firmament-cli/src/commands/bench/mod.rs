//! `firmament bench`: medians of the main costs, printed as text or one JSON object.

mod cpu;
mod gpu;

use std::time::Instant;

use anyhow::Result;
use clap::{Args, ValueEnum};
use serde_json::json;

use crate::backend::{describe, open_gpu, probe_hardware, Probe};
use crate::common::AtmosphereArgs;
use cpu as render_bench;
use gpu as gpu_bench;

/// What `firmament bench` measures.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum BenchBackend {
    /// The CPU, and the GPU when wgpu finds a hardware adapter (software rasterisers are
    /// skipped: see `all`).
    Auto,
    /// The CPU and the GPU on whatever adapter wgpu finds, software rasterisers included.
    All,
    /// The CPU only.
    Cpu,
    /// The GPU only (any adapter).
    Gpu,
}

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
    /// Which backends to measure. GPU: the precompute (same sizes, wavelengths and orders as
    /// the CPU's) and the CPU's 1080p frame, on the adapter wgpu opens. A software
    /// rasteriser (Mesa lavapipe) is measured only with `all` or `gpu`: on the 2-core
    /// machine of BENCHMARKS.md one default-size precompute on lavapipe takes about two
    /// minutes (the CPU path: seconds), so use `--gpu-runs 1` (and `--table-size small` for
    /// a quick look).
    #[arg(long, value_enum, value_name = "auto|all|cpu|gpu", default_value_t = BenchBackend::Auto)]
    pub backend: BenchBackend,
    /// Repetitions per GPU measurement (default: --runs).
    #[arg(long, value_name = "N")]
    pub gpu_runs: Option<usize>,
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

/// Run `f` `runs` times (at least once); the seconds of each.
pub fn time_runs(runs: usize, mut f: impl FnMut() -> Result<()>) -> Result<Vec<f64>> {
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
    // The GPU to measure, or why none.
    let (gpu, gpu_skipped) = match args.backend {
        BenchBackend::Cpu => (None, Some("not requested (--backend cpu)".to_string())),
        BenchBackend::Gpu | BenchBackend::All => (Some(open_gpu()?), None),
        BenchBackend::Auto => match probe_hardware() {
            Probe::Hardware(ctx) => (Some(*ctx), None),
            Probe::NoHardware(why) => (
                None,
                Some(format!("{why} (--backend all measures a software adapter)")),
            ),
        },
    };
    let measure_cpu = args.backend != BenchBackend::Gpu;
    if !args.json {
        eprintln!(
            "machine: {cpu}, {threads} threads; {} runs per measurement",
            args.runs
        );
        match (&gpu, &gpu_skipped) {
            (Some(ctx), _) => eprintln!("backend: gpu ({})", describe(ctx)),
            (None, Some(why)) => eprintln!("backend: gpu not measured: {why}"),
            (None, None) => {}
        }
        if !measure_cpu {
            eprintln!("backend: cpu not measured (--backend gpu)");
        }
    }
    let mut result = json!({
        "machine": { "cpu": cpu, "threads": threads },
        "runs": args.runs,
        "cpu_precompute_s": null,
        "cpu_precompute_wavelengths": null,
        "cpu_precompute_orders": null,
        "cpu_precompute_stages_s": null,
        "cpu_precompute_spectral_s": null,
        "cpu_precompute_spectral_wavelengths": null,
        "gpu_skipped": gpu_skipped,
    });
    for key in render_bench::KEYS.iter().chain(&gpu_bench::KEYS) {
        result[*key] = serde_json::Value::Null;
    }
    if measure_cpu {
        cpu_precompute(&mut result, args, &model, &config)?;
        render_bench::extend(&mut result, args)?;
    }
    if let Some(ctx) = &gpu {
        gpu_bench::extend(&mut result, args, ctx, !args.json)?;
    }
    if args.json {
        println!("{}", serde_json::to_string_pretty(&result)?);
    } else {
        for (k, v) in result.as_object().unwrap() {
            println!("{k}: {v}");
        }
    }
    Ok(())
}

/// The CPU precompute: median, stages, spectral.
fn cpu_precompute(
    result: &mut serde_json::Value,
    args: &BenchArgs,
    model: &firmament::atmosphere::Model,
    config: &firmament::sky::bruneton4d::TableConfig,
) -> Result<()> {
    let mut stages: Vec<(String, f64)> = Vec::new();
    let precompute = time_runs(args.runs, || {
        let _ =
            firmament::sky::bruneton4d::precompute::precompute(model, config, &|_, _| {}, None)?;
        Ok(())
    })?;
    // Where the time goes: one more run with stage timestamps.
    {
        let last = std::sync::Mutex::new((Instant::now(), String::from("start")));
        let acc = std::sync::Mutex::new(Vec::<(String, f64)>::new());
        firmament::sky::bruneton4d::precompute::precompute(
            model,
            config,
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
    result["cpu_precompute_s"] = json!(median(precompute));
    result["cpu_precompute_wavelengths"] = json!(model.channels());
    result["cpu_precompute_orders"] = json!(config.orders);
    result["cpu_precompute_stages_s"] = stages
        .iter()
        .map(|(n, t)| (n.clone(), json!(t)))
        .collect::<serde_json::Map<_, _>>()
        .into();
    if args.spectral {
        let mut spectral_args = args.atmosphere.clone();
        spectral_args.wavelengths = "spectral".into();
        let spectral_model = spectral_args.model()?;
        let times = time_runs(args.runs.min(3), || {
            let _ = firmament::sky::bruneton4d::precompute::precompute(
                &spectral_model,
                config,
                &|_, _| {},
                None,
            )?;
            Ok(())
        })?;
        result["cpu_precompute_spectral_s"] = json!(median(times));
        result["cpu_precompute_spectral_wavelengths"] = json!(spectral_model.channels());
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

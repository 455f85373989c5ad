//! `firmament bench`: medians of the main costs, printed as text or one JSON object.
//!
//! Imports run one way: the leaves [`timing`] (runs and medians), [`scenes`] (the frames
//! measured) and [`report`] (what is printed) import nothing of bench; [`cpu`] and [`gpu`]
//! measure with them and take plain values, not the arguments; this module chooses what to
//! measure and prints the report.

mod clouds;
mod cpu;
mod gpu;
mod gpu_methods;
mod methods;
mod report;
mod scenes;
mod timing;

use anyhow::Result;
use clap::{Args, ValueEnum};

use crate::backend::{Gpu, Probe};
use crate::common::AtmosphereArgs;
use crate::method::Method;
use report::{BenchReport, Machine};

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

/// Arguments of `firmament bench` (without --wavelengths: RGB, the wavelengths of the
/// performance goals).
#[derive(Args, Debug, Clone)]
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
    /// Sky methods whose costs are measured, comma-separated (bruneton4d, hillaire2020,
    /// elek3d); the 4D tables' figures are always there (the others are compared with them).
    #[arg(
        long,
        default_value = "bruneton4d,hillaire2020,elek3d",
        value_name = "METHOD,..."
    )]
    pub method: String,
    /// Repetitions per GPU measurement (default: --runs).
    #[arg(long, value_name = "N")]
    pub gpu_runs: Option<usize>,
    /// Also time the cloudy 1080p frame (`scenes/clouds-cumulus-noon.toml`): about 30 s a
    /// run on two cores, at most 3 runs on the CPU.
    #[arg(long)]
    pub clouds: bool,
}

/// Run the benchmarks.
pub fn run(args: &BenchArgs) -> Result<()> {
    // The performance goals are RGB's (SPEC §7): without --wavelengths, bench measures RGB,
    // not the rendering default.
    let atmosphere = AtmosphereArgs {
        wavelengths: Some(args.atmosphere.wavelengths.clone().unwrap_or("rgb".into())),
        ..args.atmosphere.clone()
    };
    let args = &BenchArgs {
        atmosphere,
        ..args.clone()
    };
    let mut wanted = Vec::new();
    for m in args.method.split(',') {
        match Method::from_str(m.trim(), true) {
            Ok(Method::Reference) | Err(_) => anyhow::bail!(
                "invalid value for `--method`: {m:?} (accepted: bruneton4d (or lut), hillaire2020, elek3d, separated by commas)"
            ),
            Ok(m) => wanted.push(m),
        }
    }
    let model = args.atmosphere.model()?;
    let config = args.atmosphere.table_config()?;
    let spectral_model = if args.spectral {
        let mut spectral_args = args.atmosphere.clone();
        spectral_args.wavelengths = Some("spectral".into());
        Some(spectral_args.model()?)
    } else {
        None
    };
    let machine = Machine::this();
    // The GPU to measure, or why none.
    let (gpu, gpu_skipped) = match args.backend {
        BenchBackend::Cpu => (None, Some("not requested (--backend cpu)".to_string())),
        BenchBackend::Gpu | BenchBackend::All => (Some(Gpu::open()?), None),
        BenchBackend::Auto => match Gpu::probe_hardware() {
            Probe::Hardware(gpu) => (Some(*gpu), None),
            Probe::NoHardware(why) => (
                None,
                Some(format!("{why} (--backend all measures a software adapter)")),
            ),
        },
    };
    let measure_cpu = args.backend != BenchBackend::Gpu;
    if !args.json {
        eprintln!(
            "machine: {}, {} threads; {} runs per measurement",
            machine.cpu, machine.threads, args.runs
        );
        match (&gpu, &gpu_skipped) {
            (Some(gpu), _) => eprintln!("backend: gpu ({})", gpu.describe()),
            (None, Some(why)) => eprintln!("backend: gpu not measured: {why}"),
            (None, None) => {}
        }
        if !measure_cpu {
            eprintln!("backend: cpu not measured (--backend gpu)");
        }
    }
    let mut report = BenchReport {
        machine,
        runs: args.runs,
        cpu_precompute: Default::default(),
        cpu_frames: Default::default(),
        cpu_reference: Default::default(),
        cpu_methods: Default::default(),
        gpu_skipped,
        gpu: Default::default(),
        gpu_methods: Default::default(),
    };
    if measure_cpu {
        report.cpu_precompute =
            cpu::precompute_timings(&model, &config, args.runs, spectral_model.as_ref())?;
        let tables = args.atmosphere.sky(true)?;
        report.cpu_frames = cpu::frame_timings(&tables, args.runs)?;
        if args.clouds {
            if !args.json {
                eprintln!("cpu: the 1080p cloudy frame");
            }
            let frame = clouds::CloudFrame::new(&tables)?;
            report.cpu_frames.cpu_frame_1080p_clouds_s =
                Some(clouds::cpu_seconds(&tables, &frame, args.runs)?);
        }
        report.cpu_reference = cpu::reference_timings(&model, args.runs)?;
        if wanted.contains(&Method::Hillaire2020) {
            methods::hillaire_timings(&model, &tables, args.runs, &mut report.cpu_methods)?;
        }
        if wanted.contains(&Method::Elek3d) {
            methods::elek3d_timings(&model, args.runs, &mut report.cpu_methods)?;
        }
    }
    if let Some(gpu) = &gpu {
        let runs = args.gpu_runs.unwrap_or(args.runs).max(1);
        report.gpu = gpu::timings(
            gpu,
            &model,
            &config,
            spectral_model.as_ref(),
            runs,
            args.clouds,
            !args.json,
        )?;
        if wanted.contains(&Method::Hillaire2020) {
            if !args.json {
                eprintln!("gpu: hillaire2020's passes and 1080p frame");
            }
            gpu_methods::hillaire_timings(gpu, &model, runs, &mut report.gpu_methods)?;
        }
        if wanted.contains(&Method::Elek3d) {
            if !args.json {
                eprintln!("gpu: elek3d's 1080p frame");
            }
            gpu_methods::elek3d_timings(gpu, &model, runs, &mut report.gpu_methods)?;
        }
    }
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report.to_json())?);
    } else {
        for line in report.lines() {
            println!("{line}");
        }
    }
    Ok(())
}

//! `firmament`: physically based sky and atmosphere rendering from the command line.

mod backend;
mod bench;
mod common;
mod gallery;
mod gpu_bench;
mod query;
mod render;
mod render_bench;
mod validate;

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Result;
use clap::{Parser, Subcommand};
use firmament::atmosphere::{presets, Atmosphere};

use common::AtmosphereArgs;

#[derive(Parser, Debug)]
#[command(
    name = "firmament",
    version,
    about = "Physically based sky, atmosphere and cloud renderer"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Radiometric answers as JSON: radiance, luminance, transmittance, optical depths, irradiance.
    Query(query::QueryArgs),
    /// Print or check atmosphere definitions.
    Atmosphere {
        #[command(subcommand)]
        action: AtmosphereAction,
    },
    /// Precompute the tables and write them to a file for `--tables`.
    Bake {
        #[command(flatten)]
        atmosphere: AtmosphereArgs,
        /// Output table file.
        #[arg(long, value_name = "FILE")]
        out: PathBuf,
        /// Where the tables are computed: `cpu`, `gpu` (wgpu, any adapter; read back and
        /// written in the same format) or `auto` (a hardware GPU when wgpu finds one, else
        /// the CPU; never a software rasteriser such as lavapipe).
        #[arg(long, value_enum, value_name = "cpu|gpu|auto", default_value_t = backend::BackendChoice::Auto)]
        backend: backend::BackendChoice,
    },
    /// Render a picture of the sky (with no arguments: a default scene to firmament.png and firmament.exr).
    Render(render::RenderArgs),
    /// The canonical views as PNGs with an index.html contact sheet.
    Gallery(gallery::GalleryArgs),
    /// Benchmarks: medians of the precomputation and frame costs.
    Bench(bench::BenchArgs),
    /// Measure the table method against the Monte Carlo reference (errors per configuration; see docs/accuracy.md).
    Validate(validate::ValidateArgs),
}

#[derive(Subcommand, Debug)]
enum AtmosphereAction {
    /// Print a preset as a complete, commented TOML file.
    Show {
        /// Preset name.
        name: String,
    },
    /// List the presets.
    List,
    /// Check an atmosphere file and print it back, complete.
    Check {
        /// TOML file.
        file: PathBuf,
    },
}

fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Query(args) => {
            let value = query::run(&args)?;
            println!("{}", serde_json::to_string_pretty(&value)?);
        }
        Command::Atmosphere { action } => match action {
            AtmosphereAction::Show { name } => print!("{}", presets::toml_text(&name)?),
            AtmosphereAction::List => {
                for name in presets::NAMES {
                    let a = Atmosphere::preset(name)?;
                    println!("{name:14} {}", a.description);
                }
            }
            AtmosphereAction::Check { file } => {
                let a = Atmosphere::from_file(&file)?;
                print!("{}", a.to_toml());
            }
        },
        Command::Bake {
            atmosphere,
            out,
            backend,
        } => {
            common::check_output_dir(&out, "--out")?;
            if atmosphere.tables.is_some() {
                anyhow::bail!("`bake` computes tables: --tables makes no sense here");
            }
            let model = atmosphere.model()?;
            let config = atmosphere.table_config()?;
            let tables = match backend::Backend::open(backend, false)? {
                backend::Backend::Cpu => common::compute_tables(&model, &config, false)?,
                backend::Backend::Gpu(gpu) => gpu.tables(&model, &config, false)?,
            };
            firmament::sky::bruneton4d::file::write(&tables, &out)?;
            eprintln!("wrote {}", out.display());
        }
        Command::Bench(args) => bench::run(&args)?,
        Command::Render(args) => render::run(&args)?,
        Command::Gallery(args) => gallery::run(&args)?,
        Command::Validate(args) => validate::run(&args)?,
    }
    Ok(())
}

/// Mesa's Vulkan device-select layer connects to Wayland to find the desktop's GPU and, on
/// a headless machine (no XDG_RUNTIME_DIR), prints `error: XDG_RUNTIME_DIR is invalid…`
/// every time the GPU is probed, which `--backend auto` does. firmament ranks the adapters
/// itself, so the layer is switched off there unless the user configured it.
fn quiet_headless_vulkan() {
    let set = |k: &str| std::env::var_os(k).is_some();
    if !set("XDG_RUNTIME_DIR")
        && !set("NODEVICE_SELECT")
        && !set("MESA_VK_DEVICE_SELECT")
        && !set("DRI_PRIME")
    {
        // Before any thread is started.
        std::env::set_var("NODEVICE_SELECT", "1");
    }
}

fn main() -> ExitCode {
    quiet_headless_vulkan();
    let cli = Cli::parse();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

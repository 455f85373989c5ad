//! `firmament`: physically based sky and atmosphere rendering from the command line.
//!
//! A thin layer over the `firmament` library: each subcommand ([`commands`]) turns flags
//! into library calls and prints or writes what they return; [`common`] and [`backend`]
//! hold what several subcommands share.

mod backend;
mod commands;
mod common;
mod method;

use std::process::ExitCode;

use anyhow::Result;
use clap::{Parser, Subcommand};

use commands::{
    astro, atmosphere, bake, bench, gallery, query, render, render_args, validate, view,
};

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
    Query(Box<query::QueryArgs>),
    /// Where the sun and the moon are for a date and a place, and the day's sunrise, sunset and twilights, as JSON.
    Astro(astro::AstroCommandArgs),
    /// Print or check atmosphere definitions.
    Atmosphere {
        #[command(subcommand)]
        action: atmosphere::AtmosphereAction,
    },
    /// Precompute the tables and write them to a file for `--tables`.
    Bake(bake::BakeArgs),
    /// Render a picture of the sky (with no arguments: a default scene to firmament.png and firmament.exr).
    Render(Box<render_args::RenderArgs>),
    /// The canonical views as PNGs with an index.html contact sheet.
    Gallery(gallery::GalleryArgs),
    /// Benchmarks: medians of the precomputation and frame costs.
    Bench(bench::BenchArgs),
    /// Measure the table method against the Monte Carlo reference (errors per configuration; see docs/accuracy.md).
    Validate(validate::ValidateArgs),
    /// A window drawing the scene live on the GPU: fly the camera, move the sun or the clock, switch the method, change the air and the exposure, capture PNG/EXR and save the scene.
    View(Box<view::ViewArgs>),
}

fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Query(args) => {
            let value = query::run(&args)?;
            println!("{}", serde_json::to_string_pretty(&value)?);
        }
        Command::Astro(args) => {
            let value = astro::run(&args)?;
            println!("{}", serde_json::to_string_pretty(&value)?);
        }
        Command::Atmosphere { action } => atmosphere::run(&action)?,
        Command::Bake(args) => bake::run(&args)?,
        Command::Bench(args) => bench::run(&args)?,
        Command::Render(args) => render::run(&args)?,
        Command::Gallery(args) => gallery::run(&args)?,
        Command::Validate(args) => validate::run(&args)?,
        Command::View(args) => view::run(&args)?,
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

//! `firmament bake`: precompute the tables and write them to a file for `--tables`.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use firmament::sky::bruneton4d::file::{self, Encoding};

use crate::backend::{Backend, BackendChoice};
use crate::common::{check_output_dir, compute_tables, AtmosphereArgs};

/// Arguments of `firmament bake` (the shared atmosphere flags without `--tables`, which
/// `bake` computes rather than reads, and `--no-cache`, since it never uses the cache:
/// hidden from its help, refused if given).
#[derive(Args, Debug)]
#[command(mut_arg("tables", |a| a.hide(true)), mut_arg("no_cache", |a| a.hide(true)))]
pub struct BakeArgs {
    #[command(flatten)]
    pub atmosphere: AtmosphereArgs,
    /// Output table file.
    #[arg(long, value_name = "FILE")]
    pub out: PathBuf,
    /// Where the tables are computed: `cpu`, `gpu` (wgpu, any adapter; read back and
    /// written in the same format) or `auto` (a hardware GPU when wgpu finds one, else
    /// the CPU; never a software rasteriser such as lavapipe).
    #[arg(long, value_enum, value_name = "cpu|gpu|auto", default_value_t = BackendChoice::Auto)]
    pub backend: BackendChoice,
    /// Store the 4D scattering tables as half floats with a power-of-two scale per texel:
    /// half the size (131 MB in place of 253 MB for spectral tables at the default sizes),
    /// each value within 4.9·10⁻⁴ of its f32 (the radiance errors: docs/accuracy.md).
    #[arg(long)]
    pub compact: bool,
}

/// Run `firmament bake`.
pub fn run(args: &BakeArgs) -> Result<()> {
    check_output_dir(&args.out, "--out")?;
    if args.atmosphere.tables.is_some() {
        anyhow::bail!("`bake` computes tables: --tables makes no sense here");
    }
    if args.atmosphere.no_cache {
        anyhow::bail!("`bake` always computes its tables and never uses the table cache: --no-cache makes no sense here");
    }
    let model = args.atmosphere.model()?;
    let config = args.atmosphere.table_config()?;
    let tables = match Backend::open(args.backend, false)? {
        Backend::Cpu => compute_tables(&model, &config, false)?,
        Backend::Gpu(gpu) => gpu.tables(&model, &config, false)?,
    };
    let encoding = if args.compact {
        Encoding::Half
    } else {
        Encoding::F32
    };
    file::write_encoded(&tables, &args.out, encoding)?;
    eprintln!(
        "wrote {} ({}, {})",
        args.out.display(),
        model.wavelengths.describe(),
        encoding.name()
    );
    Ok(())
}

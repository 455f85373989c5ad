//! `firmament bake`: precompute the tables and write them to a file for `--tables`.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use firmament::sky::bruneton4d::file;

use crate::backend::{Backend, BackendChoice};
use crate::common::{check_output_dir, compute_tables, AtmosphereArgs};

/// Arguments of `firmament bake` (the shared atmosphere flags without `--tables`, which
/// `bake` computes rather than reads: hidden from its help, refused if given).
#[derive(Args, Debug)]
#[command(mut_arg("tables", |a| a.hide(true)))]
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
}

/// Run `firmament bake`.
pub fn run(args: &BakeArgs) -> Result<()> {
    check_output_dir(&args.out, "--out")?;
    if args.atmosphere.tables.is_some() {
        anyhow::bail!("`bake` computes tables: --tables makes no sense here");
    }
    let model = args.atmosphere.model()?;
    let config = args.atmosphere.table_config()?;
    let tables = match Backend::open(args.backend, false)? {
        Backend::Cpu => compute_tables(&model, &config, false)?,
        Backend::Gpu(gpu) => gpu.tables(&model, &config, false)?,
    };
    file::write(&tables, &args.out)?;
    eprintln!("wrote {}", args.out.display());
    Ok(())
}

//! `--backend cpu|gpu|auto`: where the tables are precomputed and frames rendered. The GPU
//! work goes through `firmament_gpu` (wgpu); everything after a frame (exposure, tone
//! mapping, image files) is the CPU code either way.
//!
//! With `commands/bench/gpu.rs`, the only place that calls `firmament_gpu`: the commands
//! see [`Backend`], [`Gpu`] and [`RenderSky`] (`render_sky.rs`: the sky a frame is drawn
//! from).

use std::time::Instant;

use anyhow::Result;
use clap::ValueEnum;
use firmament::atmosphere::Model;
use firmament::sky::bruneton4d::{Bruneton4d, TableConfig, Tables};
use firmament_gpu::Precomputer;
use firmament_gpu::{GpuContext, GpuError, GpuSky};

use crate::common::{cancel_flag, print_tables_time, spinner, AtmosphereArgs};

mod render_sky;
mod retable;

pub use render_sky::{gpu_lights, RenderSky};

/// The `--backend` flag of render, bake, query and gallery.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum BackendChoice {
    /// The CPU (rayon threads).
    Cpu,
    /// The GPU through wgpu, whatever adapter it finds (software rasterisers included);
    /// an error when there is none.
    Gpu,
    /// The GPU when wgpu finds a hardware adapter, else the CPU (a software rasteriser such
    /// as lavapipe is slower than the CPU path, so it is never picked).
    #[default]
    Auto,
}

/// The backend a command runs on.
pub enum Backend {
    Cpu,
    Gpu(Box<Gpu>),
}

/// An opened GPU.
pub struct Gpu {
    pub ctx: GpuContext,
}

/// What `auto` found: a hardware GPU opened, or why not (for the message).
pub enum Probe {
    Hardware(Box<Gpu>),
    NoHardware(String),
}

impl Backend {
    /// Resolve the choice; prints `backend: …` on stderr unless `quiet`.
    pub fn open(choice: BackendChoice, quiet: bool) -> Result<Backend> {
        let cpu_line = || format!("cpu ({} threads)", rayon::current_num_threads());
        let (backend, line) = match choice {
            BackendChoice::Cpu => (Backend::Cpu, cpu_line()),
            BackendChoice::Gpu => {
                let gpu = Gpu::open()?;
                let line = format!("gpu ({})", gpu.describe());
                (Backend::Gpu(Box::new(gpu)), line)
            }
            BackendChoice::Auto => match Gpu::probe_hardware() {
                Probe::Hardware(gpu) => {
                    let line = format!("gpu (auto: {})", gpu.describe());
                    (Backend::Gpu(gpu), line)
                }
                Probe::NoHardware(why) => (
                    Backend::Cpu,
                    format!(
                        "cpu (auto: {why}; {} threads)",
                        rayon::current_num_threads()
                    ),
                ),
            },
        };
        if !quiet {
            eprintln!("backend: {line}");
        }
        Ok(backend)
    }
}

/// The error for a failed GPU step: what failed, the device's reason, and the way out.
pub fn gpu_failure(what: &str, e: GpuError) -> anyhow::Error {
    anyhow::anyhow!("{what} failed on the GPU: {e} (`--backend cpu` does the same work on the CPU)")
}

/// GPU work under a spinner on stderr (hidden when `quiet`): the GPU reports no progress,
/// and Ctrl-C cannot stop a submission, so once the work is done it refuses to go on.
pub(crate) fn on_gpu<T>(message: &str, quiet: bool, work: impl FnOnce() -> Result<T>) -> Result<T> {
    let bar = spinner(message, quiet);
    let result = work();
    bar.finish_and_clear();
    let value = result?;
    if cancel_flag().load(std::sync::atomic::Ordering::Relaxed) {
        anyhow::bail!("interrupted");
    }
    Ok(value)
}

impl Gpu {
    /// Open the GPU for `--backend gpu`: any adapter, or a clear error.
    pub fn open() -> Result<Gpu> {
        let ctx = GpuContext::new().map_err(|e| {
            anyhow::anyhow!(
                "--backend gpu: could not open a GPU: {e} (`--backend cpu` computes on the CPU)"
            )
        })?;
        Ok(Gpu { ctx })
    }

    /// Look for a hardware adapter with compute shaders and open it (adapters are
    /// enumerated first: no device is created for a software one). Where there is no
    /// hardware GPU this costs the Vulkan loader's start-up, about 65 ms with Mesa's drivers
    /// installed.
    pub fn probe_hardware() -> Probe {
        let desc = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
        let backends = desc.backends;
        let instance = wgpu::Instance::new(desc);
        let adapters: Vec<wgpu::AdapterInfo> =
            pollster::block_on(instance.enumerate_adapters(backends))
                .into_iter()
                .filter(|a| {
                    a.get_downlevel_capabilities()
                        .flags
                        .contains(wgpu::DownlevelFlags::COMPUTE_SHADERS)
                })
                .map(|a| a.get_info())
                .collect();
        drop(instance);
        if !adapters
            .iter()
            .any(|a| a.device_type != wgpu::DeviceType::Cpu)
        {
            return Probe::NoHardware(match adapters.first() {
                Some(a) => format!("no hardware GPU; found software adapter {}", a.name),
                None => "no GPU adapter found".into(),
            });
        }
        // GpuContext::new ranks hardware before software: it opens the one found.
        match GpuContext::new() {
            Ok(ctx) if !ctx.is_software() => Probe::Hardware(Box::new(Gpu { ctx })),
            Ok(ctx) => Probe::NoHardware(format!(
                "no hardware GPU opened; found software adapter {}",
                ctx.adapter_name()
            )),
            Err(e) => Probe::NoHardware(format!("GPU unusable: {e}")),
        }
    }

    /// The adapter in words: "NAME, BACKEND" (plus "software rasteriser" where it is one).
    pub fn describe(&self) -> String {
        let ctx = &self.ctx;
        format!(
            "{}, {}{}",
            ctx.adapter_name(),
            ctx.backend(),
            if ctx.is_software() {
                ", software rasteriser"
            } else {
                ""
            }
        )
    }

    /// Wait until the device has finished everything submitted.
    pub fn wait_idle(&self, during: &str) -> Result<()> {
        self.ctx
            .device()
            .poll(wgpu::PollType::wait_indefinitely())
            .map(|_| ())
            .map_err(|e| {
                gpu_failure(
                    during,
                    GpuError::Execution {
                        during: during.to_string(),
                        reason: e.to_string(),
                    },
                )
            })
    }

    /// Precompute the tables on the GPU and read them back (for files and CPU lookups).
    pub fn tables(&self, model: &Model, config: &TableConfig, quiet: bool) -> Result<Tables> {
        self.precompute(
            model,
            config,
            quiet,
            "shader compilation and readback included",
            || {
                Precomputer::new(&self.ctx)
                    .and_then(|p| p.run(&self.ctx, model, config))
                    .map_err(|e| gpu_failure("precomputing the tables", e))
            },
        )
    }

    /// Precompute the tables on the GPU and keep them on the device (for GPU frames).
    fn sky(&self, model: &Model, config: &TableConfig, quiet: bool) -> Result<GpuSky> {
        self.precompute(
            model,
            config,
            quiet,
            "shader compilation included; kept on the device",
            || {
                let sky = Precomputer::new(&self.ctx)
                    .and_then(|p| GpuSky::precompute(&self.ctx, &p, model, config))
                    .map_err(|e| gpu_failure("precomputing the tables", e))?;
                self.wait_idle("precomputing the tables")?;
                Ok(sky)
            },
        )
    }

    /// A precomputation on the GPU under a spinner, then its `tables: …` line (with `note`).
    fn precompute<T>(
        &self,
        model: &Model,
        config: &TableConfig,
        quiet: bool,
        note: &str,
        work: impl FnOnce() -> Result<T>,
    ) -> Result<T> {
        let started = Instant::now();
        let computed = on_gpu("precomputing tables on the GPU", quiet, work)?;
        if !quiet {
            print_tables_time(started, model, config, " on the GPU", &format!("; {note}"));
        }
        Ok(computed)
    }
}

impl AtmosphereArgs {
    /// Model and tables (read from --tables, or computed on `backend`), paired.
    pub fn sky_on(&self, backend: &Backend, quiet: bool) -> Result<Bruneton4d> {
        match (backend, &self.tables) {
            (Backend::Gpu(gpu), None) => {
                let model = self.model()?;
                let tables = gpu.tables(&model, &self.table_config()?, quiet)?;
                Ok(Bruneton4d::new(model, tables)?)
            }
            _ => self.sky(quiet),
        }
    }
}

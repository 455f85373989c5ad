//! A sky's tables replaced for another atmosphere while its compiled passes stay: what the
//! viewer does when a slider moves the aerosols, the ozone or the ground. Compiling the
//! render and table shaders is most of a fresh sky's cost on a software rasteriser (and a
//! cold one takes minutes), so a new atmosphere re-runs only the tables.

use std::sync::OnceLock;

use anyhow::Result;
use firmament::atmosphere::Model;
use firmament::sky::bruneton4d::Bruneton4d;
use firmament_gpu::elek3d::GpuElek3d;
use firmament_gpu::hillaire2020::GpuHillaire;
use firmament_gpu::GpuSky;

use super::{gpu_failure, RenderSky};
use crate::common::AtmosphereArgs;
use crate::method::{CpuSky, Method};

impl RenderSky<'_> {
    /// Recompute the tables of this sky's method for `atmosphere` (same wavelengths, same
    /// table sizes), keeping the compiled passes: the 4D tables precomputed on the GPU,
    /// Hillaire 2020's tables with its kept table passes, the 3D table on the CPU and
    /// uploaded. A CPU sky is refused (the viewer draws on the GPU).
    pub fn retable(&mut self, atmosphere: &AtmosphereArgs, quiet: bool) -> Result<()> {
        match self {
            RenderSky::Cpu(..) => {
                anyhow::bail!("retable: a CPU sky is built afresh (RenderSky::new)")
            }
            RenderSky::Gpu {
                gpu,
                sky,
                sky_model,
                cpu_sky,
                config,
                ..
            } => {
                let model = atmosphere.model()?;
                same_channels(sky_model, &model)?;
                **sky = gpu.sky(&model, config, quiet)?;
                **sky_model = model;
                // The CPU's copy is read back again when the terrain asks for it.
                **cpu_sky = OnceLock::new();
            }
            RenderSky::GpuHillaire {
                gpu,
                sky,
                sky_model,
                precomputer,
                ..
            } => {
                let model = atmosphere.model()?;
                same_channels(sky_model, &model)?;
                let config = atmosphere.hillaire.config();
                **sky = GpuHillaire::compute(&gpu.ctx, precomputer, &model, &config)
                    .map_err(|e| gpu_failure("Hillaire 2020's tables", e))?;
                gpu.wait_idle("Hillaire 2020's tables")?;
                **sky_model = model;
            }
            RenderSky::GpuElek3d {
                gpu,
                sky,
                sky_model,
                ..
            } => {
                let CpuSky::Elek3d(cpu) = atmosphere.cpu_sky(Method::Elek3d, quiet)? else {
                    unreachable!("cpu_sky(Elek3d) builds the 3D tables")
                };
                same_channels(sky_model, &cpu.model)?;
                **sky = GpuElek3d::from_sky(&gpu.ctx, &cpu)
                    .map_err(|e| gpu_failure("uploading the 3D tables", e))?;
                **sky_model = cpu.model.clone();
            }
        }
        Ok(())
    }

    /// Draw from `tables` (4D tables computed elsewhere: the amortised update's swap),
    /// uploaded to the device; the render pipeline stays. The 4D sky on the GPU only.
    pub fn set_tables(&mut self, tables: Bruneton4d) -> Result<()> {
        let RenderSky::Gpu {
            gpu,
            sky,
            sky_model,
            cpu_sky,
            ..
        } = self
        else {
            anyhow::bail!("set_tables: the 4D tables on the GPU only");
        };
        same_channels(sky_model, &tables.model)?;
        **sky = GpuSky::from_sky(&gpu.ctx, &tables)
            .map_err(|e| gpu_failure("uploading the tables", e))?;
        **sky_model = tables.model.clone();
        let fresh = OnceLock::new();
        let _ = fresh.set(tables);
        **cpu_sky = fresh;
        Ok(())
    }
}

/// A new atmosphere keeps the wavelengths the passes and buffers were made for.
fn same_channels(old: &Model, new: &Model) -> Result<()> {
    if old.wavelengths.nm() != new.wavelengths.nm() {
        anyhow::bail!(
            "the new atmosphere's wavelengths ({:?} nm) differ from the sky's ({:?} nm): build the sky afresh",
            new.wavelengths.nm(),
            old.wavelengths.nm()
        );
    }
    Ok(())
}

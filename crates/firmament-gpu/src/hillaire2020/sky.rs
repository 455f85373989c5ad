//! Hillaire 2020 ready to render on the GPU ([`GpuHillaire`]): the atmosphere-wide tables on
//! the device, the per-channel constants the frame reads, and the per-view cache (one
//! sky-view table per light, rewritten by every frame). The WGSL twin is
//! `shaders/hillaire2020/view.wgsl`; an engine binds these buffers at its slots and composes
//! [`crate::shader::hillaire2020_sky_module`] into its own shader.

use firmament::atmosphere::Model;
use firmament::sky::hillaire2020::HillaireConfig;

use super::precompute::{check_f_ms, GpuHillaireTables, HillairePrecomputer, HillaireTables};
use crate::bruneton4d::atmosphere::{groups, GROUP};
use crate::device::{check_buffers, scoped};
use crate::passes::{init, storage};
use crate::render::frame::{FrameSky, CHANNEL_DATA_VEC4, CHANNEL_SRGB, CHANNEL_STRIDE, MAX_LIGHTS};
use crate::{GpuContext, GpuError};

/// Hillaire 2020's tables on the device, ready to render
/// ([`crate::GpuHillaireRenderer`]). Bindings of its buffers (`shaders/hillaire2020/`):
/// 0 atmosphere, 2 data, 3 optical depth, 8 sizes, 9 their data, 11 view constants, 13 the
/// sky-view tables, 20 Ψ_ms, 21 the sky irradiance.
pub struct GpuHillaire {
    tables: GpuHillaireTables,
    /// Per channel group: the linear sRGB rows of the colour matrix (binding 11).
    view_constants: wgpu::Buffer,
    /// The sky-view table of each light (binding 13), written before every frame.
    sky_view: wgpu::Buffer,
    config: HillaireConfig,
    channels: usize,
    radii_m: (f64, f64),
    solar_irradiance: Vec<f64>,
    balance: [f64; 3],
    max_f_ms: f64,
}

impl std::fmt::Debug for GpuHillaire {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("GpuHillaire")
            .field("channels", &self.channels)
            .field("config", &self.config)
            .field("max_f_ms", &self.max_f_ms)
            .finish()
    }
}

/// Bytes of the sky-view tables: per light, the table's texels × channel groups.
fn sky_view_bytes(config: &HillaireConfig, groups: usize) -> u64 {
    (MAX_LIGHTS * config.sky_view.0 * config.sky_view.1 * groups * GROUP * 4) as u64
}

impl GpuHillaire {
    /// Build the tables for `model` on the GPU with `precomputer` and keep them there;
    /// waits for f_ms (a few kB read back) and refuses the atmospheres
    /// `Hillaire2020::compute` refuses (f_ms above `F_MS_LIMIT`), with its message.
    pub fn compute(
        ctx: &GpuContext,
        precomputer: &HillairePrecomputer,
        model: &Model,
        config: &HillaireConfig,
    ) -> Result<GpuHillaire, GpuError> {
        let n = model.channels();
        firmament::spectrum::check_channels(n, "rendering")?;
        check_buffers(
            ctx,
            &[("sky-view tables", sky_view_bytes(config, groups(n)))],
        )?;
        let tables = precomputer.run_on_device(ctx, model, config)?;
        let (max_f_ms, at) = tables.max_f_ms(ctx, model, config)?;
        check_f_ms(model, max_f_ms, at)?;
        scoped(ctx, "preparing the Hillaire 2020 sky", || {
            Ok(GpuHillaire::assemble(ctx, model, config, tables, max_f_ms))
        })
    }

    /// A sky from tables on the device: adds the per-channel constants and the sky-view
    /// tables.
    fn assemble(
        ctx: &GpuContext,
        model: &Model,
        config: &HillaireConfig,
        tables: GpuHillaireTables,
        max_f_ms: f64,
    ) -> GpuHillaire {
        let n = model.channels();
        let colour = model.colour_matrix();
        // The uniform's full size (the shader declares a fixed-size array); lanes of
        // channel k in group k/4.
        let mut constants = vec![0.0f32; CHANNEL_DATA_VEC4 * 4];
        for k in 0..n {
            let (group, lane) = (k / GROUP, k % GROUP);
            let mut unit = vec![0.0f64; n];
            unit[k] = 1.0;
            for (c, v) in colour.to_srgb(&unit).iter().enumerate() {
                constants[(group * CHANNEL_STRIDE + CHANNEL_SRGB + c) * 4 + lane] = *v as f32;
            }
        }
        let device = ctx.device();
        GpuHillaire {
            view_constants: init(
                device,
                "view constants",
                bytemuck::cast_slice(&constants),
                crate::passes::UNIFORM_USAGE,
            ),
            sky_view: storage(device, "sky-view tables", sky_view_bytes(config, groups(n))),
            tables,
            config: *config,
            channels: n,
            radii_m: (model.bottom_radius_m, model.top_radius_m),
            solar_irradiance: model.solar_irradiance.clone(),
            balance: colour.white_balance(&model.solar_irradiance, true),
            max_f_ms,
        }
    }

    /// Number of wavelengths.
    pub fn channels(&self) -> usize {
        self.channels
    }

    /// The sizes and counts the tables were built with.
    pub fn config(&self) -> &HillaireConfig {
        &self.config
    }

    /// The largest f_ms of the multiple-scattering pass (`Hillaire2020::max_f_ms`).
    pub fn max_f_ms(&self) -> f64 {
        self.max_f_ms
    }

    /// The tables on the device.
    pub fn tables(&self) -> &GpuHillaireTables {
        &self.tables
    }

    /// The per-channel constants (binding 11).
    pub fn view_constants(&self) -> &wgpu::Buffer {
        &self.view_constants
    }

    /// The sky-view tables (binding 13), written by the `sky_view` entry point.
    pub fn sky_view(&self) -> &wgpu::Buffer {
        &self.sky_view
    }

    /// The tables read back into the CPU's layout (`model` the one they were built with).
    pub fn read_back(&self, ctx: &GpuContext, model: &Model) -> Result<HillaireTables, GpuError> {
        self.tables.read_back(ctx, model, &self.config)
    }
}

impl FrameSky for GpuHillaire {
    fn radii_m(&self) -> (f64, f64) {
        self.radii_m
    }
    fn mie_layout(&self) -> u32 {
        0
    }
    fn channel_count(&self) -> usize {
        self.channels
    }
    fn solar_irradiance(&self) -> &[f64] {
        &self.solar_irradiance
    }
    fn balance(&self) -> [f64; 3] {
        self.balance
    }
}

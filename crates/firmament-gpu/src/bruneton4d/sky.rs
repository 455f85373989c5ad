//! The 4D tables ready to render on the GPU ([`GpuSky`]): the tables on the device (uploaded
//! from a CPU [`Bruneton4d`] or precomputed there), the per-channel constants the view
//! functions read, and the per-view cache (one slice of the tables per light). The WGSL twin
//! is `shaders/bruneton4d/view.wgsl`; an engine binds these buffers at its slots and
//! composes [`crate::shader::sky_module`] into its own shader.

use firmament::atmosphere::Model;
use firmament::sky::bruneton4d::params::Radii;
use firmament::sky::bruneton4d::{Bruneton4d, MieStorage, TableConfig, TableSizes};

use super::atmosphere::{self, groups, GROUP};
use super::precompute::{GpuTables, Precomputer};
use crate::device::{check_buffers, scoped};
use crate::passes::{init, storage};
use crate::render::frame::{
    CHANNEL_DATA_VEC4, CHANNEL_MIE_RATIO, CHANNEL_SRGB, CHANNEL_STRIDE, MAX_LIGHTS, SLICE_TABLES,
};
use crate::{GpuContext, GpuError};

/// A sky ready to render on the GPU.
pub struct GpuSky {
    tables: GpuTables,
    /// Per channel group: the linear sRGB rows of the colour matrix and the red-only Mie
    /// ratios (binding 11, `view_constants`).
    view_constants: wgpu::Buffer,
    /// The per-view cache: the tables at each light's (r, μ_s) (binding 13, `slice_table`),
    /// rewritten by every frame.
    slice: wgpu::Buffer,
    /// Single Mie layout (`View.mie_layout` in view.wgsl).
    pub(crate) mie_layout: u32,
    pub(crate) channels: usize,
    pub(crate) radii: Radii,
    pub(crate) sizes: TableSizes,
    /// The solar irradiance the tables were computed with (each light scales against it).
    pub(crate) solar_irradiance: Vec<f64>,
    /// White-balance factors (ColourMatrix::white_balance with the option on).
    pub(crate) balance: [f64; 3],
}

impl std::fmt::Debug for GpuSky {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("GpuSky")
            .field("channels", &self.channels)
            .field("sizes", &self.sizes)
            .finish()
    }
}

/// Bytes of the per-view cache: per light, [single; multiple; single Mie] per (μ, ν) entry
/// and channel group.
fn slice_bytes(sizes: &TableSizes, groups: usize) -> u64 {
    (MAX_LIGHTS * sizes.scattering_mu * sizes.scattering_nu * SLICE_TABLES * groups * GROUP * 4)
        as u64
}

/// Channels padded to groups of four per texel, as the shaders index them.
fn pad_channels(data: &[f32], channels: usize, groups: usize) -> Vec<f32> {
    let texels = data.len() / channels.max(1);
    let mut out = vec![0.0f32; texels * groups * GROUP];
    for t in 0..texels {
        out[t * groups * GROUP..t * groups * GROUP + channels]
            .copy_from_slice(&data[t * channels..(t + 1) * channels]);
    }
    out
}

impl GpuSky {
    /// Upload `sky`'s tables (computed on the CPU or read from a file) and parameters.
    /// Refuses more wavelengths than the renderers handle and tables larger than the device
    /// binds.
    pub fn from_sky(ctx: &GpuContext, sky: &Bruneton4d) -> Result<GpuSky, GpuError> {
        let model = &sky.model;
        let tables = &sky.tables;
        let n = sky.channels();
        firmament::spectrum::check_channels(n, "rendering")?;
        let n_groups = groups(n);
        let red_only = tables.config.mie == MieStorage::RedOnly;
        let transmittance = pad_channels(&tables.optical_depth.data, n, n_groups);
        let irradiance = pad_channels(&tables.irradiance.data, n, n_groups);
        let single_rayleigh = pad_channels(&tables.single_rayleigh.data, n, n_groups);
        let multiple = pad_channels(&tables.multiple.data, n, n_groups);
        let single_mie = if red_only {
            pad_channels(&tables.single_mie.data, 1, 1)
        } else {
            pad_channels(&tables.single_mie.data, n, n_groups)
        };
        let bytes = |v: &[f32]| (v.len() * 4) as u64;
        let sizes = tables.config.sizes;
        check_buffers(
            ctx,
            &[
                ("scattering table", bytes(&single_rayleigh)),
                ("multiple scattering table", bytes(&multiple)),
                ("camera slice", slice_bytes(&sizes, n_groups)),
                ("single Mie table", bytes(&single_mie)),
                ("transmittance table", bytes(&transmittance)),
                ("irradiance table", bytes(&irradiance)),
            ],
        )?;
        let packed = atmosphere::pack(model, &sizes);
        let device = ctx.device();
        scoped(ctx, "uploading the tables", || {
            let usage = wgpu::BufferUsages::STORAGE;
            let f = |label: &str, v: &[f32]| init(device, label, bytemuck::cast_slice(v), usage);
            let tables = GpuTables {
                atmosphere: init(
                    device,
                    "atmosphere",
                    bytemuck::cast_slice(&packed.uniform),
                    crate::passes::UNIFORM_USAGE,
                ),
                data: f("atmosphere data", &packed.data),
                transmittance: f("transmittance", &transmittance),
                irradiance: f("irradiance", &irradiance),
                single_rayleigh: f("single rayleigh", &single_rayleigh),
                single_mie: f("single mie", &single_mie),
                multiple: f("multiple scattering", &multiple),
                row_sums: storage(device, "unused", 16),
            };
            Ok(GpuSky::assemble(
                ctx,
                model,
                sizes,
                u32::from(red_only),
                tables,
            ))
        })
    }

    /// Precompute the tables for `model` on the GPU with `precomputer` and keep them there
    /// (no readback: the same tables as [`crate::precompute`] followed by
    /// [`GpuSky::from_sky`], without the round trip through host memory).
    pub fn precompute(
        ctx: &GpuContext,
        precomputer: &Precomputer,
        model: &Model,
        config: &TableConfig,
    ) -> Result<GpuSky, GpuError> {
        let n = model.channels();
        firmament::spectrum::check_channels(n, "rendering")?;
        let s = config.sizes;
        check_buffers(ctx, &[("camera slice", slice_bytes(&s, groups(n)))])?;
        let tables = precomputer.run_on_device(ctx, model, config)?;
        // The device keeps single Mie in full even when red-only: channel 0 of each texel.
        let mie_layout = if config.mie == MieStorage::RedOnly {
            2
        } else {
            0
        };
        scoped(ctx, "preparing the GPU tables", || {
            Ok(GpuSky::assemble(ctx, model, s, mie_layout, tables))
        })
    }

    /// A sky from tables on the device: adds the per-channel constants and the slice.
    fn assemble(
        ctx: &GpuContext,
        model: &Model,
        sizes: TableSizes,
        mie_layout: u32,
        tables: GpuTables,
    ) -> GpuSky {
        let n = model.channels();
        let n_groups = groups(n);
        let colour = model.colour_matrix();
        let mie_ratio = model.groups.mie_ratio();
        // The uniform's full size (the shader declares a fixed-size array); lanes of
        // channel k in group k/4.
        let mut constants = vec![0.0f32; CHANNEL_DATA_VEC4 * 4];
        for k in 0..n {
            let (group, lane) = (k / GROUP, k % GROUP);
            let mut set = |row: usize, v: f64| {
                constants[(group * CHANNEL_STRIDE + row) * 4 + lane] = v as f32;
            };
            let mut unit = vec![0.0f64; n];
            unit[k] = 1.0;
            for (c, v) in colour.to_srgb(&unit).iter().enumerate() {
                set(CHANNEL_SRGB + c, *v);
            }
            set(CHANNEL_MIE_RATIO, mie_ratio[k]);
        }
        let device = ctx.device();
        GpuSky {
            view_constants: init(
                device,
                "view constants",
                bytemuck::cast_slice(&constants),
                crate::passes::UNIFORM_USAGE,
            ),
            slice: storage(device, "camera slice", slice_bytes(&sizes, n_groups)),
            tables,
            mie_layout,
            channels: n,
            radii: Radii::of(model),
            sizes,
            solar_irradiance: model.solar_irradiance.clone(),
            balance: colour.white_balance(&model.solar_irradiance, true),
        }
    }

    /// Number of wavelengths.
    pub fn channels(&self) -> usize {
        self.channels
    }

    /// The tables on the device, for an engine to bind at the slots of
    /// `shaders/bruneton4d/view.wgsl` (0 atmosphere, 2 data, 3–7 the tables).
    pub fn tables(&self) -> &GpuTables {
        &self.tables
    }

    /// The per-channel constants (binding 11).
    pub fn view_constants(&self) -> &wgpu::Buffer {
        &self.view_constants
    }

    /// The per-view cache (binding 13), written by the `camera_slice` entry point.
    pub fn slice(&self) -> &wgpu::Buffer {
        &self.slice
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn channels_are_padded_to_groups_of_four() {
        let data = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0, 10.0];
        let padded = pad_channels(&data, 5, 2);
        assert_eq!(padded.len(), 16);
        assert_eq!(&padded[..8], &[1.0, 2.0, 3.0, 4.0, 5.0, 0.0, 0.0, 0.0]);
        assert_eq!(&padded[8..], &[6.0, 7.0, 8.0, 9.0, 10.0, 0.0, 0.0, 0.0]);
    }
}

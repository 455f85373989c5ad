//! The render pass's pipelines for one output: `main` (the planet's sphere), `camera_slice`,
//! and the entry points compiled on first use: `main_terrain` over a terrain, `main_clouds`
//! under clouds, and `main_clouds` with its `WITH_TERRAIN` override for clouds over a
//! terrain (one WGSL source, two pipelines: shaders/render/cloud_frame.wgsl).

use std::sync::OnceLock;

use crate::clouds::GpuClouds;
use crate::device::scoped;
use crate::passes::{Pass, Slot};
use crate::shader::render_source;
use crate::terrain::GpuTerrain;
use crate::{GpuContext, GpuError};

/// A render pipeline (for one output), its `camera_slice` entry point, and its
/// `main_terrain` and `main_clouds` entry points (compiled on first use).
pub(super) struct Pipelines {
    pub(super) pass: Pass,
    pub(super) slice: wgpu::ComputePipeline,
    terrain: OnceLock<wgpu::ComputePipeline>,
    clouds: OnceLock<wgpu::ComputePipeline>,
    /// `main_clouds` with `WITH_TERRAIN` set: clouds over a terrain.
    terrain_clouds: OnceLock<wgpu::ComputePipeline>,
}

pub(super) fn compile(ctx: &GpuContext, output: Slot, format: Option<&str>) -> Pipelines {
    use Slot::{Read, Texture, Uniform, Write};
    let device = ctx.device();
    let pass = Pass::new(
        ctx,
        "render",
        render_source(format),
        &[
            (3, Read),
            (4, Read),
            (5, Read),
            (6, Read),
            (7, Read),
            (10, Uniform),
            (11, Uniform),
            (12, output),
            (13, Write),
            (14, Uniform),
            (15, Uniform),
            (16, Texture),
            (17, Read),
            (18, Uniform),
            (19, Read),
            (20, Uniform),
            (25, Texture),
            (26, Uniform),
        ],
    );
    Pipelines {
        slice: pass.entry_point(device, "camera_slice"),
        pass,
        terrain: OnceLock::new(),
        clouds: OnceLock::new(),
        terrain_clouds: OnceLock::new(),
    }
}

impl Pipelines {
    /// The pipeline drawing the pixels of a frame over `terrain` and under `clouds`
    /// (compiled here the first time).
    pub(super) fn main_for(
        &self,
        ctx: &GpuContext,
        terrain: Option<&GpuTerrain>,
        clouds: Option<&GpuClouds>,
    ) -> Result<&wgpu::ComputePipeline, GpuError> {
        Ok(match (terrain, clouds) {
            (None, None) => &self.pass.pipeline,
            (Some(_), None) => self.compiled(ctx, &self.terrain, "main_terrain", &[])?,
            (None, Some(_)) => self.compiled(ctx, &self.clouds, "main_clouds", &[])?,
            (Some(t), Some(c)) => {
                // The two share the observer's foot and the planet's sphere.
                if (t.radius_m() - c.planet_radius_m()).abs() > 1.0 {
                    return Err(firmament::Error::invalid(
                        "RenderInputs",
                        format!(
                            "clouds over a planet of radius {} m above a terrain on one of {} m",
                            c.planet_radius_m(),
                            t.radius_m()
                        ),
                        "clouds on the terrain's sphere",
                    )
                    .into());
                }
                let constants = [("WITH_TERRAIN", 1.0)];
                self.compiled(ctx, &self.terrain_clouds, "main_clouds", &constants)?
            }
        })
    }

    /// The entry point `name` with `constants` set, compiled into `cell` on first use.
    fn compiled<'a>(
        &self,
        ctx: &GpuContext,
        cell: &'a OnceLock<wgpu::ComputePipeline>,
        name: &str,
        constants: &[(&str, f64)],
    ) -> Result<&'a wgpu::ComputePipeline, GpuError> {
        if let Some(p) = cell.get() {
            return Ok(p);
        }
        let what = match constants {
            [] => name.to_string(),
            _ => format!("{name} with {constants:?}"),
        };
        let p = scoped(ctx, &format!("render shader compilation ({what})"), || {
            Ok(self.pass.entry_point_with(ctx.device(), name, constants))
        })?;
        Ok(cell.get_or_init(|| p))
    }
}

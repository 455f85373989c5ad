//! The stars and the lights' small disks added into a frame that stays on the device (the
//! viewer's HDR frame): the CPU projects and weighs them
//! (`firmament::render::stars::point_splats`, one entry per pixel), this pass adds the
//! entries in one dispatch (`shaders/render/stars.wgsl`), so a GPU frame shows the night sky
//! without a readback.

use crate::device::scoped;
use crate::{GpuContext, GpuError};

/// Bytes of one entry: the pixel's index and its linear sRGB share.
const SPLAT_BYTES: u64 = 16;
/// Threads per workgroup (the shader's `@workgroup_size`).
const WORKGROUP: u32 = 64;
/// Workgroups along x before the dispatch wraps into y (the shader's 65535 × 64).
const MAX_GROUPS_X: u32 = 65_535;

/// The pass and a buffer for its entries (grown as needed).
pub struct PointSplats {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    buffer: Option<(wgpu::Buffer, u64)>,
    params: wgpu::Buffer,
}

impl PointSplats {
    /// Compile the pass.
    pub fn new(ctx: &GpuContext) -> Result<PointSplats, GpuError> {
        let device = ctx.device();
        scoped(ctx, "the stars' pass compilation", || {
            let (pipeline, layout) = crate::passes::buffer_pipeline(
                ctx,
                "stars",
                include_str!("../../shaders/render/stars.wgsl"),
                "add_points",
                &[
                    (0, wgpu::BufferBindingType::Storage { read_only: false }),
                    (1, wgpu::BufferBindingType::Storage { read_only: true }),
                    (2, crate::passes::uniform_binding(ctx)),
                ],
            );
            let params = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("stars params"),
                size: 16,
                usage: crate::passes::UNIFORM_USAGE.union(wgpu::BufferUsages::COPY_DST),
                mapped_at_creation: false,
            });
            Ok(PointSplats {
                pipeline,
                layout,
                buffer: None,
                params,
            })
        })
    }

    /// Upload `splats` (pixel index, linear sRGB; each index once) and record their
    /// addition into `frame` (RGBA f32 per pixel, the mask in alpha). Nothing is recorded
    /// without entries.
    pub fn encode(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        frame: &wgpu::Buffer,
        splats: &[(u32, [f32; 3])],
    ) {
        if splats.is_empty() {
            return;
        }
        let device = ctx.device();
        let bytes = splats.len() as u64 * SPLAT_BYTES;
        if self.buffer.as_ref().is_none_or(|(_, size)| *size < bytes) {
            let size = bytes.next_power_of_two().max(1024);
            let buffer = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("star splats"),
                size,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            self.buffer = Some((buffer, size));
        }
        let (buffer, _) = self.buffer.as_ref().expect("just made");
        let raw: Vec<u8> = splats
            .iter()
            .flat_map(|(i, c)| {
                let mut e = [0u8; 16];
                e[0..4].copy_from_slice(&i.to_le_bytes());
                for k in 0..3 {
                    e[4 + 4 * k..8 + 4 * k].copy_from_slice(&c[k].to_le_bytes());
                }
                e
            })
            .collect();
        ctx.queue().write_buffer(buffer, 0, &raw);
        let mut params = [0u8; 16];
        params[0..4].copy_from_slice(&(splats.len() as u32).to_le_bytes());
        ctx.queue().write_buffer(&self.params, 0, &params);
        let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("stars"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: frame.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: buffer.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: self.params.as_entire_binding(),
                },
            ],
        });
        let groups = (splats.len() as u32).div_ceil(WORKGROUP);
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("stars"),
            timestamp_writes: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &bind, &[]);
        pass.dispatch_workgroups(groups.min(MAX_GROUPS_X), groups.div_ceil(MAX_GROUPS_X), 1);
    }
}

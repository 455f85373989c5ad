//! Compute pipelines: one per WGSL pass (its source composed by [`crate::shader`]), an
//! explicit bind group layout (slots 0–2 always: atmosphere, pass parameters, data), and a
//! dispatch helper that spreads large tables over two dispatch dimensions.

use wgpu::util::DeviceExt;

use crate::GpuContext;

/// Workgroup size of every pass (`WORKGROUP` in the WGSL prelude).
pub const WORKGROUP: u32 = 64;

/// How a pass uses a binding slot.
#[derive(Clone, Copy, Debug)]
pub enum Slot {
    /// A uniform buffer.
    Uniform,
    /// A read-only storage buffer.
    Read,
    /// A read-write storage buffer.
    Write,
    /// A 2D texture of unfilterable floats, read with `textureLoad`.
    Texture,
    /// A write-only 2D storage texture of this format.
    StorageTexture(wgpu::TextureFormat),
}

/// What every uniform block's buffer may be bound as: a uniform buffer, or a read-only
/// storage buffer where the passes read them so ([`GpuContext::uniforms_as_storage`]).
pub const UNIFORM_USAGE: wgpu::BufferUsages =
    wgpu::BufferUsages::UNIFORM.union(wgpu::BufferUsages::STORAGE);

/// `source` with its uniform blocks declared as `ctx` reads them (read-only storage where
/// [`GpuContext::uniforms_as_storage`]; WGSL lays both out alike).
pub fn uniform_source(ctx: &GpuContext, source: &str) -> String {
    if ctx.uniforms_as_storage() {
        source.replace("var<uniform>", "var<storage, read>")
    } else {
        source.to_string()
    }
}

/// The buffer binding type of a uniform block on `ctx`.
pub fn uniform_binding(ctx: &GpuContext) -> wgpu::BufferBindingType {
    if ctx.uniforms_as_storage() {
        wgpu::BufferBindingType::Storage { read_only: true }
    } else {
        wgpu::BufferBindingType::Uniform
    }
}

/// Binding slots every pass has.
const COMMON: [(u32, Slot); 3] = [(0, Slot::Uniform), (1, Slot::Uniform), (2, Slot::Read)];

/// A compute pipeline and its bind group layout.
pub struct Pass {
    pub name: &'static str,
    pub pipeline: wgpu::ComputePipeline,
    pub layout: wgpu::BindGroupLayout,
    slots: Vec<u32>,
    module: wgpu::ShaderModule,
    pipeline_layout: wgpu::PipelineLayout,
}

impl Pass {
    /// Compile `code` (a whole composed source); `slots` are the pass's own bindings besides
    /// the common ones. Its uniform blocks become read-only storage buffers where `ctx`
    /// asks for that ([`GpuContext::uniforms_as_storage`]; WGSL lays both out alike).
    pub fn new(ctx: &GpuContext, name: &'static str, code: String, slots: &[(u32, Slot)]) -> Pass {
        let device = ctx.device();
        let code = uniform_source(ctx, &code);
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some(name),
            source: wgpu::ShaderSource::Wgsl(code.into()),
        });
        let entries: Vec<wgpu::BindGroupLayoutEntry> = COMMON
            .iter()
            .chain(slots)
            .map(|&(binding, slot)| wgpu::BindGroupLayoutEntry {
                binding,
                visibility: wgpu::ShaderStages::COMPUTE,
                ty: match slot {
                    Slot::Uniform => buffer_binding(uniform_binding(ctx)),
                    Slot::Read => {
                        buffer_binding(wgpu::BufferBindingType::Storage { read_only: true })
                    }
                    Slot::Write => {
                        buffer_binding(wgpu::BufferBindingType::Storage { read_only: false })
                    }
                    Slot::Texture => wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: false },
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                    Slot::StorageTexture(format) => wgpu::BindingType::StorageTexture {
                        access: wgpu::StorageTextureAccess::WriteOnly,
                        format,
                        view_dimension: wgpu::TextureViewDimension::D2,
                    },
                },
                count: None,
            })
            .collect();
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some(name),
            entries: &entries,
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(name),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(name),
            layout: Some(&pipeline_layout),
            module: &module,
            entry_point: Some("main"),
            compilation_options: wgpu::PipelineCompilationOptions::default(),
            cache: None,
        });
        let slots = COMMON.iter().chain(slots).map(|s| s.0).collect();
        Pass {
            name,
            pipeline,
            layout,
            slots,
            module,
            pipeline_layout,
        }
    }

    /// Another entry point of the same source, with the same bind group layout.
    pub fn entry_point(&self, device: &wgpu::Device, entry: &str) -> wgpu::ComputePipeline {
        self.entry_point_with(device, entry, &[])
    }

    /// Another entry point of the same source, with the same bind group layout and the
    /// pipeline-overridable constants `constants` (WGSL `override`s) set.
    pub fn entry_point_with(
        &self,
        device: &wgpu::Device,
        entry: &str,
        constants: &[(&str, f64)],
    ) -> wgpu::ComputePipeline {
        device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(entry),
            layout: Some(&self.pipeline_layout),
            module: &self.module,
            entry_point: Some(entry),
            compilation_options: wgpu::PipelineCompilationOptions {
                constants,
                ..Default::default()
            },
            cache: None,
        })
    }

    /// A bind group with `common` at slots 0–2 and `buffers` at the pass's own slots, in
    /// the order they were declared.
    pub fn bind(
        &self,
        device: &wgpu::Device,
        common: [&wgpu::Buffer; 3],
        buffers: &[&wgpu::Buffer],
    ) -> wgpu::BindGroup {
        assert_eq!(
            self.slots.len(),
            3 + buffers.len(),
            "{}: wrong number of buffers",
            self.name
        );
        let entries: Vec<wgpu::BindGroupEntry> = self
            .slots
            .iter()
            .zip(common.iter().chain(buffers))
            .map(|(&binding, b)| wgpu::BindGroupEntry {
                binding,
                resource: b.as_entire_binding(),
            })
            .collect();
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(self.name),
            layout: &self.layout,
            entries: &entries,
        })
    }
}

/// A whole-buffer binding of type `ty`.
fn buffer_binding(ty: wgpu::BufferBindingType) -> wgpu::BindingType {
    wgpu::BindingType::Buffer {
        ty,
        has_dynamic_offset: false,
        min_binding_size: None,
    }
}

/// A compute pipeline of its own source's entry point `entry` over buffer bindings only
/// (not an atmosphere pass: no common slots), and its bind group layout; the source's
/// uniform blocks as `ctx` reads them ([`uniform_source`]).
pub fn buffer_pipeline(
    ctx: &GpuContext,
    label: &str,
    source: &str,
    entry: &str,
    bindings: &[(u32, wgpu::BufferBindingType)],
) -> (wgpu::ComputePipeline, wgpu::BindGroupLayout) {
    let device = ctx.device();
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(label),
        source: wgpu::ShaderSource::Wgsl(uniform_source(ctx, source).into()),
    });
    let entries: Vec<wgpu::BindGroupLayoutEntry> = bindings
        .iter()
        .map(|&(binding, ty)| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: buffer_binding(ty),
            count: None,
        })
        .collect();
    let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(label),
        entries: &entries,
    });
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(label),
        bind_group_layouts: &[Some(&layout)],
        immediate_size: 0,
    });
    let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(label),
        layout: Some(&pipeline_layout),
        module: &module,
        entry_point: Some(entry),
        compilation_options: Default::default(),
        cache: None,
    });
    (pipeline, layout)
}

/// Workgroup counts (x, y) covering `invocations` with 64-wide workgroups, x at most
/// `max_per_dimension` (the shaders rebuild the flat index from both).
pub fn workgroups(invocations: usize, max_per_dimension: u32) -> (u32, u32) {
    let total = invocations.div_ceil(WORKGROUP as usize).max(1);
    let x = total.min(max_per_dimension as usize);
    let y = total.div_ceil(x);
    (x as u32, y as u32)
}

/// Record one dispatch of `pass` over `invocations`, for `groups` channel groups (z).
pub fn dispatch(
    cpass: &mut wgpu::ComputePass,
    pass: &Pass,
    bind_group: &wgpu::BindGroup,
    invocations: usize,
    groups: usize,
    max_per_dimension: u32,
) {
    let (x, y) = workgroups(invocations, max_per_dimension);
    cpass.set_pipeline(&pass.pipeline);
    cpass.set_bind_group(0, bind_group, &[]);
    cpass.dispatch_workgroups(x, y, groups as u32);
}

/// A storage buffer of `bytes` bytes (at least 16).
pub fn storage(device: &wgpu::Device, label: &str, bytes: u64) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: bytes.max(16),
        usage: wgpu::BufferUsages::STORAGE
            | wgpu::BufferUsages::COPY_SRC
            | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

/// A buffer initialised with `contents` (at least 16 bytes).
pub fn init(
    device: &wgpu::Device,
    label: &str,
    contents: &[u8],
    usage: wgpu::BufferUsages,
) -> wgpu::Buffer {
    let mut bytes = contents.to_vec();
    while bytes.len() < 16 || !bytes.len().is_multiple_of(16) {
        bytes.push(0);
    }
    device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some(label),
        contents: &bytes,
        usage,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn workgroups_cover_large_tables_within_the_dimension_limit() {
        assert_eq!(workgroups(1, 65535), (1, 1));
        assert_eq!(workgroups(64, 65535), (1, 1));
        assert_eq!(workgroups(65, 65535), (2, 1));
        let (x, y) = workgroups(64 << 20, 65535);
        assert!(x <= 65535 && y <= 65535);
        assert!(x as usize * y as usize * 64 >= 64 << 20);
    }
}

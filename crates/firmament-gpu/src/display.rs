//! A frame on a display: exposure and tone mapping of a linear HDR frame on the GPU, for a
//! window (the viewer) or an engine's swap chain. The twin of what `Frame::to_srgb8` and
//! the exposure of `firmament render` do on the CPU (`shaders/display/`):
//!
//! - `exposure.wgsl`: the frame's log-average luminance metered as
//!   `Frame::log_average_luminance` and `tonemap::auto_ev100` meter it, then adapted over
//!   time (or a manual EV100), kept on the device (no readback in the frame loop);
//! - `tonemap.wgsl`: the gamut mapping, `tonemap::exposure_from_ev100`, the tone curve and
//!   the sRGB transfer function into any colour target, resampled to the target's size.
//!
//! The frame comes in the render pass's own frame buffer ([`crate::RenderTarget::Buffer`],
//! [`crate::GpuRenderer::frame_buffer`]: f32, as a sun's disk at ~10⁹ cd/m² overflows half
//! floats), so the viewer draws with the very pipeline `firmament render --backend gpu`
//! reads back. Readbacks ([`read_hdr_frame`], [`read_rgba8`]) serve captures and tests.

use firmament::render::tonemap::{ToneCurve, DISPLAY_MID_GREY, METER_K};
use firmament::render::Frame;
use wgpu::util::DeviceExt;

use crate::device::{read_back, scoped, staging_buffer};
use crate::passes::uniform_source;
use crate::render::frame_from_pixels;
use crate::{GpuContext, GpuError};

/// How a frame is exposed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Exposure {
    /// A fixed EV100.
    Manual { ev100: f64 },
    /// Metered from the frame (`tonemap::auto_ev100` of its log-average luminance),
    /// approaching the metered value with time constant `tau_s` (0: at once).
    Automatic { tau_s: f64 },
}

/// One frame's display settings.
#[derive(Clone, Copy, Debug)]
pub struct DisplaySettings {
    pub exposure: Exposure,
    pub curve: ToneCurve,
    /// Seconds since the previous frame (for the adaptation).
    pub dt_s: f64,
    /// Forget the adapted exposure (the first frame, a new scene).
    pub reset: bool,
}

/// The exposure state on the device, as read back ([`Display::read_exposure`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ExposureState {
    /// The EV100 the last frame was shown at.
    pub ev100: f64,
    /// The frame's metered log-average luminance (cd/m²).
    pub metered_cd_m2: f64,
    /// Pixels the meter counted.
    pub pixels: f64,
}

/// The exposure and display pipelines, and the exposure state.
pub struct Display {
    exposure_pipeline: wgpu::ComputePipeline,
    exposure_layout: wgpu::BindGroupLayout,
    present_layout: wgpu::BindGroupLayout,
    present_module: wgpu::ShaderModule,
    present_pipeline_layout: wgpu::PipelineLayout,
    /// The present pipeline per target format, built on first use.
    present: std::sync::Mutex<Vec<(wgpu::TextureFormat, wgpu::RenderPipeline)>>,
    state: wgpu::Buffer,
}

fn uniform_entry(
    ctx: &GpuContext,
    binding: u32,
    visibility: wgpu::ShaderStages,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Buffer {
            ty: crate::passes::uniform_binding(ctx),
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

fn storage_entry(
    binding: u32,
    visibility: wgpu::ShaderStages,
    read_only: bool,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

fn hdr_entry(visibility: wgpu::ShaderStages) -> wgpu::BindGroupLayoutEntry {
    storage_entry(0, visibility, true)
}

/// Whether a format's writes are sRGB-encoded by the hardware.
fn encodes_srgb(format: wgpu::TextureFormat) -> bool {
    format.is_srgb()
}

fn curve_index(curve: ToneCurve) -> u32 {
    match curve {
        ToneCurve::Aces => 0,
        ToneCurve::Filmic => 1,
        ToneCurve::Clamp => 2,
    }
}

impl Display {
    /// Compile the exposure pass and the display shader.
    pub fn new(ctx: &GpuContext) -> Result<Display, GpuError> {
        let device = ctx.device();
        scoped(ctx, "display shader compilation", || {
            let exposure_module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("exposure"),
                source: wgpu::ShaderSource::Wgsl(
                    uniform_source(ctx, include_str!("../shaders/display/exposure.wgsl")).into(),
                ),
            });
            let compute = wgpu::ShaderStages::COMPUTE;
            let exposure_layout =
                device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                    label: Some("exposure"),
                    entries: &[
                        hdr_entry(compute),
                        uniform_entry(ctx, 1, compute),
                        storage_entry(2, compute, false),
                    ],
                });
            let exposure_pipeline_layout =
                device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                    label: Some("exposure"),
                    bind_group_layouts: &[Some(&exposure_layout)],
                    immediate_size: 0,
                });
            let exposure_pipeline =
                device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                    label: Some("exposure"),
                    layout: Some(&exposure_pipeline_layout),
                    module: &exposure_module,
                    entry_point: Some("log_average_luminance"),
                    compilation_options: Default::default(),
                    cache: None,
                });
            let fragment = wgpu::ShaderStages::FRAGMENT;
            let present_layout =
                device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                    label: Some("display"),
                    entries: &[
                        hdr_entry(fragment),
                        uniform_entry(ctx, 1, fragment),
                        storage_entry(2, fragment, true),
                    ],
                });
            let present_pipeline_layout =
                device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                    label: Some("display"),
                    bind_group_layouts: &[Some(&present_layout)],
                    immediate_size: 0,
                });
            let present_module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("display"),
                source: wgpu::ShaderSource::Wgsl(
                    uniform_source(ctx, include_str!("../shaders/display/tonemap.wgsl")).into(),
                ),
            });
            let state = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("exposure state"),
                contents: bytemuck::cast_slice(&[0f32; 4]),
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            });
            Ok(Display {
                exposure_pipeline,
                exposure_layout,
                present_layout,
                present_module,
                present_pipeline_layout,
                present: std::sync::Mutex::new(Vec::new()),
                state,
            })
        })
    }

    fn present_pipeline(
        &self,
        device: &wgpu::Device,
        format: wgpu::TextureFormat,
    ) -> wgpu::RenderPipeline {
        let mut cache = self.present.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((_, p)) = cache.iter().find(|(f, _)| *f == format) {
            return p.clone();
        }
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("display"),
            layout: Some(&self.present_pipeline_layout),
            vertex: wgpu::VertexState {
                module: &self.present_module,
                entry_point: Some("fullscreen"),
                buffers: &[],
                compilation_options: Default::default(),
            },
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: None,
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module: &self.present_module,
                entry_point: Some("present"),
                targets: &[Some(wgpu::ColorTargetState {
                    format,
                    blend: None,
                    write_mask: wgpu::ColorWrites::ALL,
                })],
                compilation_options: Default::default(),
            }),
            multiview_mask: None,
            cache: None,
        });
        cache.push((format, pipeline.clone()));
        pipeline
    }

    /// Record the exposure pass over `hdr` (a `width`×`height` frame buffer, 16 bytes per
    /// pixel as [`crate::RenderTarget::Buffer`] holds it) and the display of it into
    /// `target` (any colour format; a UNORM one receives sRGB codes, an sRGB one linear
    /// values it encodes itself). With
    /// `timestamps` (a set of [`crate::pass_timer::PASS_QUERIES`]) the exposure pass
    /// writes slots 4–5 and the tone mapping 6–7.
    #[allow(clippy::too_many_arguments)]
    pub fn encode(
        &self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        hdr: &wgpu::Buffer,
        hdr_size: (u32, u32),
        target: &wgpu::TextureView,
        target_format: wgpu::TextureFormat,
        target_size: (u32, u32),
        settings: &DisplaySettings,
        timestamps: Option<&wgpu::QuerySet>,
    ) {
        let device = ctx.device();
        let (manual, ev100, tau_s) = match settings.exposure {
            Exposure::Manual { ev100 } => (1u32, ev100, 0.0),
            Exposure::Automatic { tau_s } => (0u32, 0.0, tau_s),
        };
        let exposure_words: [u32; 8] = [
            hdr_size.0,
            hdr_size.1,
            (settings.dt_s.max(0.0) as f32).to_bits(),
            (tau_s.max(0.0) as f32).to_bits(),
            (ev100 as f32).to_bits(),
            manual,
            (METER_K as f32).to_bits(),
            settings.reset as u32,
        ];
        let exposure_params = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("exposure parameters"),
            contents: bytemuck::cast_slice(&exposure_words),
            usage: crate::passes::UNIFORM_USAGE,
        });
        let exposure_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("exposure"),
            layout: &self.exposure_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: hdr.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: exposure_params.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: self.state.as_entire_binding(),
                },
            ],
        });
        {
            let mut cpass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("exposure"),
                timestamp_writes: timestamps.map(|set| wgpu::ComputePassTimestampWrites {
                    query_set: set,
                    beginning_of_pass_write_index: Some(4),
                    end_of_pass_write_index: Some(5),
                }),
            });
            cpass.set_pipeline(&self.exposure_pipeline);
            cpass.set_bind_group(0, &exposure_group, &[]);
            cpass.dispatch_workgroups(1, 1, 1);
        }
        let display_words: [u32; 8] = [
            hdr_size.0,
            hdr_size.1,
            target_size.0,
            target_size.1,
            curve_index(settings.curve),
            (!encodes_srgb(target_format)) as u32,
            (settings.curve.inverse(DISPLAY_MID_GREY) as f32).to_bits(),
            (METER_K as f32).to_bits(),
        ];
        let display_params = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("display parameters"),
            contents: bytemuck::cast_slice(&display_words),
            usage: crate::passes::UNIFORM_USAGE,
        });
        let display_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("display"),
            layout: &self.present_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: hdr.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: display_params.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: self.state.as_entire_binding(),
                },
            ],
        });
        let pipeline = self.present_pipeline(device, target_format);
        let mut rpass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("display"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: target,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: timestamps.map(|set| wgpu::RenderPassTimestampWrites {
                query_set: set,
                beginning_of_pass_write_index: Some(6),
                end_of_pass_write_index: Some(7),
            }),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        rpass.set_pipeline(&pipeline);
        rpass.set_bind_group(0, &display_group, &[]);
        rpass.draw(0..3, 0..1);
    }

    /// The exposure the last displayed frame used (waits for the device).
    pub fn read_exposure(&self, ctx: &GpuContext) -> Result<ExposureState, GpuError> {
        let during = "reading the exposure back";
        let staging = scoped(ctx, during, || {
            let staging = staging_buffer(ctx.device(), "exposure readback", 16);
            let mut encoder = ctx
                .device()
                .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: None });
            encoder.copy_buffer_to_buffer(&self.state, 0, &staging, 0, 16);
            ctx.queue().submit([encoder.finish()]);
            Ok(staging)
        })?;
        let raw = read_back(ctx, &[&staging], during)?;
        let v: Vec<f32> = bytemuck::pod_collect_to_vec(&raw[0]);
        Ok(ExposureState {
            ev100: v[0] as f64,
            metered_cd_m2: v[1] as f64,
            pixels: v[2] as f64,
        })
    }
}

/// A frame buffer the display reads (`width`×`height`, 16 bytes per pixel; usage STORAGE,
/// COPY_SRC for captures and COPY_DST for a frame the CPU drew).
pub fn hdr_buffer(ctx: &GpuContext, width: u32, height: u32) -> wgpu::Buffer {
    ctx.device().create_buffer(&wgpu::BufferDescriptor {
        label: Some("hdr frame"),
        size: width as u64 * height as u64 * crate::PIXEL_BYTES,
        usage: wgpu::BufferUsages::STORAGE
            | wgpu::BufferUsages::COPY_SRC
            | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

/// Copy a 2D texture's texels out (rows without padding; waits for the device).
fn read_texture(
    ctx: &GpuContext,
    texture: &wgpu::Texture,
    bytes_per_texel: u32,
    during: &str,
) -> Result<Vec<u8>, GpuError> {
    let (w, h) = (texture.width(), texture.height());
    let row = w * bytes_per_texel;
    let padded =
        row.div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
    let staging = scoped(ctx, during, || {
        let staging = staging_buffer(ctx.device(), during, padded as u64 * h as u64);
        let mut encoder = ctx
            .device()
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: None });
        encoder.copy_texture_to_buffer(
            texture.as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: &staging,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(padded),
                    rows_per_image: Some(h),
                },
            },
            wgpu::Extent3d {
                width: w,
                height: h,
                depth_or_array_layers: 1,
            },
        );
        ctx.queue().submit([encoder.finish()]);
        Ok(staging)
    })?;
    let raw = read_back(ctx, &[&staging], during)?;
    let mut out = Vec::with_capacity((row * h) as usize);
    for r in 0..h as usize {
        let start = r * padded as usize;
        out.extend_from_slice(&raw[0][start..start + row as usize]);
    }
    Ok(out)
}

/// A frame buffer's frame as the CPU's [`Frame`] (waits for the device).
pub fn read_hdr_frame(
    ctx: &GpuContext,
    buffer: &wgpu::Buffer,
    width: u32,
    height: u32,
) -> Result<Frame, GpuError> {
    let bytes = width as u64 * height as u64 * crate::PIXEL_BYTES;
    let during = "reading the frame back";
    let staging = scoped(ctx, during, || {
        let staging = staging_buffer(ctx.device(), during, bytes);
        let mut encoder = ctx
            .device()
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: None });
        encoder.copy_buffer_to_buffer(buffer, 0, &staging, 0, bytes);
        ctx.queue().submit([encoder.finish()]);
        Ok(staging)
    })?;
    let raw = read_back(ctx, &[&staging], during)?;
    let values: Vec<f32> = bytemuck::pod_collect_to_vec(&raw[0]);
    Ok(frame_from_pixels(&values, width as usize, height as usize))
}

/// An 8-bit RGBA texture's codes, rows from the top (waits for the device); a BGRA one is
/// returned as RGBA.
pub fn read_rgba8(ctx: &GpuContext, texture: &wgpu::Texture) -> Result<Vec<[u8; 4]>, GpuError> {
    let raw = read_texture(ctx, texture, 4, "reading the display back")?;
    let bgra = matches!(
        texture.format(),
        wgpu::TextureFormat::Bgra8Unorm | wgpu::TextureFormat::Bgra8UnormSrgb
    );
    Ok(raw
        .chunks_exact(4)
        .map(|p| {
            if bgra {
                [p[2], p[1], p[0], p[3]]
            } else {
                [p[0], p[1], p[2], p[3]]
            }
        })
        .collect())
}

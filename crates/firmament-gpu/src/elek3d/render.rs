//! Frames of the 3D tables on the GPU ([`GpuElek3dRenderer`]): `firmament::render::render`
//! of the clear sky with the `Elek3d` method, as one compute pass of two dispatches: the
//! slice of the tables at the observer for each light (`camera_slice` of
//! `shaders/elek3d/view.wgsl`, the CPU view's per-view cache), then one invocation per pixel
//! (`render/render.wgsl` composed after `elek3d/view.wgsl`: every camera projection, the
//! ground sphere lit by each light and the sky with the aerial perspective from the tables at
//! both ends of the ray, views from space, the lights' disks, lunar lights, the background
//! glow, an optional per-pixel shadowed length). The frame's uniforms are the 4D renderer's
//! (`render::frame`); no terrain.

use std::sync::OnceLock;
use std::time::Instant;

use firmament::render::{Frame, RenderSettings};
use firmament::scene::Light;

use super::sky::GpuElek3d;
use crate::bruneton4d::atmosphere::groups;
use crate::device::{f32s, read_back, scoped, staging_buffer};
use crate::passes::{init, workgroups, Pass, Slot, WORKGROUP};
use crate::render::frame::{light_words, FrameConstants, MAX_LIGHTS};
use crate::render::{
    frame_from_pixels, RenderInputs, RenderTarget, RenderTiming, BAND_ROW_ALIGN, PIXEL_BYTES,
};
use crate::shader::elek3d_render_source;
use crate::{GpuContext, GpuError};

/// Storage buffers the render pass binds: data, five tables, output, slices.
const STORAGE_BUFFERS_NEEDED: u32 = 8;

/// A render pipeline (for one output) and its `camera_slice` entry point.
struct Pipelines {
    pass: Pass,
    slice: wgpu::ComputePipeline,
}

/// The render pipelines of the 3D tables, compiled once per context (the texture outputs on
/// first use).
pub struct GpuElek3dRenderer {
    buffer: Pipelines,
    rgba32: OnceLock<Pipelines>,
    rgba16: OnceLock<Pipelines>,
    /// Binding 1 (the precomputation's pass parameters), unused here.
    unused_params: wgpu::Buffer,
    /// Binding 16 when no shadowed lengths are given (1×1).
    no_shadow_lengths: wgpu::TextureView,
    /// Binding 25 when no planet map is given.
    no_planet: crate::planet::NoPlanet,
    /// Cap on the output bytes one dispatch writes (None: the device's binding limit).
    max_band_bytes: Option<u64>,
}

/// Everything one frame's dispatches need, built and checked before any work is recorded.
struct Job<'p> {
    pipelines: &'p Pipelines,
    bind_groups: Vec<wgpu::BindGroup>,
    /// Workgroups (x, y) per band.
    dispatches: Vec<(u32, u32)>,
    /// Workgroups (x, y, groups) of the slices (None: observer in space).
    slice: Option<(u32, u32, u32)>,
}

fn compile(ctx: &GpuContext, output: Slot, format: Option<&str>) -> Pipelines {
    use Slot::{Read, Texture, Uniform, Write};
    let device = ctx.device();
    let pass = Pass::new(
        ctx,
        "elek3d render",
        elek3d_render_source(format),
        &[
            (3, Read),
            (4, Read),
            (5, Read),
            (6, Read),
            (7, Read),
            (8, Uniform),
            (10, Uniform),
            (11, Uniform),
            (12, output),
            (13, Write),
            (14, Uniform),
            (15, Uniform),
            (16, Texture),
            (25, Texture),
            (26, Uniform),
        ],
    );
    Pipelines {
        slice: pass.entry_point(device, "camera_slice"),
        pass,
    }
}

impl GpuElek3dRenderer {
    /// Compile the render pass (buffer output).
    pub fn new(ctx: &GpuContext) -> Result<GpuElek3dRenderer, GpuError> {
        let limits = ctx.limits();
        if limits.max_storage_buffers_per_shader_stage < STORAGE_BUFFERS_NEEDED {
            return Err(GpuError::Limit {
                what: "the 3D-table render pass".into(),
                needed: format!("{STORAGE_BUFFERS_NEEDED} storage buffers"),
                limit: limits.max_storage_buffers_per_shader_stage.to_string(),
                limit_name: "max_storage_buffers_per_shader_stage",
                adapter: ctx.adapter_name().to_string(),
            });
        }
        let device = ctx.device();
        scoped(ctx, "render shader compilation (3D tables)", || {
            let texture = device.create_texture(&wgpu::TextureDescriptor {
                label: Some("no shadowed lengths"),
                size: wgpu::Extent3d {
                    width: 1,
                    height: 1,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: wgpu::TextureFormat::R32Float,
                usage: wgpu::TextureUsages::TEXTURE_BINDING,
                view_formats: &[],
            });
            Ok(GpuElek3dRenderer {
                buffer: compile(ctx, Slot::Write, None),
                rgba32: OnceLock::new(),
                rgba16: OnceLock::new(),
                unused_params: init(device, "unused", &[0; 16], crate::passes::UNIFORM_USAGE),
                no_shadow_lengths: texture.create_view(&Default::default()),
                no_planet: crate::planet::NoPlanet::new(device),
                max_band_bytes: None,
            })
        })
    }

    /// Draw frames in bands of rows writing at most `bytes` each (as
    /// [`crate::GpuRenderer::with_max_band_bytes`]).
    pub fn with_max_band_bytes(mut self, bytes: u64) -> GpuElek3dRenderer {
        self.max_band_bytes = Some(bytes);
        self
    }

    /// A frame buffer for `settings` (usage STORAGE | COPY_SRC), to render into and read
    /// back.
    pub fn frame_buffer(&self, ctx: &GpuContext, settings: &RenderSettings) -> wgpu::Buffer {
        ctx.device().create_buffer(&wgpu::BufferDescriptor {
            label: Some("frame"),
            size: (settings.width * settings.height) as u64 * PIXEL_BYTES,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        })
    }

    /// Render a frame: the same [`Frame`] as [`firmament::render::render`] of the clear sky
    /// with the `Elek3d` method (linear sRGB with Y in cd/m², and the projection mask).
    pub fn render(
        &self,
        ctx: &GpuContext,
        sky: &GpuElek3d,
        lights: &[Light],
        settings: &RenderSettings,
    ) -> Result<Frame, GpuError> {
        self.render_with(ctx, sky, lights, settings, RenderInputs::default())
    }

    /// [`GpuElek3dRenderer::render`] with extra inputs (per-pixel shadowed lengths, the
    /// background glow; a terrain is refused).
    pub fn render_with(
        &self,
        ctx: &GpuContext,
        sky: &GpuElek3d,
        lights: &[Light],
        settings: &RenderSettings,
        inputs: RenderInputs,
    ) -> Result<Frame, GpuError> {
        check_frame_buffer(ctx, settings)?;
        let output = self.frame_buffer(ctx, settings);
        let mut encoder = ctx
            .device()
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("firmament elek3d frame"),
            });
        let target = RenderTarget::Buffer(&output);
        self.encode(ctx, &mut encoder, sky, lights, settings, target, inputs)?;
        ctx.queue().submit([encoder.finish()]);
        self.read_frame(ctx, &output, settings.width, settings.height)
    }

    /// Record a frame into `encoder` (one compute pass: the slices, then the pixels; nothing
    /// is submitted). Refuses what the CPU refuses, more than `MAX_LIGHTS` lights, a terrain,
    /// and frames the device cannot hold.
    #[allow(clippy::too_many_arguments)]
    pub fn encode(
        &self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        sky: &GpuElek3d,
        lights: &[Light],
        settings: &RenderSettings,
        target: RenderTarget,
        inputs: RenderInputs,
    ) -> Result<(), GpuError> {
        let job = self.prepare(ctx, sky, lights, settings, target, inputs)?;
        scoped(ctx, "recording the frame", || {
            record(encoder, &job, inputs.timestamps);
            Ok(())
        })
    }

    /// Read a frame buffer rendered for a `width`×`height` frame back as a [`Frame`] (waits
    /// for the device).
    pub fn read_frame(
        &self,
        ctx: &GpuContext,
        output: &wgpu::Buffer,
        width: usize,
        height: usize,
    ) -> Result<Frame, GpuError> {
        let bytes = (width * height) as u64 * PIXEL_BYTES;
        let device = ctx.device();
        let staging = scoped(ctx, "frame rendering (3D tables)", || {
            let mut encoder = device.create_command_encoder(&Default::default());
            let staging = staging_buffer(device, "frame readback", bytes);
            encoder.copy_buffer_to_buffer(output, 0, &staging, 0, bytes);
            ctx.queue().submit([encoder.finish()]);
            Ok(staging)
        })?;
        let during = "reading the frame back";
        let raw = scoped(ctx, during, || read_back(ctx, &[&staging], during))?;
        Ok(frame_from_pixels(&f32s(&raw[0]), width, height))
    }

    /// Render `frames` frames into a buffer (after one warm-up) and return the median time of
    /// the compute pass alone (the slices and the pixels; no upload, no readback): from
    /// timestamp queries where the device has them, else the wall time of submit + wait (as
    /// [`crate::GpuRenderer::time_render`]).
    pub fn time_render(
        &self,
        ctx: &GpuContext,
        sky: &GpuElek3d,
        lights: &[Light],
        settings: &RenderSettings,
        frames: usize,
    ) -> Result<RenderTiming, GpuError> {
        let frames = frames.max(1);
        check_frame_buffer(ctx, settings)?;
        let output = self.frame_buffer(ctx, settings);
        let target = RenderTarget::Buffer(&output);
        let job = self.prepare(ctx, sky, lights, settings, target, RenderInputs::default())?;
        let device = ctx.device();
        let timestamps = ctx.supports_timestamps();
        let mut times = Vec::with_capacity(frames);
        scoped(ctx, "timing frames (3D tables)", || {
            let queries = timestamps.then(|| {
                let set = device.create_query_set(&wgpu::QuerySetDescriptor {
                    label: Some("frame timestamps"),
                    ty: wgpu::QueryType::Timestamp,
                    count: 2,
                });
                let resolve = device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("timestamp resolve"),
                    size: 16,
                    usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                    mapped_at_creation: false,
                });
                (set, resolve)
            });
            for i in 0..=frames {
                let mut encoder = device.create_command_encoder(&Default::default());
                record(&mut encoder, &job, queries.as_ref().map(|q| &q.0));
                let readback = queries.as_ref().map(|(set, resolve)| {
                    encoder.resolve_query_set(set, 0..2, resolve, 0);
                    let b = staging_buffer(device, "timestamp readback", 16);
                    encoder.copy_buffer_to_buffer(resolve, 0, &b, 0, 16);
                    b
                });
                let start = Instant::now();
                ctx.queue().submit([encoder.finish()]);
                device
                    .poll(wgpu::PollType::wait_indefinitely())
                    .map_err(|e| GpuError::Execution {
                        during: "timing frames (3D tables)".into(),
                        reason: e.to_string(),
                    })?;
                let wall = start.elapsed().as_secs_f64();
                let seconds = match readback {
                    Some(b) => {
                        let raw = read_back(ctx, &[&b], "reading timestamps")?;
                        let tick = |b: &[u8]| u64::from_le_bytes(b[..8].try_into().unwrap());
                        tick(&raw[0][8..16]).saturating_sub(tick(&raw[0][0..8])) as f64
                            * ctx.queue().get_timestamp_period() as f64
                            * 1e-9
                    }
                    None => wall,
                };
                if i > 0 {
                    times.push(seconds);
                }
            }
            Ok(())
        })?;
        times.sort_by(f64::total_cmp);
        Ok(RenderTiming {
            seconds: times[times.len() / 2],
            frames,
            method: if timestamps {
                "timestamp queries"
            } else {
                "wall clock (submit + wait)"
            },
        })
    }

    /// The pipelines of a target.
    fn pipelines(&self, ctx: &GpuContext, target: &RenderTarget) -> Result<&Pipelines, GpuError> {
        let (cell, format, wgsl) = match target {
            RenderTarget::Buffer(_) => return Ok(&self.buffer),
            RenderTarget::Texture(_, wgpu::TextureFormat::Rgba32Float) => (
                &self.rgba32,
                wgpu::TextureFormat::Rgba32Float,
                "rgba32float",
            ),
            RenderTarget::Texture(_, wgpu::TextureFormat::Rgba16Float) => (
                &self.rgba16,
                wgpu::TextureFormat::Rgba16Float,
                "rgba16float",
            ),
            RenderTarget::Texture(_, other) => {
                return Err(firmament::Error::invalid(
                    "render target format",
                    format!("{other:?}"),
                    "Rgba32Float or Rgba16Float",
                )
                .into())
            }
        };
        if let Some(p) = cell.get() {
            return Ok(p);
        }
        let p = scoped(ctx, "render shader compilation (3D tables)", || {
            Ok(compile(ctx, Slot::StorageTexture(format), Some(wgsl)))
        })?;
        Ok(cell.get_or_init(|| p))
    }

    /// Validate the settings and inputs, check the device limits, and build the frame's
    /// uniforms and one bind group per band of rows (a texture target is one band).
    fn prepare<'p>(
        &'p self,
        ctx: &GpuContext,
        sky: &GpuElek3d,
        lights: &[Light],
        settings: &RenderSettings,
        target: RenderTarget,
        inputs: RenderInputs,
    ) -> Result<Job<'p>, GpuError> {
        settings.validate()?;
        if lights.is_empty() || lights.len() > MAX_LIGHTS {
            return Err(firmament::Error::invalid(
                "lights",
                lights.len(),
                format!("between 1 and {MAX_LIGHTS} lights for a GPU frame"),
            )
            .into());
        }
        if inputs.terrain.is_some() {
            return Err(firmament::Error::invalid(
                "terrain",
                "a GpuTerrain",
                "none: the 3D tables (elek3d) have no terrain on the GPU (GpuRenderer draws terrains over the 4D tables; the CPU method takes them)",
            )
            .into());
        }
        let (w, h) = (settings.width, settings.height);
        let limits = ctx.limits();
        let limit = |what: String, needed: String, limit: String, limit_name| GpuError::Limit {
            what,
            needed,
            limit,
            limit_name,
            adapter: ctx.adapter_name().to_string(),
        };
        let row_bytes = w as u64 * PIXEL_BYTES;
        let band_rows = match target {
            RenderTarget::Texture(..) => h,
            RenderTarget::Buffer(_) => {
                let (binding_limit, name) = match self.max_band_bytes {
                    Some(b) if b < limits.max_storage_buffer_binding_size => {
                        (b, "GpuElek3dRenderer::with_max_band_bytes")
                    }
                    _ => (
                        limits.max_storage_buffer_binding_size,
                        "max_storage_buffer_binding_size",
                    ),
                };
                let fit = (binding_limit / row_bytes) as usize;
                let rows = if fit >= h {
                    h
                } else {
                    fit / BAND_ROW_ALIGN * BAND_ROW_ALIGN
                };
                if rows == 0 {
                    return Err(limit(
                        format!("a frame {w} pixels wide"),
                        format!("{} bytes per {BAND_ROW_ALIGN} rows", row_bytes * 16),
                        format!("{binding_limit} bytes"),
                        name,
                    ));
                }
                rows
            }
        };
        let max_dim = limits.max_compute_workgroups_per_dimension;
        if workgroups(band_rows * w, max_dim).1 > max_dim {
            return Err(limit(
                format!("a {w}×{h} frame"),
                format!("{} invocations per dispatch", band_rows * w),
                format!("{max_dim}² workgroups of {WORKGROUP}"),
                "max_compute_workgroups_per_dimension",
            ));
        }
        let pipelines = self.pipelines(ctx, &target)?;
        let constants =
            FrameConstants::new(sky, lights.len(), inputs.shadow_lengths.is_some(), settings);
        let device = ctx.device();
        scoped(ctx, "preparing the frame (3D tables)", || {
            let uniform = |label: &str, words: &[u32]| {
                init(
                    device,
                    label,
                    bytemuck::cast_slice(words),
                    crate::passes::UNIFORM_USAGE,
                )
            };
            let light_uniform = uniform("lights", &light_words(sky, lights, inputs.background));
            let coordinates = uniform("slice coordinates", &sky.slice_words(lights, settings));
            let shadow = inputs.shadow_lengths.unwrap_or(&self.no_shadow_lengths);
            let (planet_map, planet_uniform) = self.no_planet.or(device, inputs.planet);
            let t = sky.tables();
            let mut bind_groups = Vec::new();
            let mut dispatches = Vec::new();
            let mut first = 0;
            while first < h {
                let rows = band_rows.min(h - first);
                let frame_uniform = uniform("frame constants", &constants.words(first, rows));
                let output = match target {
                    RenderTarget::Buffer(buffer) => {
                        wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                            buffer,
                            offset: first as u64 * row_bytes,
                            size: wgpu::BufferSize::new(rows as u64 * row_bytes),
                        })
                    }
                    RenderTarget::Texture(view, _) => wgpu::BindingResource::TextureView(view),
                };
                let entries = [
                    (0, t.atmosphere.as_entire_binding()),
                    (1, self.unused_params.as_entire_binding()),
                    (2, t.data.as_entire_binding()),
                    (3, t.optical_depth.as_entire_binding()),
                    (4, t.irradiance.as_entire_binding()),
                    (5, t.single_rayleigh.as_entire_binding()),
                    (6, t.single_mie.as_entire_binding()),
                    (7, t.multiple.as_entire_binding()),
                    (8, t.params.as_entire_binding()),
                    (10, frame_uniform.as_entire_binding()),
                    (11, sky.view_constants().as_entire_binding()),
                    (12, output),
                    (13, sky.slice().as_entire_binding()),
                    (14, light_uniform.as_entire_binding()),
                    (15, coordinates.as_entire_binding()),
                    (16, wgpu::BindingResource::TextureView(shadow)),
                    (25, wgpu::BindingResource::TextureView(planet_map)),
                    (26, planet_uniform.as_entire_binding()),
                ];
                let entries: Vec<wgpu::BindGroupEntry> = entries
                    .into_iter()
                    .map(|(binding, resource)| wgpu::BindGroupEntry { binding, resource })
                    .collect();
                bind_groups.push(device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("elek3d frame"),
                    layout: &pipelines.pass.layout,
                    entries: &entries,
                }));
                dispatches.push(workgroups(rows * w, max_dim));
                first += rows;
            }
            let slice = constants.inside.then(|| {
                let (x, y) = workgroups(sky.config().view_zenith * lights.len(), max_dim);
                (x, y, groups(sky.channels()) as u32)
            });
            Ok(Job {
                pipelines,
                bind_groups,
                dispatches,
                slice,
            })
        })
    }
}

/// Record the frame's dispatches (one compute pass, timestamps 0 and 1 at its ends if
/// given): the slices, then the pixels band by band.
fn record(encoder: &mut wgpu::CommandEncoder, job: &Job, timestamps: Option<&wgpu::QuerySet>) {
    let mut cpass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
        label: Some("firmament elek3d frame"),
        timestamp_writes: timestamps.map(|set| wgpu::ComputePassTimestampWrites {
            query_set: set,
            beginning_of_pass_write_index: Some(0),
            end_of_pass_write_index: Some(1),
        }),
    });
    if let (Some((x, y, z)), Some(bg)) = (job.slice, job.bind_groups.first()) {
        cpass.set_pipeline(&job.pipelines.slice);
        cpass.set_bind_group(0, bg, &[]);
        cpass.dispatch_workgroups(x, y, z);
    }
    cpass.set_pipeline(&job.pipelines.pass.pipeline);
    for (bg, &(x, y)) in job.bind_groups.iter().zip(&job.dispatches) {
        cpass.set_bind_group(0, bg, &[]);
        cpass.dispatch_workgroups(x, y, 1);
    }
}

/// Refuse a frame buffer larger than the device allocates (as the 4D renderer does).
fn check_frame_buffer(ctx: &GpuContext, settings: &RenderSettings) -> Result<(), GpuError> {
    settings.validate()?;
    let (w, h) = (settings.width, settings.height);
    let total = w as u64 * h as u64 * PIXEL_BYTES;
    let limit = ctx.limits().max_buffer_size;
    if total > limit {
        return Err(GpuError::Limit {
            what: format!("a {w}×{h} frame"),
            needed: format!("{total} bytes ({PIXEL_BYTES} per pixel)"),
            limit: format!("{limit} bytes"),
            limit_name: "max_buffer_size",
            adapter: ctx.adapter_name().to_string(),
        });
    }
    Ok(())
}

//! Frames of Hillaire 2020 on the GPU ([`GpuHillaireRenderer`]): `firmament::render::render`
//! of the clear sky with the `Hillaire2020` method, as two compute passes: the sky-view
//! table of each light at the observer (`sky_view` of `shaders/hillaire2020/sky_view.wgsl`,
//! the method's per-view cache), then one invocation per pixel (`render/render.wgsl` composed
//! after `hillaire2020/view.wgsl`: every camera projection, the ground sphere lit by each
//! light and the sky with the aerial perspective marched per pixel, the sky from the tables
//! or marched from space, the lights' disks, lunar lights, the background glow, an optional
//! per-pixel shadowed length). The frame's uniforms are the 4D renderer's
//! (`render::frame`); no terrain.

use std::sync::OnceLock;

use firmament::render::{Frame, RenderSettings};
use firmament::scene::Light;
use firmament::sky::bruneton4d::Table2;

use super::sky::GpuHillaire;
use crate::bruneton4d::atmosphere::{groups, GROUP};
use crate::device::{f32s, read_back, scoped, staging_buffer};
use crate::passes::{init, workgroups, Pass, Slot, WORKGROUP};
use crate::render::frame::{light_words, FrameConstants, FrameSky, MAX_LIGHTS};
use crate::render::{frame_from_pixels, RenderInputs, RenderTarget, BAND_ROW_ALIGN, PIXEL_BYTES};
use crate::shader::hillaire2020_render_source;
use crate::{GpuContext, GpuError};

/// Storage buffers the render pass binds: data, optical depth, Hillaire's data, output,
/// sky-view tables, Ψ_ms, sky irradiance.
const STORAGE_BUFFERS_NEEDED: u32 = 7;

/// A render pipeline (for one output) and its `sky_view` entry point.
pub(crate) struct Pipelines {
    pass: Pass,
    sky_view: wgpu::ComputePipeline,
}

/// The render pipelines of Hillaire 2020, compiled once per context (the texture outputs on
/// first use).
pub struct GpuHillaireRenderer {
    buffer: Pipelines,
    rgba32: OnceLock<Pipelines>,
    rgba16: OnceLock<Pipelines>,
    /// Binding 16 when no shadowed lengths are given (1×1).
    no_shadow_lengths: wgpu::TextureView,
    /// Binding 25 when no planet map is given.
    no_planet: crate::planet::NoPlanet,
    /// Cap on the output bytes one dispatch writes (None: the device's binding limit).
    max_band_bytes: Option<u64>,
}

/// Everything one frame's dispatches need, built and checked before any work is recorded.
pub(crate) struct Job<'p> {
    pipelines: &'p Pipelines,
    bind_groups: Vec<wgpu::BindGroup>,
    /// Workgroups (x, y) per band.
    dispatches: Vec<(u32, u32)>,
    /// Workgroups (x, y, groups) of the sky-view tables (None: observer in space).
    sky_view: Option<(u32, u32, u32)>,
}

fn compile(ctx: &GpuContext, output: Slot, format: Option<&str>) -> Pipelines {
    use Slot::{Read, Texture, Uniform, Write};
    let device = ctx.device();
    let pass = Pass::new(
        ctx,
        "hillaire2020 render",
        hillaire2020_render_source(format),
        &[
            (3, Read),
            (8, Uniform),
            (9, Read),
            (10, Uniform),
            (11, Uniform),
            (12, output),
            (13, Write),
            (14, Uniform),
            (15, Uniform),
            (16, Texture),
            (20, Read),
            (21, Read),
            (25, Texture),
            (26, Uniform),
        ],
    );
    Pipelines {
        sky_view: pass.entry_point(device, "sky_view"),
        pass,
    }
}

/// The `SkyViewCoordinates` uniform: per light (μ_s at the observer, angular radius), the
/// observer's r and ρ (km), the lights.
fn sky_view_words(sky: &GpuHillaire, lights: &[Light], settings: &RenderSettings) -> Vec<u32> {
    let bits = |x: f64| (x as f32).to_bits();
    let (bottom, _) = sky.radii_m();
    let r = bottom + settings.camera.altitude_m;
    let mut words = vec![0u32; MAX_LIGHTS * 4];
    for (l, light) in lights.iter().enumerate() {
        // The observer is on the +z axis: μ_s = light·up = light.z.
        words[l * 4] = bits(light.direction.z.clamp(-1.0, 1.0));
        words[l * 4 + 1] = bits(light.angular_radius_rad);
    }
    let rho = (r * r - bottom * bottom).max(0.0).sqrt();
    words.extend([bits(r * 1e-3), bits(rho * 1e-3), lights.len() as u32, 0]);
    words
}

impl Job<'_> {
    /// Whether the frame builds sky-view tables (an observer in the atmosphere).
    pub(crate) fn has_sky_view(&self) -> bool {
        self.sky_view.is_some()
    }
}

impl GpuHillaireRenderer {
    /// Compile the render pass (buffer output).
    pub fn new(ctx: &GpuContext) -> Result<GpuHillaireRenderer, GpuError> {
        let limits = ctx.limits();
        if limits.max_storage_buffers_per_shader_stage < STORAGE_BUFFERS_NEEDED {
            return Err(GpuError::Limit {
                what: "the Hillaire 2020 render pass".into(),
                needed: format!("{STORAGE_BUFFERS_NEEDED} storage buffers"),
                limit: limits.max_storage_buffers_per_shader_stage.to_string(),
                limit_name: "max_storage_buffers_per_shader_stage",
                adapter: ctx.adapter_name().to_string(),
            });
        }
        let device = ctx.device();
        scoped(ctx, "render shader compilation (Hillaire 2020)", || {
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
            Ok(GpuHillaireRenderer {
                buffer: compile(ctx, Slot::Write, None),
                rgba32: OnceLock::new(),
                rgba16: OnceLock::new(),
                no_shadow_lengths: texture.create_view(&Default::default()),
                no_planet: crate::planet::NoPlanet::new(device),
                max_band_bytes: None,
            })
        })
    }

    /// Draw frames in bands of rows writing at most `bytes` each (as
    /// [`crate::GpuRenderer::with_max_band_bytes`]).
    pub fn with_max_band_bytes(mut self, bytes: u64) -> GpuHillaireRenderer {
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
    /// with the Hillaire 2020 method (linear sRGB with Y in cd/m², and the projection mask).
    pub fn render(
        &self,
        ctx: &GpuContext,
        sky: &GpuHillaire,
        lights: &[Light],
        settings: &RenderSettings,
    ) -> Result<Frame, GpuError> {
        self.render_with(ctx, sky, lights, settings, RenderInputs::default())
    }

    /// [`GpuHillaireRenderer::render`] with extra inputs (per-pixel shadowed lengths, the
    /// background glow; a terrain is refused).
    pub fn render_with(
        &self,
        ctx: &GpuContext,
        sky: &GpuHillaire,
        lights: &[Light],
        settings: &RenderSettings,
        inputs: RenderInputs,
    ) -> Result<Frame, GpuError> {
        check_frame_buffer(ctx, settings)?;
        let output = self.frame_buffer(ctx, settings);
        let mut encoder = ctx
            .device()
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("firmament hillaire2020 frame"),
            });
        let target = RenderTarget::Buffer(&output);
        self.encode(ctx, &mut encoder, sky, lights, settings, target, inputs)?;
        ctx.queue().submit([encoder.finish()]);
        self.read_frame(ctx, &output, settings.width, settings.height)
    }

    /// Record a frame into `encoder` (the sky-view tables, then the pixels; nothing is
    /// submitted). Refuses what the CPU refuses, more than `MAX_LIGHTS` lights, a terrain,
    /// and frames the device cannot hold.
    #[allow(clippy::too_many_arguments)]
    pub fn encode(
        &self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        sky: &GpuHillaire,
        lights: &[Light],
        settings: &RenderSettings,
        target: RenderTarget,
        inputs: RenderInputs,
    ) -> Result<(), GpuError> {
        let job = self.prepare(ctx, sky, lights, settings, target, inputs)?;
        scoped(ctx, "recording the frame", || {
            self.record(encoder, &job, inputs.timestamps);
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
        let raw = read_buffer(ctx, output, (width * height) as u64 * PIXEL_BYTES, "frame")?;
        Ok(frame_from_pixels(&raw, width, height))
    }

    /// The sky-view tables a frame of `settings` under `lights` builds, read back (one
    /// [`Table2`] per light in the CPU's layout, per unit light irradiance:
    /// `Hillaire2020View`'s table). None for an observer above the atmosphere.
    pub fn sky_view_tables(
        &self,
        ctx: &GpuContext,
        sky: &GpuHillaire,
        lights: &[Light],
        settings: &RenderSettings,
    ) -> Result<Option<Vec<Table2>>, GpuError> {
        check_frame_buffer(ctx, settings)?;
        let output = self.frame_buffer(ctx, settings);
        let target = RenderTarget::Buffer(&output);
        let job = self.prepare(ctx, sky, lights, settings, target, RenderInputs::default())?;
        if job.sky_view.is_none() {
            return Ok(None);
        }
        scoped(ctx, "the sky-view tables", || {
            let mut encoder = ctx.device().create_command_encoder(&Default::default());
            self.record_sky_view(&mut encoder, &job, None);
            ctx.queue().submit([encoder.finish()]);
            Ok(())
        })?;
        let (w, h) = sky.config().sky_view;
        let (n, g) = (sky.channels(), groups(sky.channels()));
        let raw = read_buffer(
            ctx,
            sky.sky_view(),
            sky.sky_view().size(),
            "sky-view tables",
        )?;
        let tables = (0..lights.len())
            .map(|l| {
                let mut data = Vec::with_capacity(w * h * n);
                for texel in 0..w * h {
                    let at = (l * w * h + texel) * g * GROUP;
                    data.extend_from_slice(&raw[at..at + n]);
                }
                Table2 {
                    width: w,
                    height: h,
                    channels: n,
                    data,
                }
            })
            .collect();
        Ok(Some(tables))
    }

    /// Record the sky-view pass of `job` (timestamps 0 and 1 when given).
    pub(crate) fn record_sky_view(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        job: &Job,
        timestamps: Option<&wgpu::QuerySet>,
    ) {
        let (Some((x, y, z)), Some(bg)) = (job.sky_view, job.bind_groups.first()) else {
            return;
        };
        let mut cpass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("sky view"),
            timestamp_writes: timestamps.map(|set| wgpu::ComputePassTimestampWrites {
                query_set: set,
                beginning_of_pass_write_index: Some(0),
                end_of_pass_write_index: Some(1),
            }),
        });
        cpass.set_pipeline(&job.pipelines.sky_view);
        cpass.set_bind_group(0, bg, &[]);
        cpass.dispatch_workgroups(x, y, z);
    }

    /// Record the pixels of `job` (timestamps 2 and 3 when given).
    pub(crate) fn record_pixels(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        job: &Job,
        timestamps: Option<&wgpu::QuerySet>,
    ) {
        let mut cpass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("firmament hillaire2020 frame"),
            timestamp_writes: timestamps.map(|set| wgpu::ComputePassTimestampWrites {
                query_set: set,
                beginning_of_pass_write_index: Some(2),
                end_of_pass_write_index: Some(3),
            }),
        });
        cpass.set_pipeline(&job.pipelines.pass.pipeline);
        for (bg, &(x, y)) in job.bind_groups.iter().zip(&job.dispatches) {
            cpass.set_bind_group(0, bg, &[]);
            cpass.dispatch_workgroups(x, y, 1);
        }
    }

    /// Record the frame: the sky-view tables, then the pixels.
    pub(crate) fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        job: &Job,
        timestamps: Option<&wgpu::QuerySet>,
    ) {
        self.record_sky_view(encoder, job, timestamps);
        self.record_pixels(encoder, job, timestamps);
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
        let p = scoped(ctx, "render shader compilation (Hillaire 2020)", || {
            Ok(compile(ctx, Slot::StorageTexture(format), Some(wgsl)))
        })?;
        Ok(cell.get_or_init(|| p))
    }

    /// Validate the settings and inputs, check the device limits, and build the frame's
    /// uniforms and one bind group per band of rows (a texture target is one band).
    pub(crate) fn prepare<'p>(
        &'p self,
        ctx: &GpuContext,
        sky: &GpuHillaire,
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
                "none: Hillaire 2020 has no terrain on the GPU (GpuRenderer draws terrains over the 4D tables; the CPU method takes them)",
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
                        (b, "GpuHillaireRenderer::with_max_band_bytes")
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
        scoped(ctx, "preparing the frame", || {
            let uniform = |label: &str, words: &[u32]| {
                init(
                    device,
                    label,
                    bytemuck::cast_slice(words),
                    crate::passes::UNIFORM_USAGE,
                )
            };
            let light_uniform = uniform("lights", &light_words(sky, lights, inputs.background));
            let coordinates = uniform(
                "sky-view coordinates",
                &sky_view_words(sky, lights, settings),
            );
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
                    (1, t.params.as_entire_binding()),
                    (2, t.data.as_entire_binding()),
                    (3, t.optical_depth.as_entire_binding()),
                    (8, t.config.as_entire_binding()),
                    (9, t.config_data.as_entire_binding()),
                    (10, frame_uniform.as_entire_binding()),
                    (11, sky.view_constants().as_entire_binding()),
                    (12, output),
                    (13, sky.sky_view().as_entire_binding()),
                    (14, light_uniform.as_entire_binding()),
                    (15, coordinates.as_entire_binding()),
                    (16, wgpu::BindingResource::TextureView(shadow)),
                    (20, t.multiple_scattering.as_entire_binding()),
                    (21, t.irradiance.as_entire_binding()),
                    (25, wgpu::BindingResource::TextureView(planet_map)),
                    (26, planet_uniform.as_entire_binding()),
                ];
                let entries: Vec<wgpu::BindGroupEntry> = entries
                    .into_iter()
                    .map(|(binding, resource)| wgpu::BindGroupEntry { binding, resource })
                    .collect();
                bind_groups.push(device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("hillaire2020 frame"),
                    layout: &pipelines.pass.layout,
                    entries: &entries,
                }));
                dispatches.push(workgroups(rows * w, max_dim));
                first += rows;
            }
            let sky_view = constants.inside.then(|| {
                let (sw, sh) = sky.config().sky_view;
                let (x, y) = workgroups(sw * sh * lights.len(), max_dim);
                (x, y, groups(sky.channels()) as u32)
            });
            Ok(Job {
                pipelines,
                bind_groups,
                dispatches,
                sky_view,
            })
        })
    }
}

/// Refuse a frame buffer larger than the device allocates (as the 4D renderer does).
pub(crate) fn check_frame_buffer(
    ctx: &GpuContext,
    settings: &RenderSettings,
) -> Result<(), GpuError> {
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

/// The first `bytes` of `buffer` (usage COPY_SRC) as f32 (waits for the device).
fn read_buffer(
    ctx: &GpuContext,
    buffer: &wgpu::Buffer,
    bytes: u64,
    what: &str,
) -> Result<Vec<f32>, GpuError> {
    let device = ctx.device();
    let staging = scoped(ctx, what, || {
        let mut encoder = device.create_command_encoder(&Default::default());
        let staging = staging_buffer(device, "readback", bytes);
        encoder.copy_buffer_to_buffer(buffer, 0, &staging, 0, bytes);
        ctx.queue().submit([encoder.finish()]);
        Ok(staging)
    })?;
    let during = format!("reading the {what} back");
    let raw = scoped(ctx, &during, || read_back(ctx, &[&staging], &during))?;
    Ok(f32s(&raw[0]))
}

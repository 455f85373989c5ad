//! Frames on the GPU: [`firmament::render::render`] of the clear sky as one compute dispatch,
//! one invocation per pixel (`shaders/render/render.wgsl`: every camera projection, the
//! ground lit by each light and the sky seen through aerial perspective, the sky, views from
//! space, the lights' disks with limb darkening, an optional per-pixel shadowed length,
//! spectral channels to linear sRGB), into a buffer or a storage texture the caller owns.
//!
//! [`GpuRenderer::encode`] records a frame into the caller's command encoder;
//! [`GpuRenderer::read_frame`] reads a frame buffer back as the CPU's [`Frame`] (a separate
//! step), and [`GpuRenderer::render`] does both, so exposure, tone mapping and the image
//! writers apply unchanged. [`GpuRenderer::time_render`] times the dispatch alone.
//!
//! ```no_run
//! use firmament::atmosphere::Atmosphere;
//! use firmament::render::RenderSettings;
//! use firmament::scene::{sun_direction, Camera, Light, Projection};
//! use firmament::sky::bruneton4d::{Bruneton4d, TableConfig, Tables};
//! use firmament::spectrum::Wavelengths;
//! use firmament_gpu::{GpuContext, GpuRenderer, GpuSky};
//!
//! let model = Atmosphere::earth().resolve(&Wavelengths::rgb()).unwrap();
//! let tables = Tables::compute(&model, &TableConfig::default()).unwrap();
//! let sky = Bruneton4d::new(model, tables).unwrap();
//! let ctx = GpuContext::new().unwrap();
//! let gpu_sky = GpuSky::from_sky(&ctx, &sky).unwrap();
//! let renderer = GpuRenderer::new(&ctx).unwrap();
//! let camera = Camera {
//!     projection: Projection::Fisheye,
//!     altitude_m: 2.0,
//!     heading_deg: 0.0,
//!     pitch_deg: 0.0,
//!     roll_deg: 0.0,
//!     fov_deg: 60.0,
//! };
//! let settings = RenderSettings {
//!     camera: &camera,
//!     width: 512,
//!     height: 512,
//!     white_balance: false,
//! };
//! let sun = [Light::sun(&sky.model, sun_direction(80.0, 250.0), true)];
//! let frame = renderer.render(&ctx, &gpu_sky, &sun, &settings).unwrap();
//! let timing = renderer.time_render(&ctx, &gpu_sky, &sun, &settings, 5).unwrap();
//! println!("{:.2} ms ({})", timing.seconds * 1e3, timing.method);
//! # let _ = frame;
//! ```

pub(crate) mod frame;
mod pipelines;
pub mod stars;
pub mod temporal;
mod timing;

use temporal::Extent;
pub use temporal::{Interleave, TemporalFrames};
pub use timing::RenderTiming;

use std::sync::OnceLock;

use firmament::io::ImageRgbF32;
use firmament::render::{Frame, RenderSettings};
use firmament::scene::Light;

use crate::bruneton4d::atmosphere::groups;
use crate::clouds::{no_clouds_words, GpuClouds};
use crate::device::{f32s, read_back, scoped, staging_buffer};
use crate::passes::{init, workgroups, Slot, WORKGROUP};
use crate::planet::{GpuPlanet, NoPlanet};
use crate::terrain::{no_terrain_words, GpuTerrain};
use crate::{GpuContext, GpuError, GpuSky};
use frame::{light_words, slice_words, FrameConstants, MAX_LIGHTS};
use pipelines::{compile, Pipelines};

/// Bytes per pixel of a frame buffer (one `vec4<f32>`: linear sRGB and the mask).
pub const PIXEL_BYTES: u64 = 16;
/// Rows of a band are a multiple of this, so that every band's offset in the output buffer
/// (rows × width × 16 bytes) is a multiple of 256, the largest storage-offset alignment.
pub(crate) const BAND_ROW_ALIGN: usize = 16;
/// Storage buffers the render pass binds: data, five tables, output, slice, terrain, clouds.
const STORAGE_BUFFERS_NEEDED: u32 = 10;

/// Where a frame goes.
#[derive(Clone, Copy, Debug)]
pub enum RenderTarget<'a> {
    /// A storage buffer of width × height × [`PIXEL_BYTES`] bytes (usage STORAGE): per pixel,
    /// rows from the top, linear sRGB with Y in cd/m² and 1 (inside the projection) or 0.
    Buffer(&'a wgpu::Buffer),
    /// A view of a 2D storage texture of the frame's size (usage STORAGE_BINDING, format
    /// `Rgba32Float` or `Rgba16Float`): linear sRGB with Y in cd/m², the mask in alpha.
    Texture(&'a wgpu::TextureView, wgpu::TextureFormat),
}

/// What a frame may take besides the sky and the lights.
#[derive(Clone, Copy, Debug, Default)]
pub struct RenderInputs<'a> {
    /// The shadowed length of each pixel's ray (m; Bruneton & Neyret 2008 eq. 17–18, from
    /// shadow volumes or a shadow map): a 2D `R32Float` texture of the frame's size (usage
    /// TEXTURE_BINDING). Sky rays are in shadow over their first metres, rays to the ground
    /// over their last.
    pub shadow_lengths: Option<&'a wgpu::TextureView>,
    /// A glow from beyond the atmosphere (the night sky's), seen through the air.
    pub background: Option<&'a firmament::scene::sky_lights::Background>,
    /// A terrain on the planet (uploaded for the frame's lights): the frame then renders
    /// `firmament::render::render` of a scene with that terrain (its shadows, light shafts,
    /// ambient occlusion and the change of the air's light it was given), and ignores
    /// `shadow_lengths`.
    pub terrain: Option<&'a GpuTerrain>,
    /// Cloud layers (uploaded for the frame's lights): the frame then renders
    /// `firmament::render::render` of a scene with those clouds and no terrain (the ground
    /// under their shadows and light, the air's shafts through their gaps, the clouds
    /// composited at their mean depth), and ignores `shadow_lengths`. Not with a terrain.
    pub clouds: Option<&'a GpuClouds>,
    /// The planet's surface map ([`GpuPlanet`]): the ground sphere's albedo from it and the
    /// sea's glint, as `firmament::render::render` with the scene's ground set to that
    /// `PlanetSurface`. Every sky method's frame takes it.
    pub planet: Option<&'a GpuPlanet>,
    /// Timestamps written around the frame's compute passes when given (a query set of
    /// at least 4 on a device with `TIMESTAMP_QUERY`): 0 and 1 around the pass of the 4D
    /// and 3D tables' frames; Hillaire 2020's sky-view pass at 0 and 1, its pixels at 2
    /// and 3. A viewer's per-pass times ([`crate::pass_timer::PassTimer`]).
    pub timestamps: Option<&'a wgpu::QuerySet>,
    /// Draw one pixel of each k×k block only, each pixel's depth in alpha (a frame under
    /// clouds or over a terrain, into a buffer in one band): a [`TemporalFrames`] resolves
    /// it.
    pub interleave: Option<Interleave>,
}

/// The render pipelines, compiled once per context (the texture outputs on first use).
pub struct GpuRenderer {
    buffer: Pipelines,
    rgba32: OnceLock<Pipelines>,
    rgba16: OnceLock<Pipelines>,
    /// Binding 1 (the precomputation's pass parameters), unused here.
    unused_params: wgpu::Buffer,
    /// Binding 16 when no shadowed lengths are given (1×1).
    no_shadow_lengths: wgpu::TextureView,
    /// Binding 17 when no terrain is given (one word).
    no_terrain: wgpu::Buffer,
    /// Binding 19 when no clouds are given (one word).
    no_clouds: wgpu::Buffer,
    /// Binding 25 when no planet map is given.
    no_planet: NoPlanet,
    /// Cap on the output bytes one dispatch writes (None: the device's binding limit).
    max_band_bytes: Option<u64>,
}

/// Everything one frame's dispatches need, built and checked before any work is recorded.
pub(crate) struct Job<'p> {
    pipelines: &'p Pipelines,
    /// The pipeline drawing the pixels: `main`, or `main_terrain` over a terrain.
    main: &'p wgpu::ComputePipeline,
    bind_groups: Vec<wgpu::BindGroup>,
    /// Workgroups (x, y) per band.
    dispatches: Vec<(u32, u32)>,
    /// Workgroups (x, y, groups) of the slices (None: observer in space, no slice).
    slice: Option<(u32, u32, u32)>,
}

impl GpuRenderer {
    /// Compile the render pass (buffer output).
    pub fn new(ctx: &GpuContext) -> Result<GpuRenderer, GpuError> {
        let limits = ctx.limits();
        if limits.max_storage_buffers_per_shader_stage < STORAGE_BUFFERS_NEEDED {
            return Err(GpuError::Limit {
                what: "the render pass".into(),
                needed: format!("{STORAGE_BUFFERS_NEEDED} storage buffers"),
                limit: limits.max_storage_buffers_per_shader_stage.to_string(),
                limit_name: "max_storage_buffers_per_shader_stage",
                adapter: ctx.adapter_name().to_string(),
            });
        }
        let device = ctx.device();
        scoped(ctx, "render shader compilation", || {
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
            Ok(GpuRenderer {
                buffer: compile(ctx, Slot::Write, None),
                rgba32: OnceLock::new(),
                rgba16: OnceLock::new(),
                unused_params: init(device, "unused", &[0; 16], crate::passes::UNIFORM_USAGE),
                no_shadow_lengths: texture.create_view(&Default::default()),
                no_terrain: init(device, "no terrain", &[0; 16], wgpu::BufferUsages::STORAGE),
                no_clouds: init(device, "no clouds", &[0; 16], wgpu::BufferUsages::STORAGE),
                no_planet: NoPlanet::new(device),
                max_band_bytes: None,
            })
        })
    }

    /// Draw frames in bands of rows writing at most `bytes` each (16 bytes per pixel; a band
    /// has a multiple of 16 rows, at least 16), one dispatch per band. Frames larger than
    /// one storage binding are banded anyway; a smaller cap shortens each dispatch, for
    /// drivers that reset the device on long ones. Buffer targets only.
    pub fn with_max_band_bytes(mut self, bytes: u64) -> GpuRenderer {
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

    /// Render a frame; the same [`Frame`] as [`firmament::render::render`] of the clear sky
    /// (linear sRGB with Y in cd/m², and the projection mask). Refuses what the CPU refuses,
    /// and frames larger than the device can hold, before submitting anything.
    pub fn render(
        &self,
        ctx: &GpuContext,
        sky: &GpuSky,
        lights: &[Light],
        settings: &RenderSettings,
    ) -> Result<Frame, GpuError> {
        self.render_with(ctx, sky, lights, settings, RenderInputs::default())
    }

    /// [`GpuRenderer::render`] with extra inputs (per-pixel shadowed lengths).
    pub fn render_with(
        &self,
        ctx: &GpuContext,
        sky: &GpuSky,
        lights: &[Light],
        settings: &RenderSettings,
        inputs: RenderInputs,
    ) -> Result<Frame, GpuError> {
        self.check_frame_buffer(ctx, settings)?;
        let output = self.frame_buffer(ctx, settings);
        let device = ctx.device();
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("firmament frame"),
        });
        self.encode(
            ctx,
            &mut encoder,
            sky,
            lights,
            settings,
            RenderTarget::Buffer(&output),
            inputs,
        )?;
        ctx.queue().submit([encoder.finish()]);
        self.read_frame(ctx, &output, settings.width, settings.height)
    }

    /// Record a frame into `encoder` (one compute pass; nothing is submitted). Refuses what
    /// the CPU refuses, more than `MAX_LIGHTS` lights, and frames the device cannot hold.
    pub fn encode(
        &self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        sky: &GpuSky,
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
        let bytes = (width * height) as u64 * PIXEL_BYTES;
        let device = ctx.device();
        let staging = scoped(ctx, "frame rendering", || {
            let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("firmament frame readback"),
            });
            let staging = staging_buffer(device, "frame readback", bytes);
            encoder.copy_buffer_to_buffer(output, 0, &staging, 0, bytes);
            ctx.queue().submit([encoder.finish()]);
            Ok(staging)
        })?;
        let during = "reading the frame back";
        let raw = scoped(ctx, during, || read_back(ctx, &[&staging], during))?;
        Ok(frame_from_pixels(&f32s(&raw[0]), width, height))
    }

    /// Record the frame's dispatches (one compute pass, timestamps at its ends if given).
    pub(crate) fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        job: &Job,
        timestamps: Option<&wgpu::QuerySet>,
    ) {
        self.record_then(encoder, &[job], timestamps, |_| {});
    }

    /// [`GpuRenderer::record`] of `jobs` (frames of one camera and lights: the first's
    /// slices serve them all), then `after`'s dispatches, in one pass (within its
    /// timestamps).
    pub(crate) fn record_then(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        jobs: &[&Job],
        timestamps: Option<&wgpu::QuerySet>,
        after: impl FnOnce(&mut wgpu::ComputePass),
    ) {
        let timestamp_writes = timestamps.map(|set| wgpu::ComputePassTimestampWrites {
            query_set: set,
            beginning_of_pass_write_index: Some(0),
            end_of_pass_write_index: Some(1),
        });
        let mut cpass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("firmament frame"),
            timestamp_writes,
        });
        if let Some(job) = jobs.first() {
            if let (Some((x, y, z)), Some(bg)) = (job.slice, job.bind_groups.first()) {
                cpass.set_pipeline(&job.pipelines.slice);
                cpass.set_bind_group(0, bg, &[]);
                cpass.dispatch_workgroups(x, y, z);
            }
        }
        for job in jobs {
            cpass.set_pipeline(job.main);
            for (bg, &(x, y)) in job.bind_groups.iter().zip(&job.dispatches) {
                cpass.set_bind_group(0, bg, &[]);
                cpass.dispatch_workgroups(x, y, 1);
            }
        }
        after(&mut cpass);
    }

    /// Refuse a frame buffer larger than the device allocates.
    pub(crate) fn check_frame_buffer(
        &self,
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

    /// The pipelines of a target.
    fn pipelines(&self, ctx: &GpuContext, target: &RenderTarget) -> Result<&Pipelines, GpuError> {
        match target {
            RenderTarget::Buffer(_) => Ok(&self.buffer),
            RenderTarget::Texture(_, format) => {
                let (cell, wgsl) = match format {
                    wgpu::TextureFormat::Rgba32Float => (&self.rgba32, "rgba32float"),
                    wgpu::TextureFormat::Rgba16Float => (&self.rgba16, "rgba16float"),
                    other => {
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
                let p = scoped(ctx, "render shader compilation", || {
                    Ok(compile(ctx, Slot::StorageTexture(*format), Some(wgsl)))
                })?;
                Ok(cell.get_or_init(|| p))
            }
        }
    }

    /// Validate the settings, check the device limits, and build the frame's uniforms and
    /// one bind group per band of rows (a texture target is one band).
    pub(crate) fn prepare<'p>(
        &'p self,
        ctx: &GpuContext,
        sky: &GpuSky,
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
        let (w, h) = (settings.width, settings.height);
        let limits = ctx.limits();
        let adapter = ctx.adapter_name().to_string();
        let limit = |what: String, needed: String, limit: String, limit_name| GpuError::Limit {
            what,
            needed,
            limit,
            limit_name,
            adapter: adapter.clone(),
        };
        // Bands of rows, each within one storage binding (a texture takes the frame at once).
        let row_bytes = w as u64 * PIXEL_BYTES;
        let band_rows = match target {
            RenderTarget::Texture(..) => h,
            RenderTarget::Buffer(_) => {
                let (binding_limit, binding_limit_name) = match self.max_band_bytes {
                    Some(b) if b < limits.max_storage_buffer_binding_size => {
                        (b, "GpuRenderer::with_max_band_bytes")
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
                        binding_limit_name,
                    ));
                }
                rows
            }
        };
        let Extent {
            rows: (row_start, row_end),
            columns,
            step,
        } = Extent::of(&inputs, &target, (w, h), band_rows)?;
        let max_dim = limits.max_compute_workgroups_per_dimension;
        let (_, y) = workgroups(band_rows * w, max_dim);
        if y > max_dim {
            return Err(limit(
                format!("a {w}×{h} frame"),
                format!("{} invocations per dispatch", band_rows * w),
                format!("{max_dim}² workgroups of {WORKGROUP}"),
                "max_compute_workgroups_per_dimension",
            ));
        }
        let pipelines = self.pipelines(ctx, &target)?;
        let main = pipelines.main_for(ctx, inputs.terrain, inputs.clouds)?;
        let cloud_words = match inputs.clouds {
            Some(c) => c.uniform_words(sky, lights, settings)?,
            None => no_clouds_words(),
        };
        let terrain_words = match inputs.terrain {
            Some(t) => t.uniform_words(sky, lights, settings)?,
            None => no_terrain_words(),
        };
        let mut constants =
            FrameConstants::new(sky, lights.len(), inputs.shadow_lengths.is_some(), settings);
        constants.interleave = inputs.interleave.map_or(0, |il| il.word());
        constants.interleave_columns = inputs.interleave.map_or(0, |il| il.columns_word());
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
            let terrain_uniform = uniform("terrain", &terrain_words);
            let terrain_data = inputs.terrain.map_or(&self.no_terrain, |t| t.data());
            let cloud_uniform = uniform("clouds", &cloud_words);
            let cloud_data = inputs.clouds.map_or(&self.no_clouds, |c| c.data());
            let slice_uniform = uniform("slice coordinates", &slice_words(sky, lights, settings));
            let shadow = inputs.shadow_lengths.unwrap_or(&self.no_shadow_lengths);
            let (planet_map, planet_uniform) = self.no_planet.or(device, inputs.planet);
            let tables = sky.tables();
            let mut bind_groups = Vec::new();
            let mut dispatches = Vec::new();
            let mut first = row_start;
            while first < row_end {
                let rows = band_rows.min(row_end - first);
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
                    (0, tables.atmosphere.as_entire_binding()),
                    (1, self.unused_params.as_entire_binding()),
                    (2, tables.data.as_entire_binding()),
                    (3, tables.transmittance.as_entire_binding()),
                    (4, tables.irradiance.as_entire_binding()),
                    (5, tables.single_rayleigh.as_entire_binding()),
                    (6, tables.single_mie.as_entire_binding()),
                    (7, tables.multiple.as_entire_binding()),
                    (10, frame_uniform.as_entire_binding()),
                    (11, sky.view_constants().as_entire_binding()),
                    (12, output),
                    (13, sky.slice().as_entire_binding()),
                    (14, light_uniform.as_entire_binding()),
                    (15, slice_uniform.as_entire_binding()),
                    (16, wgpu::BindingResource::TextureView(shadow)),
                    (17, terrain_data.as_entire_binding()),
                    (18, terrain_uniform.as_entire_binding()),
                    (19, cloud_data.as_entire_binding()),
                    (20, cloud_uniform.as_entire_binding()),
                    (25, wgpu::BindingResource::TextureView(planet_map)),
                    (26, planet_uniform.as_entire_binding()),
                ];
                let entries: Vec<wgpu::BindGroupEntry> = entries
                    .into_iter()
                    .map(|(binding, resource)| wgpu::BindGroupEntry { binding, resource })
                    .collect();
                bind_groups.push(device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("frame"),
                    layout: &pipelines.pass.layout,
                    entries: &entries,
                }));
                let invocations = rows.div_ceil(step) * columns.div_ceil(step);
                dispatches.push(workgroups(invocations, max_dim));
                first += rows;
            }
            let slice = constants.inside.then(|| {
                let entries = sky.sizes.scattering_mu * sky.sizes.scattering_nu;
                let (x, y) = workgroups(entries * lights.len(), max_dim);
                (x, y, groups(sky.channels) as u32)
            });
            Ok(Job {
                pipelines,
                main,
                bind_groups,
                dispatches,
                slice,
            })
        })
    }
}

/// A [`Frame`] from the frame buffer's pixels (4 floats each).
pub(crate) fn frame_from_pixels(values: &[f32], width: usize, height: usize) -> Frame {
    let mut image = ImageRgbF32::new(width, height);
    let mut mask = vec![false; width * height];
    for ((p, m), v) in image
        .data
        .iter_mut()
        .zip(&mut mask)
        .zip(values.chunks_exact(4))
    {
        *p = [v[0], v[1], v[2]];
        *m = v[3] > 0.5;
    }
    Frame { image, mask }
}

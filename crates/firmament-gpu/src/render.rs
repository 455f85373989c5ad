//! Frames on the GPU: [`firmament::render::render`] as one compute dispatch, one invocation
//! per pixel (`shaders/render.wgsl`: every camera projection, the ground lit by sun and sky
//! seen through aerial perspective, the sky, views from space, the sun's disk with limb
//! darkening, spectral channels to linear sRGB). The result is the CPU's [`Frame`], so
//! exposure, tone mapping and the image writers apply unchanged.
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

use std::time::Instant;

use firmament::atmosphere::Model;
use firmament::io::ImageRgbF32;
use firmament::math::sphere::safe_sqrt;
use firmament::render::{Frame, RenderSettings};
use firmament::scene::light::{disk_solid_angle_weighted, limb_darkening_coefficients};
use firmament::scene::{Light, Projection};
use firmament::sky::bruneton4d::params::{scattering_uvwz, Radii};
use firmament::sky::bruneton4d::{Bruneton4d, MieStorage, TableConfig, TableSizes};
use firmament::spectrum::ColourMatrix;

use crate::lut::atmosphere::{self, groups, ScatteringGroups, GROUP};
use crate::lut::passes::{init, workgroups, Pass, Slot};
use crate::lut::{check_buffers, scoped, DeviceTables, Precomputer};
use crate::{GpuContext, GpuError};

/// vec4 per channel group in the per-channel data (`CHANNEL_STRIDE` in render.wgsl).
const CHANNEL_STRIDE: usize = 10;
/// Bytes per output pixel (one vec4<f32>: linear sRGB and the mask).
const PIXEL_BYTES: u64 = 16;
/// Rows of a band are a multiple of this, so that every band's offset in the output buffer
/// (rows × width × 16 bytes) is a multiple of 256, the largest storage-offset alignment.
const BAND_ROW_ALIGN: usize = 16;
/// Storage buffers the render pass binds: data, five tables, output, camera slice (the
/// per-channel data is a uniform buffer, which keeps this within WebGPU's default of 8).
const STORAGE_BUFFERS_NEEDED: u32 = 8;
/// The most wavelengths the CPU renderer handles (its per-pixel buffers hold 64).
const MAX_CHANNELS: usize = 64;
/// vec4 in the per-channel uniform (`channel_data` in render.wgsl: array<vec4<f32>, 160>),
/// room for [`MAX_CHANNELS`].
const CHANNEL_DATA_VEC4: usize = MAX_CHANNELS / GROUP * CHANNEL_STRIDE;
/// Values per camera-slice entry and channel group: single scattering, multiple scattering,
/// single Mie (`slice_table` in render.wgsl).
const SLICE_TABLES: usize = 3;

/// A sky ready to render on the GPU: the atmosphere parameters, the five tables and the
/// per-channel constants (colour matrix, sun-disk radiance with limb darkening, red-only
/// Mie ratios) in device buffers.
pub struct GpuSky {
    atmosphere: wgpu::Buffer,
    data: wgpu::Buffer,
    channel_data: wgpu::Buffer,
    /// Optical depth τ = −ln T to the top (`Tables::optical_depth`).
    transmittance: wgpu::Buffer,
    irradiance: wgpu::Buffer,
    /// Single molecular scattering (`Tables::scattering`).
    scattering: wgpu::Buffer,
    single_mie: wgpu::Buffer,
    /// Multiple scattering, radiance (`Tables::multiple`).
    multiple: wgpu::Buffer,
    /// The camera slice of the scattering tables, rewritten by every frame (render.wgsl).
    slice: wgpu::Buffer,
    /// Single Mie layout: 0 all channels, 1 red only with one vec4 per texel, 2 red only in
    /// the full layout (`mie_layout` in render.wgsl).
    mie_layout: u32,
    channels: usize,
    radii: Radii,
    sizes: TableSizes,
    sun_angular_radius_rad: f64,
    /// White-balance factors (render::white_balance with the option on).
    balance: [f64; 3],
}

impl std::fmt::Debug for GpuSky {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("GpuSky")
            .field("channels", &self.channels)
            .field("sizes", &self.sizes)
            .finish()
    }
}

/// Bytes of the camera slice: [single; multiple; single Mie] per (μ, ν) entry and channel
/// group.
fn slice_bytes(sizes: &TableSizes, groups: usize) -> u64 {
    (sizes.scattering_mu * sizes.scattering_nu * SLICE_TABLES * groups * GROUP * 4) as u64
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
    /// Refuses more wavelengths than the CPU renderer handles and tables larger than the
    /// device binds.
    pub fn from_sky(ctx: &GpuContext, sky: &Bruneton4d) -> Result<GpuSky, GpuError> {
        let model = &sky.model;
        let tables = &sky.tables;
        let n = sky.channels();
        if n > MAX_CHANNELS {
            return Err(firmament::Error::invalid(
                "wavelengths",
                n,
                format!("at most {MAX_CHANNELS} wavelengths for rendering"),
            )
            .into());
        }
        let g = groups(n);
        let red_only = tables.config.mie == MieStorage::RedOnly;
        let transmittance = pad_channels(&tables.optical_depth.data, n, g);
        let irradiance = pad_channels(&tables.irradiance.data, n, g);
        let scattering = pad_channels(&tables.single_rayleigh.data, n, g);
        let multiple = pad_channels(&tables.multiple.data, n, g);
        let single_mie = if red_only {
            pad_channels(&tables.single_mie.data, 1, 1)
        } else {
            pad_channels(&tables.single_mie.data, n, g)
        };
        let bytes = |v: &[f32]| (v.len() * 4) as u64;
        let sizes = tables.config.sizes;
        check_buffers(
            ctx,
            &[
                ("scattering table", bytes(&scattering)),
                ("multiple scattering table", bytes(&multiple)),
                ("camera slice", slice_bytes(&sizes, g)),
                ("single Mie table", bytes(&single_mie)),
                ("transmittance table", bytes(&transmittance)),
                ("irradiance table", bytes(&irradiance)),
            ],
        )?;

        let groups_info = ScatteringGroups::new(model);
        let packed = atmosphere::pack(model, &sizes, &groups_info);
        let device = ctx.device();
        scoped(ctx, "uploading the tables", || {
            let storage = wgpu::BufferUsages::STORAGE;
            let f = |label: &str, v: &[f32]| init(device, label, bytemuck::cast_slice(v), storage);
            let buffers = DeviceTables {
                atmosphere: init(
                    device,
                    "atmosphere",
                    bytemuck::cast_slice(&packed.uniform),
                    wgpu::BufferUsages::UNIFORM,
                ),
                data: f("atmosphere data", &packed.data),
                transmittance: f("transmittance", &transmittance),
                irradiance: f("irradiance", &irradiance),
                scattering: f("scattering", &scattering),
                single_mie: f("single mie", &single_mie),
                multiple: f("multiple scattering", &multiple),
                row_sums: crate::lut::passes::storage(device, "unused", 16),
            };
            Ok(GpuSky::assemble(
                ctx,
                model,
                sizes,
                &tables.mie_ratio,
                u32::from(red_only),
                buffers,
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
        let s = config.sizes;
        check_buffers(ctx, &[("camera slice", slice_bytes(&s, groups(n)))])?;
        let buffers = precomputer.run_on_device(ctx, model, config)?;
        let mie_ratio = ScatteringGroups::new(model).mie_ratio();
        // The device keeps single Mie in full even when red-only: channel 0 of each texel.
        let mie_layout = if config.mie == MieStorage::RedOnly {
            2
        } else {
            0
        };
        scoped(ctx, "preparing the GPU tables", || {
            Ok(GpuSky::assemble(
                ctx, model, s, &mie_ratio, mie_layout, buffers,
            ))
        })
    }

    /// A sky from tables on the device: adds the per-channel constants and the slice.
    fn assemble(
        ctx: &GpuContext,
        model: &Model,
        sizes: TableSizes,
        mie_ratio: &[f64],
        mie_layout: u32,
        buffers: DeviceTables,
    ) -> GpuSky {
        let n = model.channels();
        let g = groups(n);
        // Per channel: sRGB rows of the colour matrix, centre radiance × limb-darkening
        // coefficients, red-only Mie ratio; lanes of channel k in group k/4.
        let wavelengths = model.wavelengths.nm();
        let colour = ColourMatrix::new(wavelengths);
        // The uniform's full size (the shader declares a fixed-size array).
        let mut channel_data = vec![0.0f32; CHANNEL_DATA_VEC4 * 4];
        for k in 0..n {
            let (group, lane) = (k / GROUP, k % GROUP);
            let mut set = |row: usize, v: f64| {
                channel_data[(group * CHANNEL_STRIDE + row) * 4 + lane] = v as f32;
            };
            let mut unit = vec![0.0f64; n];
            unit[k] = 1.0;
            let rgb = colour.to_srgb(&unit);
            for (c, v) in rgb.iter().enumerate() {
                set(c, *v);
            }
            // Sky::solar_radiance_centre: the irradiance over the limb-darkening-weighted
            // solid angle of the disk.
            let centre = model.solar_irradiance[k]
                / disk_solid_angle_weighted(
                    model.sun_angular_radius_rad,
                    model.limb_darkening,
                    wavelengths[k],
                );
            let a = limb_darkening_coefficients(model.limb_darkening, wavelengths[k]);
            for (j, a_j) in a.iter().enumerate() {
                set(3 + j, centre * a_j);
            }
            set(9, mie_ratio.get(k).copied().unwrap_or(0.0));
        }
        let device = ctx.device();
        GpuSky {
            atmosphere: buffers.atmosphere,
            data: buffers.data,
            channel_data: init(
                device,
                "channel data",
                bytemuck::cast_slice(&channel_data),
                wgpu::BufferUsages::UNIFORM,
            ),
            transmittance: buffers.transmittance,
            irradiance: buffers.irradiance,
            scattering: buffers.scattering,
            single_mie: buffers.single_mie,
            multiple: buffers.multiple,
            slice: crate::lut::passes::storage(device, "camera slice", slice_bytes(&sizes, g)),
            mie_layout,
            channels: n,
            radii: Radii {
                bottom: model.bottom_radius_m,
                top: model.top_radius_m,
                mu_s_min: model.mu_s_min,
            },
            sizes,
            sun_angular_radius_rad: model.sun_angular_radius_rad,
            balance: colour.white_balance(&model.solar_irradiance, true),
        }
    }

    /// Number of wavelengths.
    pub fn channels(&self) -> usize {
        self.channels
    }
}

/// The render pipeline, compiled once per context.
pub struct GpuRenderer {
    pass: Pass,
    /// The per-frame camera slice (entry point `camera_slice` of the same shader).
    slice: wgpu::ComputePipeline,
    /// Binding 1 of functions.wgsl (the precomputation's pass parameters), unused here.
    unused_params: wgpu::Buffer,
    /// Cap on the output bytes one dispatch writes (None: the device's binding limit).
    max_band_bytes: Option<u64>,
}

/// The median time of the render dispatch alone (no upload, no readback) over some frames.
#[derive(Clone, Copy, Debug)]
pub struct RenderTiming {
    /// Median seconds per frame.
    pub seconds: f64,
    /// Frames timed (after one untimed warm-up frame).
    pub frames: usize,
    /// How it was measured: "timestamp queries" (GPU clock, the compute pass alone) or
    /// "wall clock (submit + wait)" where the device has no timestamp queries.
    pub method: &'static str,
}

/// Everything one frame's dispatches need, built and checked before any work is submitted.
struct Job {
    output: wgpu::Buffer,
    bind_groups: Vec<wgpu::BindGroup>,
    /// Workgroups (x, y) per band.
    dispatches: Vec<(u32, u32)>,
    /// Workgroups (x, y, groups) of the camera slice (None: camera in space, no slice).
    slice: Option<(u32, u32, u32)>,
    width: usize,
    height: usize,
}

impl GpuRenderer {
    /// Compile the render pass.
    pub fn new(ctx: &GpuContext) -> Result<GpuRenderer, GpuError> {
        use Slot::{Read, Uniform, Write};
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
            let pass = Pass::new(
                device,
                "render",
                include_str!("../shaders/render.wgsl"),
                &[
                    (3, Read),
                    (4, Read),
                    (5, Read),
                    (6, Read),
                    (7, Read),
                    (10, Uniform),
                    (11, Uniform),
                    (12, Write),
                    (13, Write),
                ],
            );
            Ok(GpuRenderer {
                slice: pass.entry_point(device, "camera_slice"),
                pass,
                unused_params: init(device, "unused", &[0; 16], wgpu::BufferUsages::UNIFORM),
                max_band_bytes: None,
            })
        })
    }

    /// Draw frames in bands of rows writing at most `bytes` each (16 bytes per pixel; a band
    /// has a multiple of 16 rows, at least 16), one dispatch per band. Frames larger than
    /// one storage binding are banded anyway; a smaller cap shortens each dispatch, for
    /// drivers that reset the device on long ones.
    pub fn with_max_band_bytes(mut self, bytes: u64) -> GpuRenderer {
        self.max_band_bytes = Some(bytes);
        self
    }

    /// Render a frame; the same [`Frame`] as [`firmament::render::render`] (linear sRGB with
    /// Y in cd/m², and the projection mask). Refuses what the CPU refuses, and frames larger
    /// than the device can hold, before submitting anything.
    pub fn render(
        &self,
        ctx: &GpuContext,
        sky: &GpuSky,
        lights: &[Light],
        settings: &RenderSettings,
    ) -> Result<Frame, GpuError> {
        let job = self.prepare(ctx, sky, lights, settings)?;
        let bytes = job.output.size();
        let staging = scoped(ctx, "frame rendering", || {
            let device = ctx.device();
            let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("firmament frame"),
            });
            self.encode(&mut encoder, &job, None);
            let staging = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("frame readback"),
                size: bytes,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            encoder.copy_buffer_to_buffer(&job.output, 0, &staging, 0, bytes);
            ctx.queue().submit([encoder.finish()]);
            Ok(staging)
        })?;
        let raw = scoped(ctx, "reading the frame back", || {
            map_read(ctx, &staging, "reading the frame back")
        })?;
        let mut image = ImageRgbF32::new(job.width, job.height);
        let mut mask = vec![false; job.width * job.height];
        let f = |b: &[u8]| f32::from_le_bytes([b[0], b[1], b[2], b[3]]);
        for ((p, m), v) in image
            .data
            .iter_mut()
            .zip(&mut mask)
            .zip(raw.chunks_exact(16))
        {
            *p = [f(&v[0..4]), f(&v[4..8]), f(&v[8..12])];
            *m = f(&v[12..16]) > 0.5;
        }
        Ok(Frame { image, mask })
    }

    /// Render `frames` frames (after one warm-up) and return the median time of the render
    /// dispatch alone, without upload or readback: from timestamp queries around the compute
    /// pass where the device has them, else the wall time of submit + wait.
    pub fn time_render(
        &self,
        ctx: &GpuContext,
        sky: &GpuSky,
        lights: &[Light],
        settings: &RenderSettings,
        frames: usize,
    ) -> Result<RenderTiming, GpuError> {
        let frames = frames.max(1);
        let job = self.prepare(ctx, sky, lights, settings)?;
        let device = ctx.device();
        let timestamps = ctx.supports_timestamps();
        let wait = |during: &str| {
            device
                .poll(wgpu::PollType::wait_indefinitely())
                .map(|_| ())
                .map_err(|e| GpuError::Execution {
                    during: during.to_string(),
                    reason: e.to_string(),
                })
        };
        let mut times = Vec::with_capacity(frames);
        scoped(ctx, "timing frames", || {
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
                self.encode(&mut encoder, &job, queries.as_ref().map(|q| &q.0));
                let readback = queries.as_ref().map(|(set, resolve)| {
                    encoder.resolve_query_set(set, 0..2, resolve, 0);
                    let b = device.create_buffer(&wgpu::BufferDescriptor {
                        label: Some("timestamp readback"),
                        size: 16,
                        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                        mapped_at_creation: false,
                    });
                    encoder.copy_buffer_to_buffer(resolve, 0, &b, 0, 16);
                    b
                });
                let start = Instant::now();
                ctx.queue().submit([encoder.finish()]);
                wait("timing frames")?;
                let wall = start.elapsed().as_secs_f64();
                let seconds = match readback {
                    Some(b) => {
                        let raw = map_read(ctx, &b, "reading timestamps")?;
                        let tick = |b: &[u8]| {
                            u64::from_le_bytes([b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7]])
                        };
                        tick(&raw[8..16]).saturating_sub(tick(&raw[0..8])) as f64
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

    /// Record the frame's dispatches (one compute pass, timestamps at its ends if given).
    fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        job: &Job,
        timestamps: Option<&wgpu::QuerySet>,
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
        if let (Some((x, y, z)), Some(bg)) = (job.slice, job.bind_groups.first()) {
            cpass.set_pipeline(&self.slice);
            cpass.set_bind_group(0, bg, &[]);
            cpass.dispatch_workgroups(x, y, z);
        }
        cpass.set_pipeline(&self.pass.pipeline);
        for (bg, &(x, y)) in job.bind_groups.iter().zip(&job.dispatches) {
            cpass.set_bind_group(0, bg, &[]);
            cpass.dispatch_workgroups(x, y, 1);
        }
    }

    /// Validate the settings, check the device limits, and build the frame constants, the
    /// output buffer and one bind group per band of rows.
    fn prepare(
        &self,
        ctx: &GpuContext,
        sky: &GpuSky,
        lights: &[Light],
        settings: &RenderSettings,
    ) -> Result<Job, GpuError> {
        settings.validate()?;
        let sun = lights.first().ok_or_else(|| {
            firmament::Error::invalid("lights", "none", "at least one light (the sun)")
        })?;
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
        let total = w as u64 * h as u64 * PIXEL_BYTES;
        if total > limits.max_buffer_size {
            return Err(limit(
                format!("a {w}×{h} frame"),
                format!("{total} bytes ({PIXEL_BYTES} per pixel)"),
                format!("{} bytes", limits.max_buffer_size),
                "max_buffer_size",
            ));
        }
        // Bands of rows, each within one storage binding.
        let row_bytes = w as u64 * PIXEL_BYTES;
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
        let band_rows = if fit >= h {
            h
        } else {
            fit / BAND_ROW_ALIGN * BAND_ROW_ALIGN
        };
        if band_rows == 0 {
            return Err(limit(
                format!("a frame {w} pixels wide"),
                format!("{} bytes per {BAND_ROW_ALIGN} rows", row_bytes * 16),
                format!("{binding_limit} bytes"),
                binding_limit_name,
            ));
        }
        let max_dim = limits.max_compute_workgroups_per_dimension;
        let (_, y) = workgroups(band_rows * w, max_dim);
        if y > max_dim {
            return Err(limit(
                format!("a {w}×{h} frame"),
                format!("{} invocations per dispatch", band_rows * w),
                format!("{max_dim}² workgroups of {}", crate::lut::passes::WORKGROUP),
                "max_compute_workgroups_per_dimension",
            ));
        }

        let constants = FrameConstants::new(sky, sun, settings);
        let device = ctx.device();
        scoped(ctx, "preparing the frame", || {
            let output = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("frame"),
                size: total,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            let mut bind_groups = Vec::new();
            let mut dispatches = Vec::new();
            let mut first = 0;
            while first < h {
                let rows = band_rows.min(h - first);
                let uniform = init(
                    device,
                    "frame constants",
                    bytemuck::cast_slice(&constants.words(first, rows)),
                    wgpu::BufferUsages::UNIFORM,
                );
                fn whole(b: &wgpu::Buffer) -> wgpu::BindingResource<'_> {
                    b.as_entire_binding()
                }
                let entries = [
                    (0, whole(&sky.atmosphere)),
                    (1, whole(&self.unused_params)),
                    (2, whole(&sky.data)),
                    (3, whole(&sky.transmittance)),
                    (4, whole(&sky.irradiance)),
                    (5, whole(&sky.scattering)),
                    (6, whole(&sky.single_mie)),
                    (7, whole(&sky.multiple)),
                    (10, whole(&uniform)),
                    (11, whole(&sky.channel_data)),
                    (13, whole(&sky.slice)),
                    (
                        12,
                        wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                            buffer: &output,
                            offset: first as u64 * row_bytes,
                            size: wgpu::BufferSize::new(rows as u64 * row_bytes),
                        }),
                    ),
                ];
                let entries: Vec<wgpu::BindGroupEntry> = entries
                    .into_iter()
                    .map(|(binding, resource)| wgpu::BindGroupEntry { binding, resource })
                    .collect();
                bind_groups.push(device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("frame"),
                    layout: &self.pass.layout,
                    entries: &entries,
                }));
                dispatches.push(workgroups(rows * w, max_dim));
                first += rows;
            }
            let slice = (constants.inside == 1).then(|| {
                let (x, y) = workgroups(sky.sizes.scattering_mu * sky.sizes.scattering_nu, max_dim);
                (x, y, groups(sky.channels) as u32)
            });
            Ok(Job {
                output,
                bind_groups,
                dispatches,
                slice,
                width: w,
                height: h,
            })
        })
    }
}

/// The `Frame` uniform of render.wgsl, computed in f64 and rounded once.
struct FrameConstants {
    width: u32,
    height: u32,
    projection: u32,
    inside: u32,
    sun_disk: u32,
    mie_layout: u32,
    forward: firmament::math::Vec3,
    right: firmament::math::Vec3,
    up: firmament::math::Vec3,
    sun: firmament::math::Vec3,
    sin_sun_radius: f64,
    balance: [f64; 3],
    camera_r_km: f64,
    camera_rho_km: f64,
    camera_above_top_km: f64,
    tan_half_fov: f64,
    slice_u_mu_s: f64,
    slice_u_r: f64,
}

impl FrameConstants {
    fn new(sky: &GpuSky, light: &Light, settings: &RenderSettings) -> FrameConstants {
        let camera = settings.camera;
        let (bottom, top) = (sky.radii.bottom, sky.radii.top);
        let r = bottom + camera.altitude_m;
        let sun = light.direction;
        let prepared = camera.prepare(bottom, settings.width, settings.height);
        let (forward, right, up) = prepared.basis();
        let inside = r <= top;
        // render::camera_slice: (r, μ_s) of the camera, μ_s = sun·origin/r = sun.z.
        let uvwz = if inside {
            scattering_uvwz(
                &sky.radii,
                &sky.sizes,
                r,
                0.0,
                sun[2].clamp(-1.0, 1.0),
                0.0,
                false,
            )
        } else {
            [0.0; 4]
        };
        FrameConstants {
            width: settings.width as u32,
            height: settings.height as u32,
            projection: match camera.projection {
                Projection::Perspective => 0,
                Projection::Fisheye => 1,
                Projection::Equirect => 2,
                Projection::Cubemap => 3,
                Projection::Orbit => 4,
            },
            inside: u32::from(inside),
            sun_disk: u32::from(light.visible_disk),
            mie_layout: sky.mie_layout,
            forward,
            right,
            up,
            sun,
            sin_sun_radius: sky.sun_angular_radius_rad.sin(),
            balance: if settings.white_balance {
                sky.balance
            } else {
                [1.0; 3]
            },
            camera_r_km: r * 1e-3,
            camera_rho_km: safe_sqrt(r * r - bottom * bottom) * 1e-3,
            camera_above_top_km: (r - top) * 1e-3,
            tan_half_fov: prepared.tan_half_fov(),
            slice_u_mu_s: uvwz[1],
            slice_u_r: uvwz[3],
        }
    }

    /// The uniform's words for the band of `rows` rows from `first_row`.
    fn words(&self, first_row: usize, rows: usize) -> Vec<u32> {
        let f = |x: f64| (x as f32).to_bits();
        let v4 = |v: firmament::math::Vec3, w: f64| [f(v[0]), f(v[1]), f(v[2]), f(w)];
        let mut out = vec![
            self.width,
            self.height,
            first_row as u32,
            rows as u32,
            self.projection,
            self.inside,
            self.sun_disk,
            self.mie_layout,
        ];
        out.extend(v4(self.forward, 0.0));
        out.extend(v4(self.right, 0.0));
        out.extend(v4(self.up, 0.0));
        out.extend(v4(self.sun, self.sin_sun_radius));
        out.extend(v4(firmament::math::Vec3::from_array(self.balance), 1.0));
        out.extend([
            f(self.camera_r_km),
            f(self.camera_rho_km),
            f(self.camera_above_top_km),
            f(self.tan_half_fov),
            f(self.slice_u_mu_s),
            f(self.slice_u_r),
            0,
            0,
        ]);
        out
    }
}

/// Map `buffer` (MAP_READ), wait for the device, and copy its bytes out.
fn map_read(ctx: &GpuContext, buffer: &wgpu::Buffer, during: &str) -> Result<Vec<u8>, GpuError> {
    let failure = |reason: String| GpuError::Execution {
        during: during.to_string(),
        reason,
    };
    let (tx, rx) = std::sync::mpsc::channel();
    buffer.slice(..).map_async(wgpu::MapMode::Read, move |r| {
        let _ = tx.send(r);
    });
    ctx.device()
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| failure(e.to_string()))?;
    rx.recv()
        .map_err(|_| failure("the device never finished mapping the buffer".into()))?
        .map_err(|e| failure(e.to_string()))?;
    let view = buffer
        .slice(..)
        .get_mapped_range()
        .map_err(|e| failure(e.to_string()))?;
    let out = view.to_vec();
    drop(view);
    buffer.unmap();
    Ok(out)
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

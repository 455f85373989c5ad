//! Hillaire 2020's atmosphere-wide tables on the GPU, pass for pass as
//! [`Hillaire2020::compute`](firmament::sky::hillaire2020::Hillaire2020::compute) builds them
//! on the CPU: the optical depth to the top (the 4D tables' transmittance pass,
//! `shaders/bruneton4d/precompute/transmittance.wgsl`, compiled with Hillaire's segment
//! count), the multiple-scattering field Ψ_ms with f_ms
//! (`shaders/hillaire2020/multiple_scattering.wgsl`: a gather of every ray, then the
//! projection per coefficient; with `multiple_scattering_orders` > 2 the same for each
//! higher order through the previous one's field, then the tail of the orders beyond, all
//! on the device: the tail's table-wide means are a one-workgroup reduction, nothing is read
//! back between orders) and the sky irradiance (`irradiance.wgsl`: a gather of every
//! (texel, direction) ray, then the sum per texel). All passes go into one
//! command buffer; each stage of [`STAGES`] is one compute pass (every order inside
//! "multiple scattering"), timed by timestamp queries where the device has them
//! ([`super::timing`]).
//!
//! Tables live in storage buffers of `vec4<f32>` in the CPU's texel order with the channels
//! in groups of four (channel group k of texel i at i·groups + k; Ψ_ms coefficient c at
//! (i·coefficients + c)·groups + k), so that [`GpuHillaireTables::read_back`] gives the CPU's
//! [`Table2`]s, compared texel by texel in `tests/hillaire2020_parity.rs`.

use std::sync::{Arc, Mutex};

use firmament::atmosphere::Model;
use firmament::sky::bruneton4d::Table2;
use firmament::sky::hillaire2020::harmonics::coefficient_count;
use firmament::sky::hillaire2020::multiple_scattering::HIGHER_ORDERS_DEGREE;
use firmament::sky::hillaire2020::{HillaireConfig, F_MS_LIMIT};

use super::config::{self, gather_split, higher_orders_directions};
use crate::bruneton4d::atmosphere::{groups, GROUP};
use crate::device::{check_buffers, scoped};
use crate::passes::{dispatch, init, storage, workgroups, Pass, Slot};
use crate::shader::{
    hillaire2020_pass_source, hillaire2020_passes, hillaire2020_transmittance_source,
};
use crate::{GpuContext, GpuError};

/// The tables on the device (and what their shaders read besides): storage buffers of
/// `vec4<f32>` in the CPU's texel order, channel groups of four. The render shader binds
/// them at the slots `shaders/hillaire2020/view.wgsl` lists.
pub struct GpuHillaireTables {
    /// The `Atmosphere` uniform (binding 0), with Hillaire's transmittance size.
    pub atmosphere: wgpu::Buffer,
    /// Per-wavelength data, constituents, layers, tabulated phases (binding 2).
    pub data: wgpu::Buffer,
    /// The `Hillaire` uniform: sizes and counts (binding 8).
    pub config: wgpu::Buffer,
    /// Gather rules, irradiance directions, phase moments (binding 9).
    pub config_data: wgpu::Buffer,
    /// Optical depth τ to the top (binding 3; `Hillaire2020::optical_depth`).
    pub optical_depth: wgpu::Buffer,
    /// Ψ_ms per unit light irradiance, coefficient-major per texel (binding 20;
    /// `MultipleScattering::table`).
    pub multiple_scattering: wgpu::Buffer,
    /// The sky's irradiance on a horizontal surface per unit light irradiance (binding 21;
    /// `Hillaire2020::irradiance`).
    pub irradiance: wgpu::Buffer,
    /// f_ms per texel and channel group (read back for the refusal).
    pub(crate) f_ms: wgpu::Buffer,
    /// Binding 1 (the 4D passes' parameters), unused by Hillaire's shaders.
    pub(crate) params: wgpu::Buffer,
}

/// The tables read back into the CPU's layout.
#[derive(Clone, Debug)]
pub struct HillaireTables {
    /// Optical depth to the top, τ(r, μ) (`Hillaire2020::optical_depth`).
    pub optical_depth: Table2,
    /// Ψ_ms: (μ_s, altitude) texels of coefficients × channels values, coefficient-major
    /// (`MultipleScattering::table`).
    pub multiple_scattering: Table2,
    /// The sky irradiance (`Hillaire2020::irradiance`).
    pub irradiance: Table2,
    /// The largest f_ms over texels and channels (`Hillaire2020::max_f_ms`).
    pub max_f_ms: f64,
    /// Where it was met: altitude (m), μ_s, channel (`MultipleScattering::max_at`).
    pub max_at: (f64, f64, usize),
}

/// Compiled pipelines, reusable across builds on one context (the transmittance pass per
/// segment count, compiled on first use).
pub struct HillairePrecomputer {
    transmittance: Mutex<Vec<(usize, Arc<Pass>)>>,
    multiple_scattering: Pass,
    gather: wgpu::ComputePipeline,
    gather_next: wgpu::ComputePipeline,
    project_next: wgpu::ComputePipeline,
    tail: wgpu::ComputePipeline,
    irradiance: Pass,
    irradiance_gather: wgpu::ComputePipeline,
}

/// One build's buffers and bind groups, recorded pass by pass.
pub(crate) struct Build {
    pub(crate) tables: GpuHillaireTables,
    transmittance: Arc<Pass>,
    /// The transmittance's, the first order's and the irradiance's.
    bind_groups: [wgpu::BindGroup; 3],
    /// Orders 2 … n − 1 of the multiple-scattering field, each through the previous one's.
    higher_orders: Vec<wgpu::BindGroup>,
    /// The tail (the last order's field and the one before).
    tail: wgpu::BindGroup,
    /// Invocations of the transmittance, gather, projection and irradiance dispatches, then
    /// of a higher order's gather and projection, then of the irradiance's gather.
    invocations: [usize; 7],
    groups: usize,
    max_dim: u32,
}

/// The passes of a build, in order ([`super::timing`] times each).
pub(crate) const STAGES: [&str; 3] = ["transmittance", "multiple scattering", "irradiance"];

impl HillairePrecomputer {
    /// Compile the passes (the transmittance with the default configuration's segments).
    pub fn new(ctx: &GpuContext) -> Result<HillairePrecomputer, GpuError> {
        use Slot::{Read, Uniform, Write};
        let d = ctx.device();
        let precomputer = scoped(ctx, "shader compilation (Hillaire 2020)", || {
            let multiple_scattering = Pass::new(
                ctx,
                "hillaire2020 multiple scattering",
                hillaire2020_pass_source(hillaire2020_passes::MULTIPLE_SCATTERING),
                &[
                    (3, Read),
                    (7, Write),
                    (8, Uniform),
                    (9, Read),
                    (20, Read),
                    (22, Write),
                    (23, Write),
                    (24, Write),
                ],
            );
            let irradiance = Pass::new(
                ctx,
                "hillaire2020 irradiance",
                hillaire2020_pass_source(hillaire2020_passes::IRRADIANCE),
                &[
                    (3, Read),
                    (7, Write),
                    (8, Uniform),
                    (9, Read),
                    (20, Read),
                    (22, Write),
                ],
            );
            Ok(HillairePrecomputer {
                transmittance: Mutex::new(Vec::new()),
                irradiance_gather: irradiance.entry_point(d, "gather"),
                gather: multiple_scattering.entry_point(d, "gather"),
                gather_next: multiple_scattering.entry_point(d, "gather_next"),
                project_next: multiple_scattering.entry_point(d, "project_next"),
                tail: multiple_scattering.entry_point(d, "tail"),
                multiple_scattering,
                irradiance,
            })
        })?;
        precomputer.transmittance_pass(ctx, HillaireConfig::default().transmittance_segments)?;
        Ok(precomputer)
    }

    /// The transmittance pass for `segments` segments per ray.
    fn transmittance_pass(&self, ctx: &GpuContext, segments: usize) -> Result<Arc<Pass>, GpuError> {
        let mut cache = self.transmittance.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((_, p)) = cache.iter().find(|(s, _)| *s == segments) {
            return Ok(p.clone());
        }
        let pass = scoped(
            ctx,
            "shader compilation (Hillaire 2020 transmittance)",
            || {
                Ok(Arc::new(Pass::new(
                    ctx,
                    "hillaire2020 transmittance",
                    hillaire2020_transmittance_source(segments),
                    &[(7, Slot::Write)],
                )))
            },
        )?;
        cache.push((segments, pass.clone()));
        Ok(pass)
    }

    /// Build the tables for `model` and leave them on the device (submitted, not waited
    /// for, not checked against f_ms: [`crate::GpuHillaire::compute`] is what refuses).
    /// Refuses what the CPU refuses and what the shaders cannot take before any work.
    pub fn run_on_device(
        &self,
        ctx: &GpuContext,
        model: &Model,
        config: &HillaireConfig,
    ) -> Result<GpuHillaireTables, GpuError> {
        let build = self.prepare(ctx, model, config)?;
        scoped(ctx, "Hillaire 2020 tables", || {
            let mut encoder =
                ctx.device()
                    .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                        label: Some("firmament hillaire2020 tables"),
                    });
            for stage in 0..STAGES.len() {
                self.record(&mut encoder, &build, stage, None);
            }
            ctx.queue().submit([encoder.finish()]);
            Ok(())
        })?;
        Ok(build.tables)
    }

    /// Build and read back the tables (the CPU's layout), refusing f_ms above the limit.
    pub fn run(
        &self,
        ctx: &GpuContext,
        model: &Model,
        config: &HillaireConfig,
    ) -> Result<HillaireTables, GpuError> {
        let tables = self.run_on_device(ctx, model, config)?;
        let read = tables.read_back(ctx, model, config)?;
        check_f_ms(model, read.max_f_ms, read.max_at)?;
        Ok(read)
    }

    /// Validate, check the device's limits, allocate the buffers and bind them.
    pub(crate) fn prepare(
        &self,
        ctx: &GpuContext,
        model: &Model,
        config: &HillaireConfig,
    ) -> Result<Build, GpuError> {
        config.validate()?;
        let n = model.channels();
        firmament::spectrum::check_channels(n, "Hillaire 2020")?;
        config::check_phases(model)?;
        let n_groups = groups(n);
        let vec4 = (GROUP * 4) as u64;
        let t_texels = config.transmittance.0 * config.transmittance.1;
        let ms_texels = config.multiple_scattering.0 * config.multiple_scattering.1;
        let e_texels = config.irradiance.0 * config.irradiance.1;
        let e_rays = e_texels * config.irradiance_directions;
        let degree = config.multiple_scattering_model.degree();
        let coefficients = coefficient_count(degree);
        let next_coefficients = coefficient_count(degree.min(HIGHER_ORDERS_DEGREE));
        let (below, above) = gather_split(config.multiple_scattering_directions.0);
        let directions = (below + above) * config.multiple_scattering_directions.1;
        let next = higher_orders_directions(config.multiple_scattering_directions);
        let next_directions = {
            let (below, above) = gather_split(next.0);
            (below + above) * next.1
        };
        let orders = config.multiple_scattering_orders;
        let bytes = |texels: usize| (texels * n_groups) as u64 * vec4;
        // An order's field and, after it, the bottom row's upward irradiance
        // (multiple_scattering.wgsl): the first order's, then the higher orders'.
        let order_bytes = [
            bytes(ms_texels * coefficients + config.multiple_scattering.0),
            bytes(ms_texels * next_coefficients + config.multiple_scattering.0),
        ];
        check_buffers(
            ctx,
            &[
                (
                    "multiple-scattering rays",
                    bytes(2 * ms_texels * directions),
                ),
                ("transmittance table", bytes(t_texels)),
                ("multiple-scattering table", bytes(ms_texels * coefficients)),
                ("multiple-scattering order", order_bytes[0]),
                ("irradiance table", bytes(e_texels)),
                ("irradiance rays", bytes(e_rays)),
            ],
        )?;
        let max_dim = ctx.limits().max_compute_workgroups_per_dimension;
        let largest = (ms_texels * directions).max(e_rays);
        if workgroups(largest, max_dim).1 > max_dim {
            return Err(GpuError::Limit {
                what: "the multiple-scattering or irradiance gather".into(),
                needed: format!("{largest} invocations"),
                limit: format!("{max_dim}² workgroups of {}", crate::passes::WORKGROUP),
                limit_name: "max_compute_workgroups_per_dimension",
                adapter: ctx.adapter_name().to_string(),
            });
        }
        let transmittance = self.transmittance_pass(ctx, config.transmittance_segments)?;
        let packed = config::pack_atmosphere(model, config);
        let hillaire = config::pack(model, config);
        let device = ctx.device();
        scoped(ctx, "preparing the Hillaire 2020 tables", || {
            let uniform = crate::passes::UNIFORM_USAGE;
            let read_only = wgpu::BufferUsages::STORAGE;
            let tables = GpuHillaireTables {
                atmosphere: init(
                    device,
                    "atmosphere",
                    bytemuck::cast_slice(&packed.uniform),
                    uniform,
                ),
                data: init(
                    device,
                    "atmosphere data",
                    bytemuck::cast_slice(&packed.data),
                    read_only,
                ),
                config: init(
                    device,
                    "hillaire2020",
                    bytemuck::cast_slice(&hillaire.uniform),
                    uniform,
                ),
                config_data: init(
                    device,
                    "hillaire2020 data",
                    bytemuck::cast_slice(&hillaire.data),
                    read_only,
                ),
                optical_depth: storage(device, "optical depth", bytes(t_texels)),
                multiple_scattering: storage(
                    device,
                    "multiple scattering",
                    bytes(ms_texels * coefficients),
                ),
                irradiance: storage(device, "sky irradiance", bytes(e_texels)),
                f_ms: storage(device, "f_ms", bytes(ms_texels)),
                params: init(device, "unused", &[0; 16], uniform),
            };
            let t = &tables;
            let common = [&t.atmosphere, &t.params, &t.data];
            let gathered = storage(
                device,
                "multiple-scattering rays",
                bytes(2 * ms_texels * directions),
            );
            let no_field = storage(device, "no multiple scattering", 16);
            let irradiance_rays = storage(device, "irradiance rays", bytes(e_rays));
            // Order j's field: the first order's buffer for odd j, the higher orders' for even
            // j (each order reads the other one).
            let fields = [
                storage(device, "multiple-scattering order", order_bytes[0]),
                storage(
                    device,
                    "multiple-scattering order",
                    if orders > 2 { order_bytes[1] } else { 16 },
                ),
            ];
            let field = |order: usize| match order {
                0 => &no_field,
                j => &fields[1 - j % 2],
            };
            let uniforms = hillaire
                .higher_orders
                .iter()
                .map(|words| {
                    init(
                        device,
                        "hillaire2020 higher orders",
                        bytemuck::cast_slice(words),
                        uniform,
                    )
                })
                .collect::<Vec<_>>();
            // The uniform of the pass that gathers order j (and of the tail after it).
            let uniform_of = |order: usize| match order {
                1 => &t.config,
                2 => &uniforms[0],
                _ => &uniforms[1],
            };
            let ms_bind = |order: usize, previous: &wgpu::Buffer| {
                self.multiple_scattering.bind(
                    device,
                    common,
                    &[
                        &t.optical_depth,
                        &t.multiple_scattering,
                        uniform_of(order),
                        &t.config_data,
                        previous,
                        &gathered,
                        &t.f_ms,
                        field(order),
                    ],
                )
            };
            let higher_orders = (2..orders).map(|j| ms_bind(j, field(j - 1))).collect();
            let tail = ms_bind(orders - 1, field(orders - 2));
            let bind_groups = [
                transmittance.bind(device, common, &[&t.optical_depth]),
                ms_bind(1, &no_field),
                self.irradiance.bind(
                    device,
                    common,
                    &[
                        &t.optical_depth,
                        &t.irradiance,
                        &t.config,
                        &t.config_data,
                        &t.multiple_scattering,
                        &irradiance_rays,
                    ],
                ),
            ];
            Ok(Build {
                tables,
                transmittance,
                bind_groups,
                higher_orders,
                tail,
                invocations: [
                    t_texels,
                    ms_texels * directions,
                    ms_texels * coefficients,
                    e_texels,
                    ms_texels * next_directions,
                    ms_texels * next_coefficients,
                    e_rays,
                ],
                groups: n_groups,
                max_dim,
            })
        })
    }

    /// Record pass `stage` of [`STAGES`] as one compute pass, with timestamps at its ends
    /// (queries 2·stage and 2·stage + 1) when given.
    pub(crate) fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        build: &Build,
        stage: usize,
        timestamps: Option<&wgpu::QuerySet>,
    ) {
        let timestamp_writes = timestamps.map(|set| wgpu::ComputePassTimestampWrites {
            query_set: set,
            beginning_of_pass_write_index: Some(2 * stage as u32),
            end_of_pass_write_index: Some(2 * stage as u32 + 1),
        });
        let mut cpass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some(STAGES[stage]),
            timestamp_writes,
        });
        let (g, max_dim, inv) = (build.groups, build.max_dim, &build.invocations);
        match stage {
            0 => dispatch(
                &mut cpass,
                &build.transmittance,
                &build.bind_groups[0],
                inv[0],
                g,
                max_dim,
            ),
            1 => {
                let mut run = |pipeline: &wgpu::ComputePipeline, bind_group, invocations| {
                    let (x, y) = workgroups(invocations, max_dim);
                    cpass.set_pipeline(pipeline);
                    cpass.set_bind_group(0, bind_group, &[]);
                    cpass.dispatch_workgroups(x, y, g as u32);
                };
                run(&self.gather, &build.bind_groups[1], inv[1]);
                run(
                    &self.multiple_scattering.pipeline,
                    &build.bind_groups[1],
                    inv[2],
                );
                for bind_group in &build.higher_orders {
                    run(&self.gather_next, bind_group, inv[4]);
                    run(&self.project_next, bind_group, inv[5]);
                }
                // The tail: one workgroup per channel group.
                cpass.set_pipeline(&self.tail);
                cpass.set_bind_group(0, &build.tail, &[]);
                cpass.dispatch_workgroups(1, 1, g as u32);
            }
            _ => {
                let (x, y) = workgroups(inv[6], max_dim);
                cpass.set_pipeline(&self.irradiance_gather);
                cpass.set_bind_group(0, &build.bind_groups[2], &[]);
                cpass.dispatch_workgroups(x, y, g as u32);
                dispatch(
                    &mut cpass,
                    &self.irradiance,
                    &build.bind_groups[2],
                    inv[3],
                    g,
                    max_dim,
                );
            }
        }
    }
}

/// Refuse f_ms above [`F_MS_LIMIT`] as `Hillaire2020::compute` does (the same message).
pub(crate) fn check_f_ms(
    model: &Model,
    max_f_ms: f64,
    max_at: (f64, f64, usize),
) -> Result<(), GpuError> {
    if max_f_ms <= F_MS_LIMIT {
        return Ok(());
    }
    let (altitude, _, k) = max_at;
    Err(firmament::Error::invalid(
        "method",
        "hillaire2020",
        format!(
            "this atmosphere scatters too much for Hillaire 2020's multiple-scattering series: \
             f_ms = {max_f_ms:.3} at {:.0} nm, {altitude:.0} m (accepted up to {F_MS_LIMIT}: beyond it the sky \
             reads 10–50 % low, docs/accuracy.md); the 4D tables (bruneton4d) or the reference take it",
            model.wavelengths.nm()[k],
        ),
    )
    .into())
}

//! The precomputation of Bruneton & Neyret 2008 Algorithm 4.1 on the GPU, pass for pass as
//! `firmament::lut::precompute` does it on the CPU: transmittance, direct irradiance, single
//! scattering (Rayleigh and Mie apart), then for each order n ≥ 2 the scattering density ΔJ
//! (the same spherical convolution in azimuth as the CPU: the incident field's cosine series
//! convolved with the phase functions' harmonics), the indirect irradiance ΔE and the multiple
//! scattering ΔS, summed over the orders into its own table (`Tables::multiple`, radiance).
//! All passes go into one command buffer; only the final tables come back.
//!
//! Tables live in storage buffers (not textures) with the CPU's texel order and the channels
//! in groups of four (one vec4 per group): filtering is done in the shaders with exact f32
//! weights, as `firmament::lut::table` does, so CPU and GPU compare texel by texel.

pub mod atmosphere;
pub(crate) mod passes;

use firmament::atmosphere::Model;
use firmament::sky::bruneton4d::{MieStorage, Table2, Table4, TableConfig, Tables};

use crate::{GpuContext, GpuError};
use atmosphere::{groups, ScatteringGroups, GROUP};
use passes::{dispatch, init, storage, Pass, Slot};

/// Incident zeniths, azimuth harmonics of the scattering density (lut::precompute).
const DENSITY_THETA: usize = 32;
const HARMONICS: usize = 16;
/// Storage buffers bound at once by the widest pass (the density field).
const STORAGE_BUFFERS_NEEDED: u32 = 6;

/// The tables as the precomputation leaves them on the device: channel groups padded to
/// vec4, single Mie in full even for [`MieStorage::RedOnly`] (the host keeps channel 0), and
/// the packed atmosphere they were computed with.
pub(crate) struct DeviceTables {
    pub atmosphere: wgpu::Buffer,
    pub data: wgpu::Buffer,
    /// Optical depth τ = −ln T to the top (what the lookups read; `Tables::optical_depth`).
    pub transmittance: wgpu::Buffer,
    pub irradiance: wgpu::Buffer,
    /// Single molecular scattering (`Tables::scattering`).
    pub scattering: wgpu::Buffer,
    pub single_mie: wgpu::Buffer,
    /// Orders ≥ 2 summed, radiance (`Tables::multiple`; zeros for one order).
    pub multiple: wgpu::Buffer,
    pub row_sums: wgpu::Buffer,
}

/// Compiled pipelines, reusable across precomputations on one context.
pub struct Precomputer {
    transmittance: Pass,
    direct_irradiance: Pass,
    single_scattering: Pass,
    phase_kernels: Pass,
    density_field: Pass,
    scattering_density: Pass,
    indirect_irradiance: Pass,
    multiple_scattering: Pass,
    order_sums: Pass,
    order_tail_factors: Pass,
    order_tail: Pass,
}

/// Precompute every table for `model` on the GPU; the result has the CPU's layout
/// ([`Tables::compute`]).
pub fn precompute(
    ctx: &GpuContext,
    model: &Model,
    config: &TableConfig,
) -> Result<Tables, GpuError> {
    let p = Precomputer::new(ctx)?;
    p.run(ctx, model, config)
}

/// Run `f` inside validation, out-of-memory and internal error scopes; the first error
/// reported (or reported to the uncaptured handler, or a device loss) becomes `Err`.
pub(crate) fn scoped<T>(
    ctx: &GpuContext,
    during: &str,
    f: impl FnOnce() -> Result<T, GpuError>,
) -> Result<T, GpuError> {
    let device = ctx.device();
    let internal = device.push_error_scope(wgpu::ErrorFilter::Internal);
    let oom = device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
    let validation = device.push_error_scope(wgpu::ErrorFilter::Validation);
    let result = f();
    let errors = [
        pollster::block_on(validation.pop()),
        pollster::block_on(oom.pop()),
        pollster::block_on(internal.pop()),
    ];
    let execution = |reason: String| GpuError::Execution {
        during: during.to_string(),
        reason,
    };
    if let Some(e) = errors.into_iter().flatten().next() {
        return Err(execution(e.to_string()));
    }
    if let Some(reason) = ctx.take_reported_errors() {
        return Err(execution(reason));
    }
    result
}

impl Precomputer {
    /// Compile the passes.
    pub fn new(ctx: &GpuContext) -> Result<Precomputer, GpuError> {
        use Slot::{Read, Write};
        let d = ctx.device();
        scoped(ctx, "shader compilation", || {
            Ok(Precomputer {
                transmittance: Pass::new(
                    d,
                    "transmittance",
                    include_str!("../../shaders/transmittance.wgsl"),
                    &[(7, Write)],
                ),
                direct_irradiance: Pass::new(
                    d,
                    "direct_irradiance",
                    include_str!("../../shaders/direct_irradiance.wgsl"),
                    &[(3, Read), (7, Write), (8, Write)],
                ),
                single_scattering: Pass::new(
                    d,
                    "single_scattering",
                    include_str!("../../shaders/single_scattering.wgsl"),
                    &[(3, Read), (7, Write), (8, Write)],
                ),
                phase_kernels: Pass::new(
                    d,
                    "phase_kernels",
                    include_str!("../../shaders/phase_kernels.wgsl"),
                    &[(7, Write)],
                ),
                density_field: Pass::new(
                    d,
                    "scattering_density_field",
                    include_str!("../../shaders/scattering_density_field.wgsl"),
                    &[(3, Read), (4, Read), (5, Read), (6, Read), (7, Write)],
                ),
                scattering_density: Pass::new(
                    d,
                    "scattering_density",
                    include_str!("../../shaders/scattering_density.wgsl"),
                    &[(7, Read), (8, Read), (9, Write)],
                ),
                indirect_irradiance: Pass::new(
                    d,
                    "indirect_irradiance",
                    include_str!("../../shaders/indirect_irradiance.wgsl"),
                    &[(5, Read), (6, Read), (7, Write), (8, Write)],
                ),
                multiple_scattering: Pass::new(
                    d,
                    "multiple_scattering",
                    include_str!("../../shaders/multiple_scattering.wgsl"),
                    &[(3, Read), (5, Read), (7, Write), (8, Write)],
                ),
                order_sums: Pass::new(
                    d,
                    "order_sums",
                    include_str!("../../shaders/order_sums.wgsl"),
                    &[(5, Read), (6, Read), (7, Write)],
                ),
                order_tail_factors: Pass::new(
                    d,
                    "order_tail_factors",
                    include_str!("../../shaders/order_tail_factors.wgsl"),
                    &[(5, Read), (7, Write)],
                ),
                order_tail: Pass::new(
                    d,
                    "order_tail",
                    include_str!("../../shaders/order_tail.wgsl"),
                    &[(4, Read), (5, Read), (6, Read), (7, Write), (8, Write)],
                ),
            })
        })
    }

    /// Precompute every table for `model` with these pipelines.
    pub fn run(
        &self,
        ctx: &GpuContext,
        model: &Model,
        config: &TableConfig,
    ) -> Result<Tables, GpuError> {
        let tables = self.run_on_device(ctx, model, config)?;
        let n = model.channels();
        let s = config.sizes;
        let g = groups(n);
        let orders = config.orders;
        let t_texels = s.transmittance_mu * s.transmittance_r;
        let e_texels = s.irradiance_mu_s * s.irradiance_r;
        let s_texels = s.scattering_r * s.scattering_mu * s.scattering_mu_s * s.scattering_nu;
        let rows = s.scattering_r * s.scattering_mu;
        let groups_info = ScatteringGroups::new(model);
        let device = ctx.device();
        let staging = scoped(ctx, "table precomputation", || {
            let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("firmament tables readback"),
            });
            let sources = [
                &tables.transmittance,
                &tables.irradiance,
                &tables.scattering,
                &tables.single_mie,
                &tables.multiple,
                &tables.row_sums,
            ];
            let staging: Vec<wgpu::Buffer> = sources
                .iter()
                .map(|src| {
                    let b = device.create_buffer(&wgpu::BufferDescriptor {
                        label: Some("readback"),
                        size: src.size(),
                        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                        mapped_at_creation: false,
                    });
                    encoder.copy_buffer_to_buffer(src, 0, &b, 0, src.size());
                    b
                })
                .collect();
            ctx.queue().submit([encoder.finish()]);
            Ok(staging)
        })?;
        let values = scoped(ctx, "reading the tables back", || read_back(ctx, &staging))?;
        let [t_data, e_data, s_data, m_data, multiple_data, rows_data] =
            <[Vec<f32>; 6]>::try_from(values).expect("six buffers");
        let unpad = |v: &[f32], texels: usize| -> Vec<f32> {
            let mut out = Vec::with_capacity(texels * n);
            for t in 0..texels {
                out.extend_from_slice(&v[t * g * GROUP..t * g * GROUP + n]);
            }
            out
        };
        let optical_depth = Table2 {
            width: s.transmittance_mu,
            height: s.transmittance_r,
            channels: n,
            data: unpad(&t_data, t_texels),
        };
        let irradiance = Table2 {
            width: s.irradiance_mu_s,
            height: s.irradiance_r,
            channels: n,
            data: unpad(&e_data, e_texels),
        };
        let table4 = |data: Vec<f32>, channels: usize| Table4 {
            nr: s.scattering_r,
            nmu: s.scattering_mu,
            nmu_s: s.scattering_mu_s,
            nnu: s.scattering_nu,
            channels,
            data,
        };
        let scattering = table4(unpad(&s_data, s_texels), n);
        let single_mie = match config.mie {
            MieStorage::Separate => table4(unpad(&m_data, s_texels), n),
            MieStorage::RedOnly => {
                table4((0..s_texels).map(|t| m_data[t * g * GROUP]).collect(), 1)
            }
        };
        let order_means = (0..orders)
            .map(|o| {
                let mut sum = vec![0.0f64; n];
                for row in 0..rows {
                    let base = ((o * rows + row) * g) * GROUP;
                    for (k, acc) in sum.iter_mut().enumerate() {
                        *acc += rows_data[base + k] as f64;
                    }
                }
                sum.iter().map(|v| v / s_texels as f64).collect()
            })
            .collect();
        Ok(Tables {
            config: *config,
            wavelengths_nm: model.wavelengths.nm().to_vec(),
            atmosphere_hash: model.hash,
            transmittance: optical_depth.transmittance_of_optical_depth(),
            optical_depth,
            irradiance,
            single_rayleigh: scattering,
            single_mie,
            order_means,
            mie_ratio: groups_info.mie_ratio(),
            multiple: table4(unpad(&multiple_data, s_texels), n),
        })
    }

    /// Precompute every table for `model` and leave them on the device (submitted, not
    /// waited for): the buffers [`crate::GpuSky::precompute`] renders from.
    pub(crate) fn run_on_device(
        &self,
        ctx: &GpuContext,
        model: &Model,
        config: &TableConfig,
    ) -> Result<DeviceTables, GpuError> {
        config.validate()?;
        let n = model.channels();
        if n > 64 {
            return Err(firmament::Error::invalid(
                "wavelengths",
                n,
                "at most 64 wavelengths for the precomputed tables",
            )
            .into());
        }
        let s = config.sizes;
        let g = groups(n);
        let orders = config.orders;
        let t_texels = s.transmittance_mu * s.transmittance_r;
        let e_texels = s.irradiance_mu_s * s.irradiance_r;
        let s_texels = s.scattering_r * s.scattering_mu * s.scattering_mu_s * s.scattering_nu;
        let rows = s.scattering_r * s.scattering_mu;
        let vec4 = (GROUP * 4) as u64;
        let bytes_t = (t_texels * g) as u64 * vec4;
        let bytes_e = (e_texels * g) as u64 * vec4;
        let bytes_s = (s_texels * g) as u64 * vec4;
        let bytes_kernels = (rows * DENSITY_THETA * 2 * HARMONICS * 4) as u64;
        let bytes_coefficients =
            (s.scattering_r * s.scattering_mu_s * DENSITY_THETA * HARMONICS * g) as u64 * vec4;
        let bytes_rows = (orders * rows * g) as u64 * vec4;
        self.check_limits(
            ctx,
            &[
                ("scattering table", bytes_s),
                ("transmittance table", bytes_t),
                ("phase harmonics", bytes_kernels),
                ("scattering density harmonics", bytes_coefficients),
                ("order sums", bytes_rows),
            ],
            s_texels,
        )?;

        let groups_info = ScatteringGroups::new(model);
        let packed = atmosphere::pack(model, &s, &groups_info);
        let max_dim = ctx.limits().max_compute_workgroups_per_dimension;
        let device = ctx.device();

        scoped(ctx, "table precomputation", || {
            let uniform = wgpu::BufferUsages::UNIFORM;
            let atm = init(
                device,
                "atmosphere",
                bytemuck::cast_slice(&packed.uniform),
                uniform,
            );
            let data = init(
                device,
                "atmosphere data",
                bytemuck::cast_slice(&packed.data),
                wgpu::BufferUsages::STORAGE,
            );
            // Pass parameters per order: mode 0 (single scattering) up to order 2, then ΔS.
            let params: Vec<wgpu::Buffer> = (0..=orders.max(1))
                .map(|o| {
                    init(
                        device,
                        "pass parameters",
                        bytemuck::cast_slice(&[u32::from(o > 2), o as u32, 0, 0]),
                        uniform,
                    )
                })
                .collect();
            let common = |o: usize| [&atm, &params[o], &data];

            let transmittance = storage(device, "transmittance", bytes_t);
            let delta_irradiance = storage(device, "delta irradiance", bytes_e);
            let irradiance = storage(device, "irradiance", bytes_e);
            let rayleigh = storage(device, "single rayleigh", bytes_s);
            let mie = storage(device, "single mie", bytes_s);
            // Zero-initialised (wgpu clears new buffers): the sum over orders ≥ 2 starts
            // empty and stays so for one order.
            let multiple = storage(device, "multiple scattering", bytes_s);
            let row_sums = storage(device, "order sums", bytes_rows);
            let order_passes = orders >= 2;
            let (kernels, coefficients, density, delta_multiple) = if order_passes {
                (
                    storage(device, "phase harmonics", bytes_kernels),
                    storage(device, "density harmonics", bytes_coefficients),
                    storage(device, "scattering density", bytes_s),
                    storage(device, "delta multiple scattering", bytes_s),
                )
            } else {
                let empty = || storage(device, "unused", 16);
                (empty(), empty(), empty(), empty())
            };

            let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("firmament tables"),
            });
            {
                let mut cpass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some("firmament tables"),
                    timestamp_writes: None,
                });
                let bg = self
                    .transmittance
                    .bind(device, common(1), &[&transmittance]);
                dispatch(&mut cpass, &self.transmittance, &bg, t_texels, g, max_dim);
                let bg = self.direct_irradiance.bind(
                    device,
                    common(1),
                    &[&transmittance, &delta_irradiance, &irradiance],
                );
                dispatch(
                    &mut cpass,
                    &self.direct_irradiance,
                    &bg,
                    e_texels,
                    g,
                    max_dim,
                );
                let bg = self.single_scattering.bind(
                    device,
                    common(1),
                    &[&transmittance, &rayleigh, &mie],
                );
                dispatch(
                    &mut cpass,
                    &self.single_scattering,
                    &bg,
                    s_texels,
                    g,
                    max_dim,
                );
                let bg = self
                    .order_sums
                    .bind(device, common(1), &[&rayleigh, &mie, &row_sums]);
                dispatch(&mut cpass, &self.order_sums, &bg, rows, g, max_dim);
                if order_passes {
                    let bg = self.phase_kernels.bind(device, common(1), &[&kernels]);
                    dispatch(
                        &mut cpass,
                        &self.phase_kernels,
                        &bg,
                        rows * DENSITY_THETA * 2,
                        1,
                        max_dim,
                    );
                }
                for order in 2..=orders {
                    let (a, b) = if order == 2 {
                        (&rayleigh, &mie)
                    } else {
                        (&delta_multiple, &delta_multiple)
                    };
                    let bg = self.density_field.bind(
                        device,
                        common(order),
                        &[&transmittance, &delta_irradiance, a, b, &coefficients],
                    );
                    dispatch(
                        &mut cpass,
                        &self.density_field,
                        &bg,
                        s.scattering_r * s.scattering_mu_s * DENSITY_THETA,
                        g,
                        max_dim,
                    );
                    let bg = self.scattering_density.bind(
                        device,
                        common(order),
                        &[&kernels, &coefficients, &density],
                    );
                    dispatch(
                        &mut cpass,
                        &self.scattering_density,
                        &bg,
                        rows * s.scattering_mu_s,
                        g,
                        max_dim,
                    );
                    let bg = self.indirect_irradiance.bind(
                        device,
                        common(order),
                        &[a, b, &delta_irradiance, &irradiance],
                    );
                    dispatch(
                        &mut cpass,
                        &self.indirect_irradiance,
                        &bg,
                        e_texels,
                        g,
                        max_dim,
                    );
                    let bg = self.multiple_scattering.bind(
                        device,
                        common(order),
                        &[&transmittance, &density, &delta_multiple, &multiple],
                    );
                    dispatch(
                        &mut cpass,
                        &self.multiple_scattering,
                        &bg,
                        s_texels,
                        g,
                        max_dim,
                    );
                    let bg = self.order_sums.bind(
                        device,
                        common(order),
                        &[&delta_multiple, &delta_multiple, &row_sums],
                    );
                    dispatch(&mut cpass, &self.order_sums, &bg, rows, g, max_dim);
                }
                if config.order_tail && orders >= 3 {
                    let factors = storage(device, "order tail factors", g as u64 * vec4);
                    let bg = self.order_tail_factors.bind(
                        device,
                        common(orders),
                        &[&row_sums, &factors],
                    );
                    dispatch(&mut cpass, &self.order_tail_factors, &bg, 1, g, max_dim);
                    let bg = self.order_tail.bind(
                        device,
                        common(orders),
                        &[
                            &delta_irradiance,
                            &delta_multiple,
                            &factors,
                            &multiple,
                            &irradiance,
                        ],
                    );
                    dispatch(
                        &mut cpass,
                        &self.order_tail,
                        &bg,
                        s_texels.max(e_texels),
                        g,
                        max_dim,
                    );
                }
            }
            ctx.queue().submit([encoder.finish()]);
            Ok(DeviceTables {
                atmosphere: atm,
                data,
                transmittance,
                irradiance,
                scattering: rayleigh,
                single_mie: mie,
                multiple,
                row_sums,
            })
        })
    }

    /// Refuse tables the device cannot hold, before allocating anything.
    fn check_limits(
        &self,
        ctx: &GpuContext,
        buffers: &[(&str, u64)],
        largest_dispatch: usize,
    ) -> Result<(), GpuError> {
        check_buffers(ctx, buffers)?;
        let limits = ctx.limits();
        let adapter = ctx.adapter_name().to_string();
        let max_dim = limits.max_compute_workgroups_per_dimension;
        let (_, y) = passes::workgroups(largest_dispatch, max_dim);
        if y > max_dim {
            return Err(GpuError::Limit {
                what: "the scattering table".into(),
                needed: format!("{largest_dispatch} invocations"),
                limit: format!("{max_dim}² workgroups of {}", passes::WORKGROUP),
                limit_name: "max_compute_workgroups_per_dimension",
                adapter,
            });
        }
        if limits.max_storage_buffers_per_shader_stage < STORAGE_BUFFERS_NEEDED {
            return Err(GpuError::Limit {
                what: "the scattering density pass".into(),
                needed: format!("{STORAGE_BUFFERS_NEEDED} storage buffers"),
                limit: limits.max_storage_buffers_per_shader_stage.to_string(),
                limit_name: "max_storage_buffers_per_shader_stage",
                adapter,
            });
        }
        Ok(())
    }
}

/// Refuse storage buffers larger than the device binds or allocates, before allocating
/// anything: (what, bytes) each.
pub(crate) fn check_buffers(ctx: &GpuContext, buffers: &[(&str, u64)]) -> Result<(), GpuError> {
    let limits = ctx.limits();
    for &(what, bytes) in buffers {
        for (limit, name) in [
            (
                limits.max_storage_buffer_binding_size,
                "max_storage_buffer_binding_size",
            ),
            (limits.max_buffer_size, "max_buffer_size"),
        ] {
            if bytes > limit {
                return Err(GpuError::Limit {
                    what: format!("the {what}"),
                    needed: format!("{bytes} bytes"),
                    limit: format!("{limit} bytes"),
                    limit_name: name,
                    adapter: ctx.adapter_name().to_string(),
                });
            }
        }
    }
    Ok(())
}

/// Map the staging buffers, wait for the device, and copy their contents out as f32.
pub(crate) fn read_back(
    ctx: &GpuContext,
    staging: &[wgpu::Buffer],
) -> Result<Vec<Vec<f32>>, GpuError> {
    let (tx, rx) = std::sync::mpsc::channel();
    for (i, b) in staging.iter().enumerate() {
        let tx = tx.clone();
        b.slice(..).map_async(wgpu::MapMode::Read, move |r| {
            let _ = tx.send((i, r));
        });
    }
    drop(tx);
    let failure = |reason: String| GpuError::Execution {
        during: "reading the tables back".into(),
        reason,
    };
    ctx.device()
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| failure(e.to_string()))?;
    for _ in 0..staging.len() {
        let (_, r) = rx
            .recv()
            .map_err(|_| failure("the device never finished mapping the tables".into()))?;
        r.map_err(|e| failure(e.to_string()))?;
    }
    let mut out = Vec::with_capacity(staging.len());
    for b in staging {
        let view = b
            .slice(..)
            .get_mapped_range()
            .map_err(|e| failure(e.to_string()))?;
        out.push(
            view.chunks_exact(4)
                .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
                .collect(),
        );
        drop(view);
        b.unmap();
    }
    Ok(out)
}

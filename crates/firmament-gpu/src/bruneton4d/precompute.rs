//! The precomputation of Bruneton & Neyret 2008 Algorithm 4.1 on the GPU, pass for pass as
//! `firmament::sky::bruneton4d::precompute` does it on the CPU (each pass's WGSL file,
//! `shaders/bruneton4d/precompute/`, is named like the CPU pass it mirrors): transmittance, direct irradiance, single
//! scattering (Rayleigh and Mie apart), then for each order n ≥ 2 the scattering density ΔJ
//! (the same spherical convolution in azimuth as the CPU: the incident field's cosine series
//! convolved with the phase functions' harmonics), the indirect irradiance ΔE and the multiple
//! scattering ΔS, summed over the orders into its own table (`Tables::multiple`, radiance).
//! All passes go into one command buffer; only the final tables come back.
//!
//! Tables live in storage buffers (not textures) with the CPU's texel order and the channels
//! in groups of four (one vec4 per group): filtering is done in the shaders with exact f32
//! weights, as `firmament::sky::bruneton4d::table` does, so CPU and GPU compare texel by
//! texel.

use firmament::atmosphere::Model;
use firmament::sky::bruneton4d::precompute::{DENSITY_THETA, HARMONICS};
use firmament::sky::bruneton4d::{MieStorage, Table2, Table4, TableConfig, Tables};

use super::atmosphere::{self, groups, GROUP};
use crate::device::{check_buffers, read_buffers_f32, scoped};
use crate::passes::{self as dispatches, dispatch, init, storage, Pass, Slot};
use crate::shader::{passes, precompute_source, Module};
use crate::{GpuContext, GpuError};

/// Storage buffers bound at once by the widest pass (the density field).
const STORAGE_BUFFERS_NEEDED: u32 = 6;

/// The tables on the device, as the precomputation leaves them (or as uploaded from CPU
/// tables): storage buffers of `vec4<f32>` with the CPU's texel order (`firmament::sky::
/// bruneton4d::table`) and the channels in groups of four (channel group k of texel i at
/// index i·groups + k, padding lanes zero), bound by the render shader at the slots
/// `shaders/bruneton4d/view.wgsl` lists.
pub struct GpuTables {
    /// The `Atmosphere` uniform (binding 0; `shaders/common/types.wgsl`).
    pub atmosphere: wgpu::Buffer,
    /// Per-wavelength data, constituents, layers, tabulated phases (binding 2).
    pub data: wgpu::Buffer,
    /// Optical depth τ = −ln T to the top, what the lookups read (binding 3;
    /// `Tables::optical_depth`).
    pub transmittance: wgpu::Buffer,
    /// Indirect ground irradiance E(r, μ_s) (binding 4; `Tables::irradiance`).
    pub irradiance: wgpu::Buffer,
    /// Single Rayleigh scattering (binding 5; `Tables::single_rayleigh`).
    pub single_rayleigh: wgpu::Buffer,
    /// Single Mie scattering (binding 6; `Tables::single_mie`): every channel, or for
    /// red-only storage channel 0 of each texel in the full layout (GPU precomputation) or
    /// one vec4 per texel (uploaded CPU tables).
    pub single_mie: wgpu::Buffer,
    /// Orders ≥ 2 summed, radiance (binding 7; `Tables::multiple`; zeros for one order).
    pub multiple: wgpu::Buffer,
    /// Per-order row sums (for `Tables::order_means`).
    pub(crate) row_sums: wgpu::Buffer,
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

impl Precomputer {
    /// Compile the passes.
    pub fn new(ctx: &GpuContext) -> Result<Precomputer, GpuError> {
        use Slot::{Read, Write};
        scoped(ctx, "shader compilation", || {
            let pass = |module: Module, slots: &[(u32, Slot)]| {
                Pass::new(ctx, module.name(), precompute_source(module), slots)
            };
            Ok(Precomputer {
                transmittance: pass(passes::TRANSMITTANCE, &[(7, Write)]),
                direct_irradiance: pass(
                    passes::DIRECT_IRRADIANCE,
                    &[(3, Read), (7, Write), (8, Write)],
                ),
                single_scattering: pass(
                    passes::SINGLE_SCATTERING,
                    &[(3, Read), (7, Write), (8, Write)],
                ),
                phase_kernels: pass(passes::PHASE_KERNELS, &[(7, Write)]),
                density_field: pass(
                    passes::SCATTERING_DENSITY_FIELD,
                    &[(3, Read), (4, Read), (5, Read), (6, Read), (7, Write)],
                ),
                scattering_density: pass(
                    passes::SCATTERING_DENSITY,
                    &[(7, Read), (8, Read), (9, Write)],
                ),
                indirect_irradiance: pass(
                    passes::INDIRECT_IRRADIANCE,
                    &[(5, Read), (6, Read), (7, Write), (8, Write)],
                ),
                multiple_scattering: pass(
                    passes::MULTIPLE_SCATTERING,
                    &[(3, Read), (5, Read), (7, Write), (8, Write)],
                ),
                order_sums: pass(passes::ORDER_SUMS, &[(5, Read), (6, Read), (7, Write)]),
                order_tail_factors: pass(
                    passes::ORDER_TAIL_FACTORS,
                    &[(4, Read), (5, Read), (7, Write), (8, Read)],
                ),
                order_tail: pass(
                    passes::ORDER_TAIL,
                    &[(4, Read), (5, Read), (6, Read), (7, Write), (8, Write)],
                ),
            })
        })
    }

    /// Precompute every table for `model` with these pipelines and read them back: the
    /// CPU's layout ([`Tables::compute`]).
    pub fn run(
        &self,
        ctx: &GpuContext,
        model: &Model,
        config: &TableConfig,
    ) -> Result<Tables, GpuError> {
        self.run_on_device(ctx, model, config)?
            .read_back(ctx, model, config)
    }

    /// Precompute every table for `model` and leave them on the device (submitted, not
    /// waited for): the buffers [`crate::GpuSky::precompute`] renders from, or an engine
    /// binds itself; [`GpuTables::read_back`] brings them to the host.
    pub fn run_on_device(
        &self,
        ctx: &GpuContext,
        model: &Model,
        config: &TableConfig,
    ) -> Result<GpuTables, GpuError> {
        config.validate()?;
        firmament::sky::bruneton4d::thickness::check(model)?;
        firmament::sky::bruneton4d::shell::check(model)?;
        let n = model.channels();
        firmament::spectrum::check_channels(n, "the precomputed tables")?;
        let s = config.sizes;
        let n_groups = groups(n);
        let orders = config.orders;
        let t_texels = s.transmittance_mu * s.transmittance_r;
        let e_texels = s.irradiance_mu_s * s.irradiance_r;
        let s_texels = s.scattering_r * s.scattering_mu * s.scattering_mu_s * s.scattering_nu;
        let rows = s.scattering_r * s.scattering_mu;
        let vec4 = (GROUP * 4) as u64;
        let bytes_t = (t_texels * n_groups) as u64 * vec4;
        let bytes_e = (e_texels * n_groups) as u64 * vec4;
        let bytes_s = (s_texels * n_groups) as u64 * vec4;
        let bytes_kernels = (rows * DENSITY_THETA * 2 * HARMONICS * 4) as u64;
        let bytes_coefficients =
            (s.scattering_r * s.scattering_mu_s * DENSITY_THETA * HARMONICS * n_groups) as u64
                * vec4;
        let bytes_rows = (orders * rows * n_groups) as u64 * vec4;
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

        let packed = atmosphere::pack_for_precompute(model, &s);
        let max_dim = ctx.limits().max_compute_workgroups_per_dimension;
        let device = ctx.device();

        scoped(ctx, "table precomputation", || {
            let uniform = crate::passes::UNIFORM_USAGE;
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
                dispatch(
                    &mut cpass,
                    &self.transmittance,
                    &bg,
                    t_texels,
                    n_groups,
                    max_dim,
                );
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
                    n_groups,
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
                    n_groups,
                    max_dim,
                );
                let bg = self
                    .order_sums
                    .bind(device, common(1), &[&rayleigh, &mie, &row_sums]);
                dispatch(&mut cpass, &self.order_sums, &bg, rows, n_groups, max_dim);
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
                        n_groups,
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
                        n_groups,
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
                        n_groups,
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
                        n_groups,
                        max_dim,
                    );
                    let bg = self.order_sums.bind(
                        device,
                        common(order),
                        &[&delta_multiple, &delta_multiple, &row_sums],
                    );
                    dispatch(&mut cpass, &self.order_sums, &bg, rows, n_groups, max_dim);
                }
                if config.order_tail && orders >= 3 {
                    let factors = storage(device, "order tail factors", n_groups as u64 * vec4);
                    let bg = self.order_tail_factors.bind(
                        device,
                        common(orders),
                        &[&delta_irradiance, &row_sums, &factors, &irradiance],
                    );
                    dispatch(
                        &mut cpass,
                        &self.order_tail_factors,
                        &bg,
                        1,
                        n_groups,
                        max_dim,
                    );
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
                        n_groups,
                        max_dim,
                    );
                }
            }
            ctx.queue().submit([encoder.finish()]);
            Ok(GpuTables {
                atmosphere: atm,
                data,
                transmittance,
                irradiance,
                single_rayleigh: rayleigh,
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
        let (_, y) = dispatches::workgroups(largest_dispatch, max_dim);
        if y > max_dim {
            return Err(GpuError::Limit {
                what: "the scattering table".into(),
                needed: format!("{largest_dispatch} invocations"),
                limit: format!("{max_dim}² workgroups of {}", dispatches::WORKGROUP),
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

impl GpuTables {
    /// Read the tables back into the CPU's layout (for files and CPU lookups): waits for the
    /// precomputation. `model` and `config` are the ones they were computed with.
    pub fn read_back(
        &self,
        ctx: &GpuContext,
        model: &Model,
        config: &TableConfig,
    ) -> Result<Tables, GpuError> {
        let n = model.channels();
        let s = config.sizes;
        let n_groups = groups(n);
        let orders = config.orders;
        let t_texels = s.transmittance_mu * s.transmittance_r;
        let e_texels = s.irradiance_mu_s * s.irradiance_r;
        let s_texels = s.scattering_r * s.scattering_mu * s.scattering_mu_s * s.scattering_nu;
        let rows = s.scattering_r * s.scattering_mu;
        let sources = [
            &self.transmittance,
            &self.irradiance,
            &self.single_rayleigh,
            &self.single_mie,
            &self.multiple,
            &self.row_sums,
        ];
        let values = read_buffers_f32(
            ctx,
            &sources,
            "table precomputation",
            "reading the tables back",
        )?;
        let [t_data, e_data, s_data, m_data, multiple_data, rows_data] =
            <[Vec<f32>; 6]>::try_from(values).expect("six buffers");
        let unpad = |v: &[f32], texels: usize| -> Vec<f32> {
            let mut out = Vec::with_capacity(texels * n);
            for t in 0..texels {
                out.extend_from_slice(&v[t * n_groups * GROUP..t * n_groups * GROUP + n]);
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
            data,
            ..Table4::for_sizes(&s, channels)
        };
        let single_mie = match config.mie {
            MieStorage::Separate => table4(unpad(&m_data, s_texels), n),
            MieStorage::RedOnly => table4(
                (0..s_texels)
                    .map(|t| m_data[t * n_groups * GROUP])
                    .collect(),
                1,
            ),
        };
        let order_means = (0..orders)
            .map(|o| {
                let mut sum = vec![0.0f64; n];
                for row in 0..rows {
                    let base = ((o * rows + row) * n_groups) * GROUP;
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
            single_rayleigh: table4(unpad(&s_data, s_texels), n),
            single_mie,
            order_means,
            mie_ratio: model.groups.mie_ratio(),
            multiple: table4(unpad(&multiple_data, s_texels), n),
        })
    }
}

//! Hillaire 2020's tables read back from the device into the CPU's layout
//! ([`GpuHillaireTables::read_back`]: [`Table2`]s as `Hillaire2020::compute` leaves them,
//! without the channel groups' padding lanes), f_ms for the refusal, and the CPU method over
//! the GPU's tables ([`HillaireTables::into_method`]).

use firmament::atmosphere::Model;
use firmament::sky::bruneton4d::Table2;
use firmament::sky::hillaire2020::harmonics::{coefficient_count, phase_moments};
use firmament::sky::hillaire2020::params::altitude_mu_s_of_texel;
use firmament::sky::hillaire2020::{
    Hillaire2020, HillaireConfig, MultipleScattering, MultipleScatteringModel,
};

use super::precompute::{GpuHillaireTables, HillaireTables};
use crate::bruneton4d::atmosphere::{groups, GROUP};
use crate::device::read_buffers_f32;
use crate::{GpuContext, GpuError};

/// `values` (`entries` entries of `groups` vec4 each) without the padding lanes: `channels`
/// values per entry.
fn unpad(values: &[f32], entries: usize, groups: usize, channels: usize) -> Vec<f32> {
    let mut out = Vec::with_capacity(entries * channels);
    for e in 0..entries {
        out.extend_from_slice(&values[e * groups * GROUP..e * groups * GROUP + channels]);
    }
    out
}

impl GpuHillaireTables {
    /// The largest f_ms and where (altitude m, μ_s, channel), from the f_ms the pass wrote
    /// (waits for the build).
    pub fn max_f_ms(
        &self,
        ctx: &GpuContext,
        model: &Model,
        config: &HillaireConfig,
    ) -> Result<(f64, (f64, f64, usize)), GpuError> {
        let raw = self.read(ctx, &[&self.f_ms])?;
        Ok(max_f_ms_of(&raw[0], model, config))
    }

    /// Copy `sources` to the host (waits for the device).
    fn read(&self, ctx: &GpuContext, sources: &[&wgpu::Buffer]) -> Result<Vec<Vec<f32>>, GpuError> {
        read_buffers_f32(
            ctx,
            sources,
            "Hillaire 2020 tables",
            "reading the Hillaire 2020 tables back",
        )
    }

    /// Read the tables back into the CPU's layout (waits for the build). `model` and
    /// `config` are the ones they were built with.
    pub fn read_back(
        &self,
        ctx: &GpuContext,
        model: &Model,
        config: &HillaireConfig,
    ) -> Result<HillaireTables, GpuError> {
        let n = model.channels();
        let g = groups(n);
        let raw = self.read(
            ctx,
            &[
                &self.optical_depth,
                &self.multiple_scattering,
                &self.irradiance,
                &self.f_ms,
            ],
        )?;
        let coefficients = coefficient_count(config.multiple_scattering_model.degree());
        let table = |(w, h): (usize, usize), per_texel: usize, values: &[f32]| Table2 {
            width: w,
            height: h,
            channels: per_texel * n,
            data: unpad(values, w * h * per_texel, g, n),
        };
        let (max_f_ms, max_at) = max_f_ms_of(&raw[3], model, config);
        Ok(HillaireTables {
            optical_depth: table(config.transmittance, 1, &raw[0]),
            multiple_scattering: table(config.multiple_scattering, coefficients, &raw[1]),
            irradiance: table(config.irradiance, 1, &raw[2]),
            max_f_ms,
            max_at,
        })
    }
}

impl HillaireTables {
    /// The CPU method over these tables (`model` and `config` the ones they were built
    /// with): its views, probes and frames then evaluate the GPU's tables.
    pub fn into_method(self, model: Model, config: &HillaireConfig) -> Hillaire2020 {
        let degree = config.multiple_scattering_model.degree();
        let moments = (model.constituents.iter())
            .map(|c| match config.multiple_scattering_model {
                MultipleScatteringModel::Isotropic => vec![1.0],
                MultipleScatteringModel::Harmonics(_) => phase_moments(&c.phase, degree),
            })
            .collect();
        Hillaire2020 {
            model,
            config: *config,
            optical_depth: self.optical_depth,
            multiple_scattering: MultipleScattering {
                table: self.multiple_scattering,
                degree,
                moments,
                max_f_ms: self.max_f_ms,
                max_at: self.max_at,
            },
            irradiance: self.irradiance,
            max_f_ms: self.max_f_ms,
        }
    }
}

/// The largest f_ms of the pass's output and where it was met (the CPU's fold: the first
/// texel, in texel order, holding the largest value).
fn max_f_ms_of(values: &[f32], model: &Model, config: &HillaireConfig) -> (f64, (f64, f64, usize)) {
    let n = model.channels();
    let g = groups(n);
    let (w, h) = config.multiple_scattering;
    let mut worst = (0.0f64, (0.0, 1.0, 0));
    for texel in 0..w * h {
        for k in 0..n {
            let f = values[texel * g * GROUP + k] as f64;
            if f > worst.0 {
                let (bottom, top) = (model.bottom_radius_m, model.top_radius_m);
                let (r, mu_s) = altitude_mu_s_of_texel(texel % w, texel / w, bottom, top, w, h);
                worst = (f, (r - bottom, mu_s, k));
            }
        }
    }
    worst
}

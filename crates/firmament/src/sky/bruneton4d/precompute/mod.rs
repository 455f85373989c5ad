//! The precomputation of Bruneton & Neyret 2008 Algorithm 4.1 (as in Bruneton 2017):
//! transmittance, direct irradiance, single scattering (Rayleigh and Mie apart), then for
//! each order n ≥ 2 the scattering density ΔJ, the indirect irradiance ΔE and the multiple
//! scattering ΔS.
//!
//! The scattering density, which dominates Bruneton's cost (512 incident directions per
//! texel), is computed as a spherical convolution: for a fixed (r, μ_s) the
//! incident radiance field is the same for every view direction, so it is sampled once on a
//! (θ, φ) grid in the sun's frame, expanded as a cosine series in azimuth, and convolved
//! with the phase functions' azimuthal harmonics (exact for the band-limited field), which
//! are independent of the order and computed once.

mod direct_irradiance;
mod grid;
mod indirect_irradiance;
mod multiple_scattering;
mod order_tail;
mod phase_kernels;
mod ray;
mod scattering_density;
mod single_scattering;
mod transmittance;

use std::sync::atomic::{AtomicBool, Ordering};

use super::lookup::Lookup;
use super::params;
use super::table::{Table2, Table4};
use super::{MieStorage, TableConfig, Tables};
use crate::atmosphere::{Model, ScatteringGroups};
use crate::{Error, Result};
use direct_irradiance::compute_direct_irradiance;
pub(crate) use grid::{MuSPositions, ScatteringGrid};
use indirect_irradiance::compute_indirect_irradiance;
use multiple_scattering::compute_multiple_scattering;
pub use order_tail::order_tail_factors;
use order_tail::{add_scaled, cap_by_energy, table_mean, table_mean_radiance};
use phase_kernels::PhaseKernels;
use scattering_density::compute_scattering_density;
use single_scattering::compute_single_scattering;
pub use transmittance::{compute_optical_depth, compute_optical_depth_in};

use crate::spectrum::MAX_CHANNELS;

/// Segments of the 4-point Gauss–Legendre rule for the transmittance table.
pub const TRANSMITTANCE_SEGMENTS: usize = 128;
/// Intervals along view rays for single and multiple scattering (Bruneton 2017 uses 50
/// trapezoids). We weight them by Simpson's rule (with the transmittance fitted as an
/// exponential, see the private `ray` module): at this spacing a zenith ray takes
/// 1.2 km steps, one aerosol scale height, where the trapezoid overestimates an
/// exponential integrand by 8 % and Simpson by 0.5 % (found by the reference path tracer).
pub const RAY_INTERVALS: usize = 50;
/// Incident zenith angles for the scattering density (midpoint rule).
pub const DENSITY_THETA: usize = 32;
/// Incident azimuths over 2π for the scattering density (Bruneton 2017 uses 32).
pub const DENSITY_PHI: usize = 32;
/// Azimuthal harmonics kept (the band limit of DENSITY_PHI samples).
pub const HARMONICS: usize = DENSITY_PHI / 2;
/// Azimuth steps over [0, π] to compute the phase functions' harmonics.
pub const KERNEL_STEPS: usize = 96;
/// Hemisphere sampling of the indirect irradiance (Bruneton 2017: 16 × 64): zenith-angle
/// steps over [0, π/2].
pub const IRRADIANCE_THETA: usize = 16;
/// Azimuth steps over [0, 2π] of the same sampling.
pub const IRRADIANCE_PHI: usize = 64;

/// Progress callback: (stage description, fraction done of the whole precomputation).
pub type Progress<'a> = &'a (dyn Fn(&str, f64) + Sync);

fn check_cancel(cancel: Option<&AtomicBool>) -> Result<()> {
    match cancel {
        Some(c) if c.load(Ordering::Relaxed) => Err(Error::Interrupted),
        _ => Ok(()),
    }
}

/// Run the whole precomputation.
pub fn precompute(
    model: &Model,
    config: &TableConfig,
    progress: Progress,
    cancel: Option<&AtomicBool>,
) -> Result<Tables> {
    config.validate()?;
    super::thickness::check(model)?;
    let n = model.channels();
    crate::spectrum::check_channels(n, "the precomputed tables")?;
    let s = config.sizes;
    let orders = config.orders;
    let total_steps = 3.0 + 3.0 * (orders.saturating_sub(1)) as f64;
    let mut step = 0.0;
    let mut report = |what: &str| {
        progress(what, step / total_steps);
        step += 1.0;
    };

    report("transmittance");
    let optical_depth = compute_optical_depth(model, &s);
    let transmittance = optical_depth.transmittance_of_optical_depth();
    check_cancel(cancel)?;
    let lookup = Lookup::new(model, s, &optical_depth);
    let grid = ScatteringGrid::new(&lookup.radii, &s);
    let groups = &model.groups;

    report("direct irradiance");
    let mut delta_irradiance = compute_direct_irradiance(model, &lookup);
    let mut irradiance = Table2::new(s.irradiance_mu_s, s.irradiance_r, n);

    report("single scattering");
    let (delta_rayleigh, delta_mie) = compute_single_scattering(model, &lookup, &grid, groups);
    check_cancel(cancel)?;
    let mut order_means = vec![table_mean_radiance(
        &delta_rayleigh,
        &delta_mie,
        groups,
        &grid,
    )];
    let mut multiple = Table4::for_sizes(&s, n);

    if orders >= 2 {
        let kernels = PhaseKernels::new(&lookup, &grid, groups);
        let mut delta_multiple = Table4::for_sizes(&s, n);
        for order in 2..=orders {
            report(&format!("scattering density, order {order}"));
            // The radiance of the previous order feeds both ΔJ and ΔE.
            let previous = if order == 2 {
                Previous::Single {
                    rayleigh: &delta_rayleigh,
                    mie: &delta_mie,
                    groups,
                }
            } else {
                Previous::Multiple(&delta_multiple)
            };
            let density = compute_scattering_density(
                model,
                &lookup,
                &grid,
                groups,
                &kernels,
                &previous,
                &delta_irradiance,
            );
            check_cancel(cancel)?;
            report(&format!("indirect irradiance, order {}", order - 1));
            delta_irradiance = compute_indirect_irradiance(model, &lookup, &previous);
            irradiance.add_assign(&delta_irradiance);
            report(&format!("multiple scattering, order {order}"));
            delta_multiple = compute_multiple_scattering(model, &lookup, &grid, &density);
            check_cancel(cancel)?;
            order_means.push(table_mean(&delta_multiple));
            multiple.add_assign(&delta_multiple);
        }
        if config.order_tail {
            if let Some(mut f) = order_tail_factors(&order_means) {
                cap_by_energy(
                    &mut f,
                    &irradiance,
                    &delta_irradiance,
                    &model.solar_irradiance,
                );
                add_scaled(&mut multiple.data, &delta_multiple.data, &f);
                add_scaled(&mut irradiance.data, &delta_irradiance.data, &f);
            }
        }
    }
    progress("done", 1.0);

    let single_mie = match config.mie {
        MieStorage::Separate => delta_mie,
        MieStorage::RedOnly => {
            let mut red = Table4::for_sizes(&s, 1);
            for (i, v) in red.data.iter_mut().enumerate() {
                *v = delta_mie.data[i * n];
            }
            red
        }
    };
    Ok(Tables {
        config: *config,
        wavelengths_nm: model.wavelengths.nm().to_vec(),
        atmosphere_hash: model.hash,
        transmittance,
        optical_depth,
        irradiance,
        single_rayleigh: delta_rayleigh,
        single_mie,
        order_means,
        mie_ratio: groups.mie_ratio(),
        multiple,
    })
}

/// The radiance field of the previous scattering order.
pub(super) enum Previous<'a> {
    /// Order 1: the single-scattering tables, phase functions applied at lookup.
    Single {
        rayleigh: &'a Table4,
        mie: &'a Table4,
        groups: &'a ScatteringGroups,
    },
    /// Order ≥ 2: ΔS, radiance as it is.
    Multiple(&'a Table4),
}

impl Previous<'_> {
    #[inline]
    pub(super) fn radiance(
        &self,
        lookup: &Lookup,
        r: f64,
        mu: f64,
        mu_s: f64,
        nu: f64,
        ground: bool,
        out: &mut [f64],
        tmp: &mut [f64],
    ) {
        let uvwz = params::scattering_uvwz(&lookup.radii, &lookup.sizes, r, mu, mu_s, nu, ground);
        match self {
            Previous::Single {
                rayleigh,
                mie,
                groups,
            } => {
                rayleigh.sample_into(uvwz, out);
                mie.sample_into(uvwz, tmp);
                let (pr, pm) = (groups.phase[0].eval(nu), groups.phase[1].eval(nu));
                for k in 0..out.len() {
                    out[k] = out[k] * pr + tmp[k] * pm;
                }
            }
            Previous::Multiple(t) => t.sample_into(uvwz, out),
        }
    }
}

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
//!
//! The passes run as the units of a [`PrecomputeJob`] ([`plan`](Unit): the 4D passes by r
//! slices, the 2D ones by rows of r, each with an estimated cost), which [`precompute`]
//! runs in one go and [`AmortisedTables`](super::AmortisedTables) a share per frame
//! (Hillaire 2016 §2 "Our approach"); every texel is computed the same way either way.

mod direct_irradiance;
mod grid;
mod indirect_irradiance;
mod job;
mod multiple_scattering;
mod order_tail;
mod phase_kernels;
mod plan;
mod ray;
pub mod ray_grading;
mod scattering_density;
mod single_scattering;
mod transmittance;

use std::sync::atomic::{AtomicBool, Ordering};

use super::lookup::Lookup;
use super::params;
use super::table::Table4;
use super::{TableConfig, Tables};
use crate::atmosphere::{Model, ScatteringGroups};
use crate::{Error, Result};
pub(crate) use grid::{MuSPositions, ScatteringGrid};
pub use job::PrecomputeJob;
pub use order_tail::{order_tail_factors, ORDER_RATIO_CAP};
pub use plan::{frame_schedule, Pass, Unit};
pub use transmittance::{
    compute_optical_depth, compute_optical_depth_in, compute_optical_depth_with, Columns,
};

use crate::spectrum::MAX_CHANNELS;

/// Segments of the 4-point Gauss–Legendre rule for the transmittance table.
pub const TRANSMITTANCE_SEGMENTS: usize = 128;
/// Intervals along view rays for single and multiple scattering (Bruneton 2017 uses 50
/// trapezoids). We weight them by Simpson's rule (with the transmittance fitted as an
/// exponential, see the private `ray` module): at even spacing a zenith ray takes
/// 1.2 km steps, one aerosol scale height, where the trapezoid overestimates an
/// exponential integrand by 8 % and Simpson by 0.5 % (found by the reference path tracer).
/// The pairs are graded by each ray's optical depth ([`ray_grading`]).
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

/// Run the whole precomputation: the units of a [`PrecomputeJob`] one after the other,
/// reporting each stage with the share of the cost done, and stopping with
/// [`Error::Interrupted`] between units once `cancel` is set.
pub fn precompute(
    model: &Model,
    config: &TableConfig,
    progress: Progress,
    cancel: Option<&AtomicBool>,
) -> Result<Tables> {
    let mut job = PrecomputeJob::new(model.clone(), config)?;
    while let Some(unit) = job.next_unit() {
        progress(&unit.pass.label(), job.fraction());
        check_cancel(cancel)?;
        job.run_unit();
    }
    check_cancel(cancel)?;
    progress("done", 1.0);
    Ok(job.finish().1)
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
                rayleigh.sample_into(uvwz, &lookup.blend(), out);
                mie.sample_into(uvwz, &lookup.blend(), tmp);
                let (pr, pm) = (groups.phase[0].eval(nu), groups.phase[1].eval(nu));
                for k in 0..out.len() {
                    out[k] = out[k] * pr + tmp[k] * pm;
                }
            }
            Previous::Multiple(t) => t.sample_into(uvwz, &lookup.blend(), out),
        }
    }
}

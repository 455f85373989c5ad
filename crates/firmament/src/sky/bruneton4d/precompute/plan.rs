//! The units of the resumable precomputation ([`super::PrecomputeJob`]) and their costs:
//! Bruneton & Neyret 2008 Algorithm 4.1's passes in order, the 4D ones (single scattering,
//! the phase kernels, ΔJ, ΔS) split by ranges of r slices and the 2D ones by rows of r, each
//! unit weighted by an estimate of its cost so that an update spread over N frames
//! (Hillaire 2016 §2 "Our approach": the LUT update amortised over several frames) can give
//! each frame 1/N of the whole.

use std::ops::Range;

use super::{DENSITY_THETA, KERNEL_STEPS, RAY_INTERVALS, TRANSMITTANCE_SEGMENTS};
use crate::sky::bruneton4d::params::TableSizes;
use crate::sky::bruneton4d::TableConfig;

/// A pass of Algorithm 4.1 (a unit computes all of it or a range of its rows).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pass {
    /// The optical depth to the top, rows of r.
    Transmittance,
    /// The sun's irradiance on the ground ΔE of order 1, whole.
    DirectIrradiance,
    /// Single scattering, r slices.
    SingleScattering,
    /// The phase functions' azimuthal harmonics for ΔJ, r slices (once, for orders ≥ 2).
    PhaseKernels,
    /// The scattering density ΔJ of this order, r slices.
    ScatteringDensity {
        /// Scattering order n ≥ 2.
        order: usize,
    },
    /// The indirect irradiance ΔE of this order (from its radiance), rows of r.
    IndirectIrradiance {
        /// Order of the radiance integrated, n − 1 ≥ 1.
        order: usize,
    },
    /// The multiple scattering ΔS of this order, r slices.
    MultipleScattering {
        /// Scattering order n ≥ 2.
        order: usize,
    },
    /// The order tail, the Mie storage and the transmittance from the optical depth: the
    /// tables assembled.
    Finish,
}

impl Pass {
    /// The stage as the progress report names it.
    pub fn label(&self) -> String {
        match self {
            Pass::Transmittance => "transmittance".into(),
            Pass::DirectIrradiance => "direct irradiance".into(),
            Pass::SingleScattering => "single scattering".into(),
            Pass::PhaseKernels => "phase kernels".into(),
            Pass::ScatteringDensity { order } => format!("scattering density, order {order}"),
            Pass::IndirectIrradiance { order } => format!("indirect irradiance, order {order}"),
            Pass::MultipleScattering { order } => format!("multiple scattering, order {order}"),
            Pass::Finish => "order tail and assembly".into(),
        }
    }
}

/// One step of the precomputation: a pass over a range of its outermost rows.
#[derive(Clone, Debug, PartialEq)]
pub struct Unit {
    /// The pass.
    pub pass: Pass,
    /// Its rows this unit computes: r slices of the 4D tables, r rows of the 2D ones, 0..1
    /// for the steps done whole.
    pub slices: Range<usize>,
    /// Estimated cost, µs of one core (texels times costs per texel measured per pass).
    pub weight: f64,
}

/// Estimated costs per row (µs of one core) of each pass for these sizes, `channels`
/// wavelengths and `constituents` constituents: texels (and ray samples or quadrature
/// points) times a cost per texel affine in the channels, measured on the development
/// machine (`examples/amortised_frames.rs --units`: `earth`, default sizes, rgb and
/// spectral, one core, the least of three runs). At the small sizes the model's shares
/// of the whole are near the measured ones (rgb: single scattering 22 % against 20 %,
/// multiple scattering 49 % against 49 %; spectral: 24 % against 31 %, 53 % against 47 %).
/// Only ratios matter: a unit's share of the whole.
#[derive(Clone, Copy, Debug)]
pub(super) struct RowCosts {
    transmittance: f64,
    direct_irradiance: f64,
    single: f64,
    kernels: f64,
    /// Order 2 (the previous order is single scattering: two lookups and phases), ≥ 3.
    density: [f64; 2],
    /// As `density`.
    indirect: [f64; 2],
    multiple: f64,
    finish: f64,
}

// Measured costs (ns of one core: [fixed, per channel]), see [`RowCosts`].
/// One Gauss–Legendre point of one constituent's column (transmittance).
const NS_COLUMN_POINT: [f64; 2] = [11.0, 0.3];
/// One texel of the direct irradiance.
const NS_DIRECT_TEXEL: [f64; 2] = [150.0, 0.0];
/// One ray sample of one single-scattering texel.
const NS_SINGLE_SAMPLE: [f64; 2] = [18.8, 5.7];
/// One azimuth step of one (r, μ, incident zenith, group) of the phase kernels.
const NS_KERNEL_STEP: [f64; 2] = [14.5, 0.0];
/// One texel of ΔJ, order 2 and ≥ 3.
const NS_DENSITY_TEXEL: [[f64; 2]; 2] = [[238.0, 58.2], [162.0, 59.8]];
/// One texel of ΔE (256 hemisphere lookups), order 1 and ≥ 2.
const NS_INDIRECT_TEXEL: [[f64; 2]; 2] = [[76_000.0, 7_800.0], [49_000.0, 5_300.0]];
/// One ray sample of one multiple-scattering texel.
const NS_MULTIPLE_SAMPLE: [f64; 2] = [14.6, 4.15];
/// One value (texel and channel) of the order tail and the Mie storage.
const NS_FINISH_VALUE: [f64; 2] = [3.3, 0.0];

impl RowCosts {
    pub(super) fn new(s: &TableSizes, channels: usize, constituents: usize) -> RowCosts {
        let n = channels as f64;
        // µs for `count` operations of cost `c`.
        let cost = |count: usize, c: [f64; 2]| count as f64 * (c[0] + c[1] * n) * 1e-3;
        let samples = RAY_INTERVALS + 1;
        let slice_texels = s.scattering_mu * s.scattering_nu * s.scattering_mu_s;
        RowCosts {
            transmittance: cost(
                s.transmittance_mu * TRANSMITTANCE_SEGMENTS * 4 * constituents,
                NS_COLUMN_POINT,
            ),
            direct_irradiance: cost(s.irradiance_mu_s * s.irradiance_r, NS_DIRECT_TEXEL),
            single: cost(slice_texels * samples, NS_SINGLE_SAMPLE),
            kernels: cost(
                s.scattering_mu * DENSITY_THETA * 2 * (KERNEL_STEPS + 1),
                NS_KERNEL_STEP,
            ),
            density: NS_DENSITY_TEXEL.map(|c| cost(slice_texels, c)),
            indirect: NS_INDIRECT_TEXEL.map(|c| cost(s.irradiance_mu_s, c)),
            multiple: cost(slice_texels * samples, NS_MULTIPLE_SAMPLE),
            finish: cost(s.scattering_r * slice_texels, NS_FINISH_VALUE),
        }
    }
}

/// The units of a precomputation with this configuration, in the order they run.
pub(super) fn plan(config: &TableConfig, channels: usize, constituents: usize) -> Vec<Unit> {
    let s = &config.sizes;
    let c = RowCosts::new(s, channels, constituents);
    // The heaviest r slice of a 4D pass is the finest unit worth having (rayon splits
    // inside it); every pass is cut into runs of rows weighing at most that.
    let cap = [c.single, c.kernels, c.density[0], c.density[1], c.multiple]
        .into_iter()
        .fold(0.0, f64::max);
    let mut units = Vec::new();
    let mut add = |pass: Pass, rows: usize, row_cost: f64| {
        let per_unit = if row_cost > 0.0 {
            ((cap / row_cost).floor() as usize).clamp(1, rows)
        } else {
            rows
        };
        let count = rows.div_ceil(per_unit);
        for i in 0..count {
            // Rows spread evenly over the units.
            let slices = i * rows / count..(i + 1) * rows / count;
            let weight = slices.len() as f64 * row_cost;
            units.push(Unit {
                pass,
                slices,
                weight,
            });
        }
    };
    add(Pass::Transmittance, s.transmittance_r, c.transmittance);
    add(Pass::DirectIrradiance, 1, c.direct_irradiance);
    add(Pass::SingleScattering, s.scattering_r, c.single);
    if config.orders >= 2 {
        add(Pass::PhaseKernels, s.scattering_r, c.kernels);
        for order in 2..=config.orders {
            let k = usize::from(order > 2);
            add(
                Pass::ScatteringDensity { order },
                s.scattering_r,
                c.density[k],
            );
            add(
                Pass::IndirectIrradiance { order: order - 1 },
                s.irradiance_r,
                c.indirect[k],
            );
            add(
                Pass::MultipleScattering { order },
                s.scattering_r,
                c.multiple,
            );
        }
    }
    add(Pass::Finish, 1, c.finish);
    units
}

/// Whether a unit of `weight` runs in a step that brings the cost done, `done`, to at most
/// `fraction` of `total` (every unit runs once `fraction` ≥ 1).
#[inline]
pub(super) fn fits(done: f64, weight: f64, fraction: f64, total: f64) -> bool {
    fraction >= 1.0 || done + weight <= fraction * total
}

/// The units each of `frames` frames runs when frame k (1-based) brings the cost done to
/// k/N of the whole ([`super::PrecomputeJob::step_to`]'s rule, what
/// [`AmortisedTables`](crate::sky::bruneton4d::AmortisedTables) does): ranges of indices
/// into `units`. A frame's weight is then under 1/N of the total plus one unit, and the
/// last frame ends the job.
pub fn frame_schedule(units: &[Unit], frames: usize) -> Vec<Range<usize>> {
    let total: f64 = units.iter().map(|u| u.weight).sum();
    let (mut next, mut done) = (0, 0.0);
    (1..=frames)
        .map(|k| {
            let fraction = k as f64 / frames as f64;
            let start = next;
            while next < units.len() && fits(done, units[next].weight, fraction, total) {
                done += units[next].weight;
                next += 1;
            }
            start..next
        })
        .collect()
}

//! The indirect irradiance pass ΔE (paper eq. 15): the previous order's radiance integrated
//! over the upper hemisphere.

use std::f64::consts::PI;
use std::ops::Range;

use rayon::prelude::*;

use super::{Previous, IRRADIANCE_PHI, IRRADIANCE_THETA};
use crate::atmosphere::Model;
use crate::sky::bruneton4d::lookup::Lookup;
use crate::sky::bruneton4d::params;

/// Indirect ground irradiance ΔE from the previous order (paper eq. 15 / Bruneton 2017
/// `ComputeIndirectIrradiance`), by midpoint quadrature over the upper hemisphere, for the
/// r rows `rows` into `out` (those rows' part of the table's data; texel by texel, so rows
/// computed apart equal the whole pass).
pub(super) fn indirect_irradiance_rows(
    model: &Model,
    lookup: &Lookup,
    previous: &Previous,
    rows: Range<usize>,
    out: &mut [f32],
) {
    let s = lookup.sizes;
    let n = model.channels();
    debug_assert_eq!(out.len(), rows.len() * s.irradiance_mu_s * n);
    let first = rows.start * s.irradiance_mu_s;
    let dtheta = PI / 2.0 / IRRADIANCE_THETA as f64;
    let dphi = 2.0 * PI / IRRADIANCE_PHI as f64;
    out.par_chunks_mut(n).enumerate().for_each(|(i, out)| {
        let i = first + i;
        let (x, y) = (i % s.irradiance_mu_s, i / s.irradiance_mu_s);
        let (r, mu_s) = params::irradiance_texel(&lookup.radii, &s, x, y);
        let sin_s = (1.0 - mu_s * mu_s).max(0.0).sqrt();
        let mut radiance = vec![0.0; n];
        let mut tmp = vec![0.0; n];
        let mut acc = vec![0.0; n];
        for j in 0..IRRADIANCE_THETA {
            let theta = (j as f64 + 0.5) * dtheta;
            let (sin_t, cos_t) = theta.sin_cos();
            let domega = dtheta * dphi * sin_t;
            // Azimuth symmetry about the sun: sample half the circle, count twice.
            for i_phi in 0..IRRADIANCE_PHI / 2 {
                let phi = (i_phi as f64 + 0.5) * dphi;
                let nu = (phi.cos() * sin_t * sin_s + cos_t * mu_s).clamp(-1.0, 1.0);
                previous.radiance(lookup, r, cos_t, mu_s, nu, false, &mut radiance, &mut tmp);
                for k in 0..n {
                    acc[k] += 2.0 * radiance[k] * cos_t * domega;
                }
            }
        }
        for k in 0..n {
            out[k] = acc[k] as f32;
        }
    });
}

//! The transmittance pass: the optical depth τ(r, μ) to the top of the atmosphere, stored
//! instead of the transmittance (see [`Table2::transmittance_of_optical_depth`]).

use std::ops::Range;

use rayon::prelude::*;

use super::TRANSMITTANCE_SEGMENTS;
use crate::atmosphere::Model;
use crate::sky::bruneton4d::params::{self, Radii, TableSizes};
use crate::sky::bruneton4d::table::{Table2, MAX_OPTICAL_DEPTH};

/// τ(r, μ) to the top, capped at [`MAX_OPTICAL_DEPTH`]: 4-point Gauss–Legendre on the
/// constituents' columns (exact optical depths per constituent, then the per-wavelength sum).
pub fn compute_optical_depth(model: &Model, s: &TableSizes) -> Table2 {
    compute_optical_depth_in(model, s, TRANSMITTANCE_SEGMENTS)
}

/// [`compute_optical_depth`] with `segments` Gauss–Legendre segments per ray.
pub fn compute_optical_depth_in(model: &Model, s: &TableSizes, segments: usize) -> Table2 {
    compute_optical_depth_with(model, s, &|r, mu, d, columns| {
        model.columns_along_ray(r, mu, d, segments, columns)
    })
}

/// [`compute_optical_depth`] with the constituents' columns along a ray from `columns(r,
/// μ, length, out)` (e.g. [`crate::atmosphere::density_table::DensityTable`]'s).
pub fn compute_optical_depth_with(model: &Model, s: &TableSizes, columns: &Columns) -> Table2 {
    let mut t = Table2::new(s.transmittance_mu, s.transmittance_r, model.channels());
    optical_depth_rows(model, s, columns, 0..s.transmittance_r, &mut t.data);
    t
}

/// The constituents' columns (m) along the ray from radius r (m) in direction μ over a
/// length (m), into the last argument.
pub type Columns<'a> = dyn Fn(f64, f64, f64, &mut [f64]) + Sync + 'a;

/// The rows `rows` (r texels) of [`compute_optical_depth_in`] into `out`, their part of the
/// table's data: a unit of the resumable precomputation ([`super::PrecomputeJob`]).
pub(super) fn optical_depth_rows(
    model: &Model,
    s: &TableSizes,
    columns_along_ray: &Columns,
    rows: Range<usize>,
    out: &mut [f32],
) {
    let n = model.channels();
    let radii = Radii::of(model);
    let width = s.transmittance_mu;
    debug_assert_eq!(out.len(), rows.len() * width * n);
    out.par_chunks_mut(width * n)
        .enumerate()
        .for_each(|(i, row)| {
            let y = rows.start + i;
            let mut columns = vec![0.0; model.constituents.len()];
            let mut tau = vec![0.0; n];
            for x in 0..width {
                let u = (x as f64 + 0.5) / width as f64;
                let v = (y as f64 + 0.5) / s.transmittance_r as f64;
                let (r, mu) =
                    params::transmittance_r_mu(&radii, u, v, s.transmittance_mu, s.transmittance_r);
                let d = crate::math::sphere::distance_to_top_atmosphere_boundary(r, mu, radii.top);
                columns_along_ray(r, mu, d, &mut columns);
                model.optical_depth_from_columns(&columns, &mut tau);
                for k in 0..n {
                    row[x * n + k] = tau[k].min(MAX_OPTICAL_DEPTH as f64) as f32;
                }
            }
        });
}

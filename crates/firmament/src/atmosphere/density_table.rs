//! The constituents' densities tabulated over altitude, for passes that evaluate them
//! millions of times (Hillaire 2020's transmittance table, rebuilt whenever the atmosphere
//! changes, and its marches' steps): linear interpolation on a uniform grid instead of an
//! exponential per constituent and sample. Building one costs [`DENSITY_SAMPLES`] profile
//! evaluations per constituent (~0.3 ms).
//!
//! Error: for an exponential layer of scale height H on a grid of step Δh, linear
//! interpolation overestimates by at most (Δh/H)²/8 relative (the interpolation remainder
//! f″·Δh²/8); with [`DENSITY_SAMPLES`] over Earth's 100 km (Δh = 12.2 m) and the aerosols'
//! H = 1.2 km that is 1.3e-5, measured on the optical depths in
//! `tests::the_tabulated_columns_are_the_exact_ones`.

use super::model::gauss_radii_along_ray;
use super::Model;
use crate::math::quadrature::GL4;

/// Grid points from the ground to the top of the atmosphere.
pub const DENSITY_SAMPLES: usize = 8192;

/// Each constituent's density at uniformly spaced altitudes.
pub struct DensityTable {
    bottom_m: f64,
    inv_step_m: f64,
    constituents: usize,
    /// `values[i·constituents + c]`: constituent c at altitude i·step.
    values: Vec<f64>,
    /// For columns along rays (when there are at most four constituents): the densities
    /// four to a row (0 past the model's constituents) on a grid uniform in r² − R_g²
    /// rather than in altitude, so that a point on a ray, whose r² is a quadratic in its
    /// distance, is looked up without a square root; built on first use (the marches do
    /// not need it). Its rows are as dense in altitude as the altitude grid's to within the
    /// atmosphere's thickness over the planet's diameter (1.6 % on Earth), so its
    /// interpolation error has the same bound.
    radial: std::sync::OnceLock<Radial>,
    /// The ground's and the top's radii (m).
    radii: (f64, f64),
    /// The model's profiles, to build `radial` from.
    profiles: Vec<crate::medium::DensityProfile>,
}

/// [`DensityTable`]'s grid in r² − R_g².
struct Radial {
    inv_step_m2: f64,
    /// In f32: a node's lerp and sum are one 4-wide operation each (the columns' sums stay
    /// within ~1e-6 relative of the f64 ones, far below the grid's own 1.3e-5).
    quads: Vec<[f32; 4]>,
}

impl DensityTable {
    /// The table of `model`'s constituents with `samples` (≥ 2) grid points.
    pub fn new(model: &Model, samples: usize) -> DensityTable {
        let samples = samples.max(2);
        let step = (model.top_radius_m - model.bottom_radius_m) / (samples - 1) as f64;
        let mut values = Vec::with_capacity(samples * model.constituents.len());
        for i in 0..samples {
            let altitude = i as f64 * step;
            values.extend(
                model
                    .constituents
                    .iter()
                    .map(|c| c.density.density(altitude)),
            );
        }
        DensityTable {
            bottom_m: model.bottom_radius_m,
            inv_step_m: 1.0 / step,
            constituents: model.constituents.len(),
            values,
            radial: std::sync::OnceLock::new(),
            radii: (model.bottom_radius_m, model.top_radius_m),
            profiles: model
                .constituents
                .iter()
                .map(|c| c.density.clone())
                .collect(),
        }
    }

    /// The grid in r² − R_g² with as many points as the altitudes' (see `radial`).
    fn radial(&self) -> &Radial {
        self.radial.get_or_init(|| {
            let samples = self.values.len() / self.constituents.max(1);
            let (bottom, top) = self.radii;
            let span = (top - bottom) * (top + bottom);
            let step = span / (samples - 1) as f64;
            let quads = (0..samples)
                .map(|i| {
                    let s = i as f64 * step;
                    // h = √(R_g² + s) − R_g, without the cancellation.
                    let altitude = s / ((bottom * bottom + s).sqrt() + bottom);
                    std::array::from_fn(|c| {
                        self.profiles.get(c).map_or(0.0, |p| p.density(altitude)) as f32
                    })
                })
                .collect();
            Radial {
                inv_step_m2: 1.0 / step,
                quads,
            }
        })
    }

    /// Each constituent's density at `altitude_m` (clamped to the table's altitudes), into
    /// `out`.
    #[inline]
    pub fn densities(&self, altitude_m: f64, out: &mut [f64]) {
        out.iter_mut().for_each(|o| *o = 0.0);
        self.add_densities(altitude_m + self.bottom_m, 1.0, out);
    }

    /// Add `weight` × each constituent's density at radius `radius_m` (clamped to the
    /// table's altitudes) to `out`.
    #[inline]
    pub fn add_densities(&self, radius_m: f64, weight: f64, out: &mut [f64]) {
        let last = self.values.len() / self.constituents - 1;
        let x = ((radius_m - self.bottom_m) * self.inv_step_m).clamp(0.0, last as f64);
        // x ≥ 0: truncation is floor.
        let i = (x as usize).min(last - 1);
        let t = x - i as f64;
        let c = self.constituents;
        let (a, b) = (
            &self.values[i * c..(i + 1) * c],
            &self.values[(i + 1) * c..(i + 2) * c],
        );
        for ((o, a), b) in out.iter_mut().zip(a).zip(b) {
            *o += weight * (a + t * (b - a));
        }
    }

    /// [`Model::columns_along_ray`] from the table: the column (m) of each constituent
    /// along the ray from radius `r` in direction `mu` over `length_m` metres, composite
    /// 4-point Gauss–Legendre over `segments` sub-intervals, into `out`.
    pub fn columns_along_ray(
        &self,
        r: f64,
        mu: f64,
        length_m: f64,
        segments: usize,
        out: &mut [f64],
    ) {
        if self.constituents > 4 {
            out.iter_mut().for_each(|o| *o = 0.0);
            gauss_radii_along_ray(r, mu, length_m, segments, |radius, w| {
                self.add_densities(radius, w, out)
            });
            return;
        }
        // As add_densities, four constituents at a time, on the grid in r² − R_g²: at
        // distance d along the ray r² − R_g² = d² + 2rμ·d + (r − R_g)(r + R_g).
        let radial = self.radial();
        let quads = &radial.quads;
        let last = quads.len() - 1;
        let (inv_step, top) = (radial.inv_step_m2, last as f64);
        let bottom = self.radii.0;
        let (two_r_mu, s0) = (2.0 * r * mu, (r - bottom) * (r + bottom));
        let mut sum = [0.0f64; 4];
        let panels = if length_m > 0.0 { segments } else { 0 };
        let h = length_m / panels.max(1) as f64;
        let (x, w) = (GL4.nodes, GL4.weights);
        let offsets = [-x[0], x[0], -x[1], x[1]].map(|x| 0.5 * h * x);
        let weights = [w[0], w[0], w[1], w[1]].map(|w| (0.5 * h * w) as f32);
        for p in 0..panels {
            let c = (p as f64 + 0.5) * h;
            // A panel's four nodes in f32, panels summed in f64.
            let mut panel = [0.0f32; 4];
            for (o, weight) in offsets.iter().zip(weights) {
                let d = c + o;
                // max before min: a NaN reads the ground's row rather than poisoning.
                let x = ((d * d + two_r_mu * d + s0) * inv_step).max(0.0).min(top);
                // x ≥ 0: truncation is floor.
                let i = (x as usize).min(last - 1);
                let t = (x - i as f64) as f32;
                let (a, b) = (&quads[i], &quads[i + 1]);
                for c in 0..4 {
                    panel[c] += weight * (a[c] + t * (b[c] - a[c]));
                }
            }
            for c in 0..4 {
                sum[c] += panel[c] as f64;
            }
        }
        for (o, s) in out.iter_mut().zip(sum) {
            *o = s;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::atmosphere::Atmosphere;
    use crate::math::sphere;
    use crate::spectrum::Wavelengths;

    #[test]
    fn the_tabulated_columns_are_the_exact_ones() {
        for atmosphere in [Atmosphere::earth(), Atmosphere::preset("mars").unwrap()] {
            let model = atmosphere.resolve(&Wavelengths::rgb()).unwrap();
            let table = DensityTable::new(&model, DENSITY_SAMPLES);
            let n = model.constituents.len();
            let (mut exact, mut tabulated) = (vec![0.0; n], vec![0.0; n]);
            let mut worst: f64 = 0.0;
            for altitude in [0.0, 500.0, 3e3, 20e3, 60e3] {
                let r = model.bottom_radius_m + altitude;
                for i in 0..=40 {
                    let mu = -0.2 + 1.2 * i as f64 / 40.0;
                    if sphere::ray_intersects_ground(r, mu, model.bottom_radius_m) {
                        continue;
                    }
                    let d = sphere::distance_to_top_atmosphere_boundary(r, mu, model.top_radius_m);
                    model.columns_along_ray(r, mu, d, 16, &mut exact);
                    table.columns_along_ray(r, mu, d, 16, &mut tabulated);
                    for (e, t) in exact.iter().zip(&tabulated) {
                        if *e > 0.0 {
                            worst = worst.max((t - e).abs() / e);
                        }
                    }
                }
            }
            eprintln!("worst relative column error {worst:.2e}");
            assert!(worst < 2e-5, "worst relative column error {worst:e}");
        }
    }
}

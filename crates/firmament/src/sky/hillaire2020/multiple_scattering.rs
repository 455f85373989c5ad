//! The multiple-scattering pass (Hillaire 2020 §5.5, eq. 5–10). At a point at altitude h
//! with the light at zenith cosine μ_s, the light scattered once towards the point (and
//! reflected by the Lambertian ground) is gathered over the sphere, L′(ω); the transfer of
//! a unit isotropic radiance through one more scattering, f_ms (eq. 8), is gathered with
//! it; every order beyond the second is taken to scale like the second, so orders ≥ 2 sum
//! to the second times 1/(1 − f_ms) (eq. 9–10).
//!
//! Two models of the second order's field, [`MultipleScatteringModel`]:
//! - `Isotropic` (Hillaire 2020 as published, Unreal's and Bevy's): the first scattering of
//!   L′ with an isotropic phase function and the field isotropic, Ψ_ms = ⟨L′⟩/(1 − f_ms),
//!   so the march adds σ_s·Ψ_ms whatever the view direction.
//! - `Harmonics(d)` (firmament's): L′ with the constituents' own phase functions, projected
//!   on the spherical harmonics of degree ≤ d about the point's vertical and the light's
//!   azimuth ([`super::harmonics`]); the march applies each constituent's phase function to
//!   it by the Funk–Hecke theorem (exact for Rayleigh at d ≥ 2), and only the orders
//!   beyond the second stay isotropic. Measured in docs/accuracy.md: the isotropic field
//!   misses the horizon's brightening and the aerosols' forward scattering of the
//!   second order (−15 % median from the ground at a 5° sun for `earth`).
//!
//! The series needs f_ms < 1 and drifts from the truth as f_ms grows: [`F_MS_LIMIT`] is
//! where the method refuses an atmosphere.

use rayon::prelude::*;

use super::harmonics::{coefficient_count, eval, phase_moments};
use super::march::{Lighting, Lit, MarchRay, Marcher, Medium, RayProfile};
use super::params::{altitude_mu_s_of_texel, altitude_mu_s_uv};
use crate::math::quadrature::GaussLegendreRule;
use crate::math::sphere::{
    distance_to_nearest_atmosphere_boundary, horizon_mu, ray_intersects_ground,
};
use crate::math::Vec3;
use crate::medium::PhaseFunction;
use crate::sky::bruneton4d::precompute::order_tail_factors;
use crate::sky::bruneton4d::Table2;
use crate::spectrum::MAX_CHANNELS;

/// The largest f_ms the method accepts (see the module's notes and docs/accuracy.md).
pub const F_MS_LIMIT: f64 = 0.8;

/// The harmonics' degree of the fields of orders ≥ 2 (see [`compute`]).
pub const HIGHER_ORDERS_DEGREE: usize = 4;

/// The gather rule's (μ, φ) nodes for the fields of orders ≥ 2, at most.
pub const HIGHER_ORDERS_DIRECTIONS: (usize, usize) = (12, 6);

/// The gather rule of the orders ≥ 2 for the first order's `directions`: the coarser of the
/// two (CPU and GPU).
pub fn higher_orders_directions(directions: (usize, usize)) -> (usize, usize) {
    (
        directions.0.min(HIGHER_ORDERS_DIRECTIONS.0),
        directions.1.min(HIGHER_ORDERS_DIRECTIONS.1),
    )
}

/// The guard on f_ms in 1/(1 − f_ms) while the pass runs (the atmospheres that reach it are
/// refused after the pass, by [`F_MS_LIMIT`]).
pub const F_MS_GUARD: f64 = 0.999;

/// How the second order's field is represented (see the module's notes).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MultipleScatteringModel {
    /// Hillaire 2020: isotropic.
    Isotropic,
    /// Spherical harmonics up to this degree (≤ 8), from the true phase functions.
    Harmonics(usize),
}

impl MultipleScatteringModel {
    /// The harmonics' degree (0 for the isotropic field).
    pub fn degree(self) -> usize {
        match self {
            MultipleScatteringModel::Isotropic => 0,
            MultipleScatteringModel::Harmonics(d) => d,
        }
    }
}

/// The pass's result: per texel and channel the harmonic coefficients of the field of
/// orders ≥ 2 per unit light irradiance (degree 0 carries the isotropic series), and each
/// constituent's phase moments k_ℓ to apply them with.
pub struct MultipleScattering {
    /// `(μ_s, altitude)` texels of [`coefficient_count`]`(degree)` × channels values,
    /// coefficient-major.
    pub table: Table2,
    /// The harmonics' degree.
    pub degree: usize,
    /// k_ℓ (ℓ ≤ degree) per constituent (all 1/… for the isotropic model's degree 0).
    pub moments: Vec<Vec<f64>>,
    /// The largest f_ms over texels and channels.
    pub max_f_ms: f64,
    /// Where it was met: altitude (m), μ_s, channel.
    pub max_at: (f64, f64, usize),
}

/// A gather direction in the point's frame (z up, the light in the x–z plane) with its
/// solid angle (sr; the mirror image across the light's plane included).
struct GatherDirection {
    dir: Vec3,
    weight: f64,
}

/// The gather rule: Gauss–Legendre in μ on each side of the horizon (where L′ jumps from
/// the ground's to the sky's), `n_phi` midpoints in φ over [0, π] doubled by the symmetry.
fn gather_directions(r: f64, bottom: f64, n_mu: usize, n_phi: usize) -> Vec<GatherDirection> {
    let mu_h = horizon_mu(r, bottom);
    // A third of the nodes below the horizon (the ground's light is dimmer and smoother).
    let below = (n_mu / 3).max(1);
    let panels = [
        (-1.0, mu_h, below),
        (mu_h, 1.0, n_mu.saturating_sub(below).max(1)),
    ];
    let mut out = Vec::new();
    for (a, b, count) in panels {
        for (mu, w_mu) in GaussLegendreRule::new(count).on(a, b) {
            let s = (1.0 - mu * mu).max(0.0).sqrt();
            for j in 0..n_phi {
                let phi = std::f64::consts::PI * (j as f64 + 0.5) / n_phi as f64;
                out.push(GatherDirection {
                    dir: Vec3::new(s * phi.cos(), s * phi.sin(), mu),
                    weight: w_mu * 2.0 * std::f64::consts::PI / n_phi as f64,
                });
            }
        }
    }
    out
}

/// What one gather over the texels gives: per texel the field's coefficients
/// ([`coefficient_count`] × channels, coefficient-major), f_ms per channel (the first
/// gather only; empty after) and the irradiance the field delivers to a horizontal surface
/// facing up (per channel: at the bottom row, the ground's).
struct Gathered {
    field: Vec<f64>,
    f_ms: Vec<f64>,
    up_irradiance: Vec<f64>,
}

/// One texel's gather: its field's coefficients, f_ms and its upward irradiance.
type TexelGather = (Vec<f64>, Vec<f64>, Vec<f64>);

/// The radiance arriving along a gather ray (see [`Grid::gather`]).
type Incoming<'a> = dyn Fn(&MarchRay, &RayProfile, bool, &mut [f64]) + Sync + 'a;

/// The texels' geometry and the gather rule.
#[derive(Clone, Copy)]
struct Grid {
    nmu_s: usize,
    nr: usize,
    bottom: f64,
    top: f64,
    directions: (usize, usize),
    degree: usize,
    channels: usize,
}

impl Grid {
    fn texels(&self) -> usize {
        self.nmu_s * self.nr
    }

    /// Gather `incoming(ray, ground, l, scattered)` (the radiance arriving at a texel's
    /// point from the ray's direction, into `l`; ∫T·σ_s along it into `scattered` when that
    /// is not empty) over every texel's directions; `with_f_ms` sums f_ms too.
    fn gather(
        &self,
        marcher: &Marcher,
        steps: usize,
        with_f_ms: bool,
        incoming: &Incoming,
    ) -> Gathered {
        let n = self.channels;
        let coefficients = coefficient_count(self.degree);
        let p_u = PhaseFunction::Isotropic.eval(1.0);
        let n_phi = self.directions.1;
        let per_row: Vec<Vec<TexelGather>> = (0..self.nr)
            .into_par_iter()
            .map(|row| {
                let (r, _) =
                    altitude_mu_s_of_texel(0, row, self.bottom, self.top, self.nmu_s, self.nr);
                let dirs = gather_directions(r, self.bottom, self.directions.0, n_phi);
                // The directions of one μ share their geometry at every μ_s of the row: one
                // profile each.
                let profiles: Vec<RayProfile> = dirs
                    .chunks(n_phi)
                    .map(|same_mu| {
                        let mu = same_mu[0].dir.z;
                        let ground = ray_intersects_ground(r, mu, self.bottom);
                        let ray = MarchRay {
                            r,
                            mu,
                            mu_s: 1.0,
                            nu: 0.0,
                            length: distance_to_nearest_atmosphere_boundary(
                                r,
                                mu,
                                self.bottom,
                                self.top,
                                ground,
                            ),
                        };
                        let mut p = RayProfile::default();
                        marcher.profile_steps_into(&ray, steps, &mut p);
                        p
                    })
                    .collect();
                (0..self.nmu_s)
                    .map(|col| {
                        let (_, mu_s) = altitude_mu_s_of_texel(
                            col,
                            row,
                            self.bottom,
                            self.top,
                            self.nmu_s,
                            self.nr,
                        );
                        self.gather_texel(
                            r,
                            mu_s,
                            &dirs,
                            &profiles,
                            with_f_ms,
                            p_u,
                            coefficients,
                            incoming,
                        )
                    })
                    .collect()
            })
            .collect();
        let per_texel = per_row.into_iter().flatten();
        let mut out = Gathered {
            field: Vec::with_capacity(self.texels() * coefficients * n),
            f_ms: Vec::new(),
            up_irradiance: Vec::with_capacity(self.texels() * n),
        };
        for (field, f_ms, up) in per_texel {
            out.field.extend(field);
            out.f_ms.extend(f_ms);
            out.up_irradiance.extend(up);
        }
        out
    }

    /// The gather at one texel (radius `r`, the light at `mu_s`) over `dirs`, whose
    /// geometry `profiles` hold (one per μ node): its field's coefficients, f_ms when
    /// `with_f_ms` and its upward irradiance.
    #[allow(clippy::too_many_arguments)]
    fn gather_texel(
        &self,
        r: f64,
        mu_s: f64,
        dirs: &[GatherDirection],
        profiles: &[RayProfile],
        with_f_ms: bool,
        p_u: f64,
        coefficients: usize,
        incoming: &Incoming,
    ) -> TexelGather {
        let n = self.channels;
        let sun = Vec3::new((1.0 - mu_s * mu_s).max(0.0).sqrt(), 0.0, mu_s);
        let mut l = vec![0.0; n];
        let mut f_ms = vec![0.0; if with_f_ms { n } else { 0 }];
        let mut up = vec![0.0; n];
        let mut field = vec![0.0; coefficients * n];
        let mut y = vec![0.0; coefficients];
        for (gi, g) in dirs.iter().enumerate() {
            let profile = &profiles[gi / self.directions.1];
            let d = g.dir;
            let mu = d.z;
            let ground = ray_intersects_ground(r, mu, self.bottom);
            let ray = MarchRay {
                r,
                mu,
                mu_s,
                nu: d.dot(sun),
                length: distance_to_nearest_atmosphere_boundary(
                    r,
                    mu,
                    self.bottom,
                    self.top,
                    ground,
                ),
            };
            incoming(&ray, profile, ground, &mut l);
            let scattered = &profile.scattered;
            let s = (1.0 - mu * mu).max(0.0).sqrt();
            eval(self.degree, mu, if s > 0.0 { d.x / s } else { 1.0 }, &mut y);
            for (c, yc) in y.iter().enumerate() {
                for k in 0..n {
                    field[c * n + k] += g.weight * yc * l[k];
                }
            }
            if mu > 0.0 {
                for k in 0..n {
                    up[k] += g.weight * mu * l[k];
                }
            }
            for k in 0..f_ms.len() {
                f_ms[k] += g.weight * p_u * scattered[k];
            }
        }
        (field, f_ms, up)
    }

    /// A table of the field's coefficients.
    fn table(&self, field: &[f64]) -> Table2 {
        let coefficients = coefficient_count(self.degree);
        let mut table = Table2::new(self.nmu_s, self.nr, coefficients * self.channels);
        for (o, v) in table.data.iter_mut().zip(field) {
            *o = *v as f32;
        }
        table
    }

    /// The irradiance on the ground (the bottom row's) as a one-row table over μ_s.
    fn ground_table(&self, up_irradiance: &[f64]) -> Table2 {
        let mut table = Table2::new(self.nmu_s, 1, self.channels);
        for (o, v) in table.data.iter_mut().zip(up_irradiance) {
            *o = *v as f32;
        }
        table
    }
}

/// The pass over `nmu_s` × `nr` texels: `directions` = (μ nodes, φ nodes over [0, π]) per
/// texel, each ray marched in `steps` steps; `orders` is the highest scattering order
/// gathered explicitly (2: Hillaire's, the field of the light scattered once; n > 2 adds
/// the fields of orders 2 … n − 1, each marched through the previous one's), the rest by a
/// series: Hillaire's 1/(1 − f_ms) below 4 orders, from 4 on the geometric tail of the
/// last two orders' ratio (as the 4D tables' `order_tail_factors`: f_ms, the transfer of
/// an isotropic radiance at one point, reads the higher orders low on the ground, where
/// half the sphere is the ground while they were scattered in the air above).
pub(crate) fn compute(
    marcher: &Marcher,
    model_kind: MultipleScatteringModel,
    nmu_s: usize,
    nr: usize,
    directions: (usize, usize),
    steps: usize,
    orders: usize,
) -> MultipleScattering {
    let model = marcher.medium.model;
    let n = model.channels();
    let (bottom, top) = (model.bottom_radius_m, model.top_radius_m);
    let degree = model_kind.degree();
    let coefficients = coefficient_count(degree);
    let grid = Grid {
        nmu_s,
        nr,
        bottom,
        top,
        directions,
        degree,
        channels: n,
    };
    let moments: Vec<Vec<f64>> = match model_kind {
        // The isotropic field is seen through an isotropic phase: k₀ = 1.
        MultipleScatteringModel::Isotropic => vec![vec![1.0]; model.constituents.len()],
        MultipleScatteringModel::Harmonics(_) => model
            .constituents
            .iter()
            .map(|c| phase_moments(&c.phase, degree))
            .collect(),
    };
    // Order 1: the light scattered once towards the point, and the Lambertian ground lit by
    // the light (eq. 6), with f_ms (eq. 8).
    let isotropic = {
        let mut p = Vec::new();
        marcher.medium.isotropic_phases(&mut p);
        p
    };
    let first = grid.gather(marcher, steps, true, &|ray, profile, ground, l| {
        match model_kind {
            MultipleScatteringModel::Isotropic => {
                marcher.march_profile(ray, profile, &isotropic, &Lighting::ALL, l)
            }
            MultipleScatteringModel::Harmonics(_) => {
                let mut phases = Vec::new();
                marcher.medium.phases(ray.nu, &mut phases);
                marcher.march_profile(ray, profile, &phases, &Lighting::ALL, l)
            }
        }
        let t = &profile.transmittance;
        if ground {
            let (r_g, mu_s_g) = ray.at(ray.length);
            let mut t_sun = [0.0; MAX_CHANNELS];
            marcher
                .lookup
                .transmittance_to_sun(r_g, mu_s_g, &mut t_sun[..n]);
            let cos = mu_s_g.max(0.0);
            for k in 0..n {
                l[k] += t[k] * t_sun[k] * cos * model.ground_albedo[k] / std::f64::consts::PI;
            }
        }
    });
    let f_ms = first.f_ms.clone();
    let mut sum = first.field.clone();
    let mut order_means = vec![degree_zero_means(&first.field, coefficients, n)];
    let mut last = first;
    // The higher orders' fields are smoother (diffuse light from everywhere): degree ≤ 2
    // (exact under Rayleigh's phase function, whose moments vanish beyond it) and a
    // coarser gather rule.
    let next_grid = Grid {
        degree: degree.min(HIGHER_ORDERS_DEGREE),
        directions: higher_orders_directions(directions),
        ..grid
    };
    let next_coefficients = coefficient_count(next_grid.degree);
    let mut last_grid = &grid;
    // Orders 2 … orders − 1 of the field: each marched through the previous order's field
    // (its phase functions applied by Funk–Hecke), and the ground lit by its irradiance.
    for _ in 2..orders {
        let previous = MultipleScattering {
            table: last_grid.table(&last.field),
            degree: last_grid.degree,
            moments: moments.clone(),
            max_f_ms: 0.0,
            max_at: (0.0, 0.0, 0),
        };
        let ground_irradiance = grid.ground_table(&last.up_irradiance[..nmu_s * n]);
        let through = Marcher::new(Medium::new(model), marcher.lookup, Some(&previous));
        let unlit = Lighting {
            single: Lit::Intervals(&[]),
            multiple: Lit::All,
        };
        let next = next_grid.gather(marcher, steps, false, &|ray, profile, ground, l| {
            through.march_profile(ray, profile, &[], &unlit, l);
            let t = &profile.transmittance;
            if ground {
                let (r_g, mu_s_g) = ray.at(ray.length);
                let (u, _) = altitude_mu_s_uv(r_g, bottom, top, mu_s_g, nmu_s, nr);
                let mut e = vec![0.0; n];
                ground_irradiance.sample_into(u, 0.5, &mut e);
                for k in 0..n {
                    l[k] += t[k] * e[k] * model.ground_albedo[k] / std::f64::consts::PI;
                }
            }
        });
        add_field(
            &mut sum,
            coefficients,
            &next.field,
            next_coefficients,
            n,
            &[1.0; MAX_CHANNELS][..n],
        );
        order_means.push(degree_zero_means(&next.field, next_coefficients, n));
        last = next;
        last_grid = &next_grid;
    }
    let last_coefficients = coefficient_count(last_grid.degree);
    // The orders beyond: the geometric tail of the last two orders' ratio (the table's
    // means; from 4 orders, the first field being far from the high orders' shape), or
    // Hillaire's series on the last order's mean, texel by texel (guarded here; compute()
    // refuses f_ms ≥ the limit).
    match order_tail_factors(&order_means) {
        Some(factors) => add_field(
            &mut sum,
            coefficients,
            &last.field,
            last_coefficients,
            n,
            &factors,
        ),
        None => {
            let (per_texel, per_last) = (coefficients * n, last_coefficients * n);
            for (i, texel) in sum.chunks_mut(per_texel).enumerate() {
                for k in 0..n {
                    let f = f_ms[i * n + k].min(F_MS_GUARD);
                    texel[k] += last.field[i * per_last + k] * f / (1.0 - f);
                }
            }
        }
    }
    let mut max = (0.0f64, 1.0, 0usize, 0.0);
    for i in 0..grid.texels() {
        let (r, mu_s) = altitude_mu_s_of_texel(i % nmu_s, i / nmu_s, bottom, top, nmu_s, nr);
        for k in 0..n {
            if f_ms[i * n + k] > max.0 {
                max = (f_ms[i * n + k], mu_s, k, r - bottom);
            }
        }
    }
    MultipleScattering {
        table: grid.table(&sum),
        degree,
        moments,
        max_f_ms: max.0,
        max_at: (max.3, max.1, max.2),
    }
}

/// `sum` (`coefficients` per texel and channel) += `field` (`field_coefficients` ≤ them, the
/// lower degrees) × `factors` per channel.
fn add_field(
    sum: &mut [f64],
    coefficients: usize,
    field: &[f64],
    field_coefficients: usize,
    n: usize,
    factors: &[f64],
) {
    for (s, f) in sum
        .chunks_mut(coefficients * n)
        .zip(field.chunks(field_coefficients * n))
    {
        for (i, v) in f.iter().enumerate() {
            s[i] += factors[i % n] * v;
        }
    }
}

/// The table-wide mean of each channel's degree-0 coefficient (the field's mean radiance
/// up to 1/Y₀₀), for the orders' ratio.
fn degree_zero_means(field: &[f64], coefficients: usize, n: usize) -> Vec<f64> {
    let texels = field.len() / (coefficients * n);
    let mut means = vec![0.0; n];
    for texel in field.chunks(coefficients * n) {
        for k in 0..n {
            means[k] += texel[k] / texels as f64;
        }
    }
    means
}

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
use super::march::{Lighting, MarchRay, Marcher};
use super::params::altitude_mu_s_of_texel;
use crate::math::quadrature::GaussLegendreRule;
use crate::math::sphere::{
    distance_to_nearest_atmosphere_boundary, horizon_mu, ray_intersects_ground,
};
use crate::math::Vec3;
use crate::medium::PhaseFunction;
use crate::sky::bruneton4d::Table2;

/// The largest f_ms the method accepts (see the module's notes and docs/accuracy.md).
pub const F_MS_LIMIT: f64 = 0.8;

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

/// The pass over `nmu_s` × `nr` texels: `directions` = (μ nodes, φ nodes over [0, π]) per
/// texel, each ray marched in `steps` steps.
pub(crate) fn compute(
    marcher: &Marcher,
    model_kind: MultipleScatteringModel,
    nmu_s: usize,
    nr: usize,
    directions: (usize, usize),
    steps: usize,
) -> MultipleScattering {
    let model = marcher.medium.model;
    let n = model.channels();
    let (bottom, top) = (model.bottom_radius_m, model.top_radius_m);
    let degree = model_kind.degree();
    let coefficients = coefficient_count(degree);
    let moments: Vec<Vec<f64>> = model
        .constituents
        .iter()
        .map(|c| phase_moments(&c.phase, degree))
        .collect();
    let mut table = Table2::new(nmu_s, nr, coefficients * n);
    let p_u = PhaseFunction::Isotropic.eval(1.0);
    let texels: Vec<(f64, f64, usize, f64)> = table
        .data
        .par_chunks_mut(coefficients * n)
        .enumerate()
        .map(|(i, out)| {
            let (r, mu_s) = altitude_mu_s_of_texel(i % nmu_s, i / nmu_s, bottom, top, nmu_s, nr);
            let sun = Vec3::new((1.0 - mu_s * mu_s).max(0.0).sqrt(), 0.0, mu_s);
            let mut phases = Vec::new();
            let (mut l, mut t, mut scattered, mut t_sun) =
                (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
            let mut f_ms = vec![0.0; n];
            let mut field = vec![0.0; coefficients * n];
            let mut y = vec![0.0; coefficients];
            for g in gather_directions(r, bottom, directions.0, directions.1) {
                let d = g.dir;
                let mu = d.z;
                let ground = ray_intersects_ground(r, mu, bottom);
                let ray = MarchRay {
                    r,
                    mu,
                    mu_s,
                    nu: d.dot(sun),
                    length: distance_to_nearest_atmosphere_boundary(r, mu, bottom, top, ground),
                };
                match model_kind {
                    MultipleScatteringModel::Isotropic => {
                        marcher.medium.isotropic_phases(&mut phases)
                    }
                    MultipleScatteringModel::Harmonics(_) => {
                        marcher.medium.phases(ray.nu, &mut phases)
                    }
                }
                marcher.march(
                    &ray,
                    steps,
                    &phases,
                    &Lighting::ALL,
                    &mut l,
                    &mut t,
                    &mut scattered,
                );
                if ground {
                    // The Lambertian ground lit by the light (eq. 6's ground term).
                    let (r_g, mu_s_g) = ray.at(ray.length);
                    marcher.lookup.transmittance_to_sun(r_g, mu_s_g, &mut t_sun);
                    let cos = mu_s_g.max(0.0);
                    for k in 0..n {
                        l[k] +=
                            t[k] * t_sun[k] * cos * model.ground_albedo[k] / std::f64::consts::PI;
                    }
                }
                let s = (1.0 - mu * mu).max(0.0).sqrt();
                eval(degree, mu, if s > 0.0 { d.x / s } else { 1.0 }, &mut y);
                for (c, yc) in y.iter().enumerate() {
                    for k in 0..n {
                        field[c * n + k] += g.weight * yc * l[k];
                    }
                }
                for k in 0..n {
                    f_ms[k] += g.weight * p_u * scattered[k];
                }
            }
            let mut worst = (0.0f64, 0usize);
            for k in 0..n {
                if f_ms[k] > worst.0 {
                    worst = (f_ms[k], k);
                }
                // Degree 0 carries the second order's mean and the isotropic series of the
                // higher orders: ×1/(1 − f_ms) (guarded here; compute() refuses f ≥ the
                // limit).
                field[k] /= 1.0 - f_ms[k].min(F_MS_GUARD);
            }
            for (o, v) in out.iter_mut().zip(&field) {
                *o = *v as f32;
            }
            (worst.0, mu_s, worst.1, r - bottom)
        })
        .collect();
    let (max_f_ms, mu_s, channel, altitude) = texels
        .into_iter()
        .fold((0.0, 1.0, 0, 0.0), |a, b| if b.0 > a.0 { b } else { a });
    MultipleScattering {
        table,
        degree,
        moments: match model_kind {
            // The isotropic field is seen through an isotropic phase: k₀ = 1.
            MultipleScatteringModel::Isotropic => vec![vec![1.0]; model.constituents.len()],
            MultipleScatteringModel::Harmonics(_) => moments,
        },
        max_f_ms,
        max_at: (altitude, mu_s, channel),
    }
}

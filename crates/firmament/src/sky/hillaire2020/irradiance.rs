//! The sky's irradiance on a horizontal surface, E(r, μ_s) = ∫_{μ>0} L(ω)·μ dω, from the
//! method's own radiance (single scattering with the constituents' phase functions plus
//! σ_s·Ψ_ms, marched as the sky view is). Hillaire 2020 leaves the sky's light on surfaces
//! to the engine (Unreal captures the sky into a sky light); a table of the same form as
//! Bruneton's irradiance table answers [`crate::sky::SkyView::sun_and_sky_irradiance`]
//! anywhere in the air, as the 4D method does.

use rayon::prelude::*;

use super::march::{Lighting, MarchRay, Marcher, RayProfile};
use super::params::altitude_mu_s_of_texel;
use crate::math::lattice::band_directions;
use crate::math::sphere::distance_to_top_atmosphere_boundary;
use crate::math::Vec3;
use crate::sky::bruneton4d::Table2;
use crate::spectrum::with_channel_buffers;

/// The table per unit light irradiance (W·m⁻²·nm⁻¹ per W·m⁻²·nm⁻¹ at the top), `nmu_s` ×
/// `nr` texels; `directions` over the upper hemisphere (a Fibonacci lattice uniform in μ,
/// each 2π/n sr), each marched in `steps` steps.
pub(crate) fn compute(
    marcher: &Marcher,
    nmu_s: usize,
    nr: usize,
    directions: usize,
    steps: usize,
) -> Table2 {
    let model = marcher.medium.model;
    let n = model.channels();
    let (bottom, top) = (model.bottom_radius_m, model.top_radius_m);
    let dirs = band_directions(Vec3::Z, 0.0, 1.0, directions);
    let weight = 2.0 * std::f64::consts::PI / dirs.len() as f64;
    let mut table = Table2::new(nmu_s, nr, n);
    table
        .data
        .par_chunks_mut(nmu_s * n)
        .enumerate()
        .for_each(|(row, out_row)| {
            // A direction's geometry is the same at every μ_s of the row: one profile each.
            let (r, _) = altitude_mu_s_of_texel(0, row, bottom, top, nmu_s, nr);
            let profiles: Vec<RayProfile> = dirs
                .iter()
                .map(|d| {
                    let ray = MarchRay {
                        r,
                        mu: d.z,
                        mu_s: 1.0,
                        nu: 0.0,
                        length: distance_to_top_atmosphere_boundary(r, d.z, top),
                    };
                    let mut p = RayProfile::default();
                    marcher.profile_steps_into(&ray, steps, &mut p);
                    p
                })
                .collect();
            let mut phases = Vec::new();
            for (col, out) in out_row.chunks_mut(n).enumerate() {
                let (_, mu_s) = altitude_mu_s_of_texel(col, row, bottom, top, nmu_s, nr);
                let sun = Vec3::new((1.0 - mu_s * mu_s).max(0.0).sqrt(), 0.0, mu_s);
                with_channel_buffers(n, |[e, l]| {
                    for (d, profile) in dirs.iter().zip(&profiles) {
                        let nu = d.dot(sun);
                        marcher.medium.phases(nu, &mut phases);
                        let ray = MarchRay {
                            r,
                            mu: d.z,
                            mu_s,
                            nu,
                            length: distance_to_top_atmosphere_boundary(r, d.z, top),
                        };
                        marcher.march_profile(&ray, profile, &phases, &Lighting::ALL, l);
                        for k in 0..n {
                            e[k] += l[k] * d.z * weight;
                        }
                    }
                    for k in 0..n {
                        out[k] = e[k] as f32;
                    }
                });
            }
        });
    table
}

//! The direct irradiance pass: the sun's irradiance on a horizontal surface (paper eq. 14's
//! first order), the start of the ground irradiance sum.

use crate::atmosphere::Model;
use crate::sky::bruneton4d::lookup::Lookup;
use crate::sky::bruneton4d::params;
use crate::sky::bruneton4d::table::Table2;

/// Direct sun irradiance on a horizontal surface, E = E_sun·T·(average cosine over the
/// partially visible disk) (Bruneton 2017 `ComputeDirectIrradiance`).
pub(super) fn compute_direct_irradiance(model: &Model, lookup: &Lookup) -> Table2 {
    let s = &lookup.sizes;
    let n = model.channels();
    let mut e = Table2::new(s.irradiance_mu_s, s.irradiance_r, n);
    let alpha_s = model.sun_angular_radius_rad;
    let mut tr = vec![0.0; n];
    for y in 0..s.irradiance_r {
        for x in 0..s.irradiance_mu_s {
            let (r, mu_s) = params::irradiance_texel(&lookup.radii, s, x, y);
            let cos_factor = if mu_s < -alpha_s {
                0.0
            } else if mu_s > alpha_s {
                mu_s
            } else {
                (mu_s + alpha_s) * (mu_s + alpha_s) / (4.0 * alpha_s)
            };
            lookup.transmittance_to_top(r, mu_s, &mut tr);
            let i = (y * s.irradiance_mu_s + x) * n;
            for k in 0..n {
                e.data[i + k] = (model.solar_irradiance[k] * tr[k] * cos_factor) as f32;
            }
        }
    }
    e
}

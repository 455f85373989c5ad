//! The light's direct irradiance and the sky's irradiance on a surface (Bruneton & Neyret
//! 2008 eq. 16; Bruneton 2017 `GetSunAndSkyIrradiance`), for any sky method that knows the
//! sky's irradiance on a horizontal surface at (r, μ_s).

use super::bruneton4d::Lookup;
use crate::math::Vec3;
use crate::scene::light::Light;

/// Into `direct` the light's beam on a surface at `point` (planet-centred, m) with unit
/// `normal` (transmittance, the planet's occlusion of the disk, the cosine of incidence),
/// into `sky` the sky's light: `horizontal(r, μ_s, out)`, the method's irradiance on a
/// horizontal surface at radius r (clamped to the ground) under the light at zenith cosine
/// μ_s, already scaled to this light, times the (1 + n·n̄)/2 occlusion factor. Above the
/// atmosphere, the direct beam only (there is no air above).
pub fn sun_and_sky_irradiance(
    lookup: &Lookup,
    light: &Light,
    point: Vec3,
    normal: Vec3,
    horizontal: impl FnOnce(f64, f64, &mut [f64]),
    direct: &mut [f64],
    sky: &mut [f64],
) {
    let n = light.irradiance.len();
    let length = point.length();
    let cos = normal.dot(light.direction).max(0.0);
    if length > lookup.radii.top {
        sky[..n].iter_mut().for_each(|v| *v = 0.0);
        lookup.transmittance_to_light(point, light.direction, direct);
    } else {
        let r = length.max(lookup.radii.bottom);
        let mu_s = (point.dot(light.direction) / length).clamp(-1.0, 1.0);
        horizontal(r, mu_s, sky);
        let occlusion = (1.0 + normal.dot(point) / length) * 0.5;
        sky[..n].iter_mut().for_each(|v| *v *= occlusion);
        lookup.transmittance_to_sun(r, mu_s, direct);
    }
    for k in 0..n {
        direct[k] *= light.irradiance[k] * cos;
    }
}

//! The sun's transmittance averaged over the view–sun azimuth: what dropping the azimuth
//! (Elek 2009) asks of single scattering.
//!
//! The 3D table holds the azimuthal mean of the 4D single scattering,
//! S₃(r, μ, μ_s) = (1/π)∫₀^π S₄(r, μ, μ_s, ν(φ)) dφ, ν(φ) = μμ_s + √(1−μ²)√(1−μ_s²)·cos φ.
//! Along the ray only the sun's transmittance depends on φ: a sample at central angle α
//! from the ray's origin sees the sun at zenith cosine μ_s·cos α + √(1−μ_s²)·sin α·cos φ.
//! So the mean moves inside the ray integral, S₃ = E∫β·T(0, t)·M(r_t, α_t, μ_s) dt, with
//! M(r′, α, μ_s) = (1/π)∫₀^π T_sun(r′, μ_s·cos α + √(1−μ_s²)·sin α·cos φ) dφ the mean
//! transmittance to the suns on a cone: three parameters, tabulated once (radius × angle
//! × the table's own μ_s texels, so that no interpolation in μ_s is needed) and read
//! bilinearly per ray sample, in place of a 4D table's ray integral per azimuth.
//!
//! The mean is taken over the sunlit part of the azimuths only, where the planet does not
//! hide the sun (cos φ above a bound from the shadow's edge), by Gauss–Legendre: the
//! integrand is smooth there and the edge of Earth's shadow falls on the interval's end.

use std::f64::consts::PI;

use rayon::prelude::*;

use super::params::Params;
use crate::math::quadrature::GaussLegendreRule;
use crate::math::sphere::safe_sqrt;
use crate::sky::bruneton4d::lookup::Lookup;
use crate::sky::bruneton4d::params::transmittance_uv;
use crate::sky::bruneton4d::table::lerp_weights;

/// M(r′, α, μ_s) on a grid: radii dense near the ground (h = H·(k/(n−1))²), central angles
/// uniform over [0, α_max] (the widest angle a chord of the atmosphere spans), the table's
/// μ_s texels.
pub(super) struct SunCone {
    nr: usize,
    nalpha: usize,
    nmu_s: usize,
    channels: usize,
    bottom: f64,
    height: f64,
    alpha_max: f64,
    /// `[((i_r·nalpha + i_alpha)·nmu_s + x)·channels + k]`.
    data: Vec<f64>,
}

impl SunCone {
    /// The table for `params`' μ_s texels: `nr` × `nalpha` texels, `nodes` Gauss–Legendre
    /// nodes over each sunlit azimuth range.
    pub fn new(lookup: &Lookup, params: &Params, nr: usize, nalpha: usize, nodes: usize) -> Self {
        let n = lookup.optical_depth.channels;
        let nmu_s = params.nmu_s;
        let (bottom, top) = (params.bottom, params.top);
        let alpha_max = 2.0 * (bottom / top).clamp(-1.0, 1.0).acos();
        let rule = GaussLegendreRule::new(nodes);
        let mu_s: Vec<(f64, f64)> = (0..nmu_s)
            .map(|x| {
                let m = params.texel_mu_s(x);
                (m, safe_sqrt(1.0 - m * m))
            })
            .collect();
        let mut cone = SunCone {
            nr,
            nalpha,
            nmu_s,
            channels: n,
            bottom,
            height: top - bottom,
            alpha_max,
            data: vec![0.0; nr * nalpha * nmu_s * n],
        };
        let slab = nalpha * nmu_s * n;
        let height = cone.height;
        cone.data
            .par_chunks_mut(slab)
            .enumerate()
            .for_each(|(i_r, out)| {
                let x = i_r as f64 / (nr - 1) as f64;
                let r = bottom + height * x * x;
                let row = SunRow::new(lookup, r);
                let mut t = vec![0.0; n];
                let mut acc = vec![0.0; n];
                for i_alpha in 0..nalpha {
                    let alpha = alpha_max * i_alpha as f64 / (nalpha - 1) as f64;
                    let (sin_a, cos_a) = alpha.sin_cos();
                    for (x, &(m, s)) in mu_s.iter().enumerate() {
                        let o = &mut out[(i_alpha * nmu_s + x) * n..][..n];
                        let (a, b) = (m * cos_a, s * sin_a);
                        row.cone_mean(lookup, &rule, a, b, &mut t, &mut acc);
                        o.copy_from_slice(&acc);
                    }
                }
            });
        cone
    }

    /// M at radius `r` (m) and central angle (cos α, sin α) for every μ_s texel, into `out`
    /// (`[x·channels + k]`, overwritten): bilinear in (radius, angle).
    #[inline]
    pub fn blend_into(&self, r: f64, cos_alpha: f64, sin_alpha: f64, out: &mut [f64]) {
        let x_r = ((r - self.bottom) / self.height).clamp(0.0, 1.0).sqrt();
        let alpha = sin_alpha.atan2(cos_alpha).max(0.0);
        // Texture coordinates of the texel-centred grids with their ends at 0 and 1.
        let u = |x: f64, n: usize| (x * (n - 1) as f64 + 0.5) / n as f64;
        let (r0, r1, tr) = lerp_weights(u(x_r, self.nr), self.nr);
        let (a0, a1, ta) = lerp_weights(u(alpha / self.alpha_max, self.nalpha), self.nalpha);
        let len = self.nmu_s * self.channels;
        let at = |i_r: usize, i_a: usize| &self.data[(i_r * self.nalpha + i_a) * len..][..len];
        let (w00, w01, w10, w11) = (
            (1.0 - tr) * (1.0 - ta),
            (1.0 - tr) * ta,
            tr * (1.0 - ta),
            tr * ta,
        );
        let (d00, d01, d10, d11) = (at(r0, a0), at(r0, a1), at(r1, a0), at(r1, a1));
        for (i, o) in out[..len].iter_mut().enumerate() {
            *o = w00 * d00[i] + w01 * d01[i] + w10 * d10[i] + w11 * d11[i];
        }
    }
}

/// The optical-depth table filtered to one radius, for the transmittance towards many suns
/// from there (as [`Lookup::transmittance_to_sun`], which filters both axes per call).
struct SunRow {
    r: f64,
    /// −√(1 − (R_g/r)²): the horizon's zenith cosine.
    cos_horizon: f64,
    /// Half-width in μ_s of the sun's disk setting behind the horizon.
    edge: f64,
    row: Vec<f64>,
}

impl SunRow {
    fn new(lookup: &Lookup, r: f64) -> SunRow {
        let radii = &lookup.radii;
        let s = &lookup.sizes;
        let table = lookup.optical_depth;
        let (_, v) = transmittance_uv(radii, r, 1.0, s.transmittance_mu, s.transmittance_r);
        let (y0, y1, ty) = lerp_weights(v, s.transmittance_r);
        let w = table.width * table.channels;
        let (row0, row1) = (&table.data[y0 * w..][..w], &table.data[y1 * w..][..w]);
        let sin_h = radii.bottom / r;
        SunRow {
            r,
            cos_horizon: -safe_sqrt(1.0 - sin_h * sin_h),
            edge: sin_h * lookup.sun_angular_radius,
            row: (row0.iter().zip(row1))
                .map(|(a, b)| (1.0 - ty) * *a as f64 + ty * *b as f64)
                .collect(),
        }
    }

    /// T_sun(r, μ_s) with the planet's occlusion of the disk, into `out`.
    #[inline]
    fn transmittance_to_sun(&self, lookup: &Lookup, mu_s: f64, out: &mut [f64]) {
        let fraction = lookup.sun_visible_fraction(self.r, mu_s);
        if fraction <= 0.0 {
            out.iter_mut().for_each(|o| *o = 0.0);
            return;
        }
        let s = &lookup.sizes;
        let (u, _) = transmittance_uv(&lookup.radii, self.r, mu_s, s.transmittance_mu, 2);
        let (x0, x1, t) = lerp_weights(u, s.transmittance_mu);
        let n = out.len();
        let (a, b) = (&self.row[x0 * n..][..n], &self.row[x1 * n..][..n]);
        for k in 0..n {
            out[k] = fraction * (-((1.0 - t) * a[k] + t * b[k])).exp();
        }
    }

    /// (1/π)∫₀^π T_sun(a + b·cos φ) dφ into `acc`, over the azimuths where the sun is not
    /// wholly behind the planet; `t` is scratch.
    fn cone_mean(
        &self,
        lookup: &Lookup,
        rule: &GaussLegendreRule,
        a: f64,
        b: f64,
        t: &mut [f64],
        acc: &mut [f64],
    ) {
        if b < 1e-9 {
            self.transmittance_to_sun(lookup, a, acc);
            return;
        }
        acc.iter_mut().for_each(|v| *v = 0.0);
        // The disk is partly visible where a + b·cos φ > cos_horizon − edge.
        let c = (self.cos_horizon - self.edge - a) / b;
        if c >= 1.0 {
            return;
        }
        let phi_lit = if c <= -1.0 { PI } else { c.acos() };
        for (phi, w) in rule.on(0.0, phi_lit) {
            self.transmittance_to_sun(lookup, a + b * phi.cos(), t);
            for (o, v) in acc.iter_mut().zip(t.iter()) {
                *o += w * v;
            }
        }
        acc.iter_mut().for_each(|v| *v /= PI);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::atmosphere::Atmosphere;
    use crate::sky::bruneton4d::precompute::compute_optical_depth;
    use crate::sky::elek3d::Elek3dConfig;
    use crate::spectrum::Wavelengths;

    /// The table read between its texels against the mean over 2000 azimuths of the
    /// transmittance lookup itself: within 1 % of the sun's unattenuated light (or 2 % of
    /// the value) everywhere, including the suns setting behind the planet, where M falls
    /// from its lit value to 0 within a few tenths of a degree.
    #[test]
    fn the_cone_table_is_the_azimuthal_mean_of_the_sun_transmittance() {
        let model = Atmosphere::earth().resolve(&Wavelengths::rgb()).unwrap();
        let config = Elek3dConfig::default();
        let sizes = config.table_sizes();
        let optical_depth = compute_optical_depth(&model, &sizes);
        let lookup = Lookup::new(&model, sizes, &optical_depth);
        let params = Params::new(&model, &config);
        let (nr, na) = config.sun_cone;
        let cone = SunCone::new(&lookup, &params, nr, na, config.azimuth_nodes);
        let n = 3;
        let mut row = vec![0.0; params.nmu_s * n];
        let mut t = vec![0.0; n];
        let mut worst: f64 = 0.0;
        for &h in &[3.0, 700.0, 4_100.0, 23_000.0] {
            let r = model.bottom_radius_m + h;
            for &alpha in &[0.0, 0.0123, 0.061, 0.19] {
                let (sin_a, cos_a) = f64::sin_cos(alpha);
                cone.blend_into(r, cos_a, sin_a, &mut row);
                for x in 0..params.nmu_s {
                    let mu_s = params.texel_mu_s(x);
                    let s = (1.0 - mu_s * mu_s).sqrt();
                    let mut want = [0.0; 3];
                    let m = 2000;
                    for j in 0..m {
                        let phi = PI * (j as f64 + 0.5) / m as f64;
                        lookup.transmittance_to_sun(
                            r,
                            mu_s * cos_a + s * sin_a * phi.cos(),
                            &mut t,
                        );
                        for k in 0..n {
                            want[k] += t[k] / m as f64;
                        }
                    }
                    for k in 0..n {
                        let got = row[x * n + k];
                        let err = (got - want[k]).abs();
                        worst = worst.max(err);
                        assert!(
                            err < 0.01 || err < 0.02 * want[k],
                            "h {h} α {alpha} μ_s {mu_s} channel {k}: {got} vs {want:?}"
                        );
                    }
                }
            }
        }
        assert!(worst > 0.0);
    }
}

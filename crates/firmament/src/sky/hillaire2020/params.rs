//! The parameterisations of Hillaire 2020's tables (*A Scalable and Production Ready Sky and
//! Atmosphere Rendering Technique*, EGSR 2020, §5), texel-centre exact as in Bruneton 2017.
//!
//! - Transmittance: Bruneton's (r, μ) mapping, shared with the 4D tables
//!   ([`crate::sky::bruneton4d::params::transmittance_uv`]; Hillaire §5.1 uses it too).
//! - Multiple scattering Ψ_ms and the sky irradiance: Hillaire's (§5.5) are linear in the
//!   light's zenith cosine (μ_s·½ + ½) and in the altitude fraction; ours are dense around
//!   the horizon in μ_s and near the ground in altitude ([`altitude_mu_s_uv`]).
//! - Sky view (§5.3): the azimuth from the light as u = sin(φ/2) (the released demo's
//!   mapping: texels densest towards the light, where the aerosols' forward peak lies), the
//!   view's angle from the zenith split at the geometric horizon, each half squashed
//!   towards it by a square root (the horizon band changes fastest).

use crate::math::sphere::safe_sqrt;
use crate::sky::bruneton4d::params::{texcoord_from_unit, unit_from_texcoord};
use std::f64::consts::PI;

/// Zenith angle (rad) of the geometric horizon seen from radius `r` over a ground of
/// radius `bottom` (π/2 on the ground, more above it).
#[inline]
pub fn horizon_zenith_angle(r: f64, bottom: f64) -> f64 {
    let cos_beta = safe_sqrt(r * r - bottom * bottom) / r;
    PI - cos_beta.clamp(-1.0, 1.0).acos()
}

/// The sky-view table's (u, v) for a view of zenith cosine `mu` whose azimuth is `cos_phi`
/// from the light's, seen from radius `r` (m) over a ground of radius `bottom` (m), in a
/// table of `nu` × `nv` texels.
#[inline]
pub fn sky_view_uv(r: f64, bottom: f64, mu: f64, cos_phi: f64, nu: usize, nv: usize) -> (f64, f64) {
    let zenith_horizon = horizon_zenith_angle(r.max(bottom), bottom);
    let beta = PI - zenith_horizon;
    let theta = mu.clamp(-1.0, 1.0).acos();
    let y = if theta < zenith_horizon {
        0.5 * (1.0 - safe_sqrt(1.0 - theta / zenith_horizon))
    } else {
        0.5 + 0.5 * safe_sqrt((theta - zenith_horizon) / beta)
    };
    let x = safe_sqrt(0.5 - 0.5 * cos_phi.clamp(-1.0, 1.0));
    (
        texcoord_from_unit(x, nu),
        texcoord_from_unit(y.min(1.0), nv),
    )
}

/// Inverse of [`sky_view_uv`]: (μ, cos φ) at (u, v).
#[inline]
pub fn sky_view_mu_cos_phi(
    r: f64,
    bottom: f64,
    u: f64,
    v: f64,
    nu: usize,
    nv: usize,
) -> (f64, f64) {
    let zenith_horizon = horizon_zenith_angle(r.max(bottom), bottom);
    let beta = PI - zenith_horizon;
    let x = unit_from_texcoord(u, nu).clamp(0.0, 1.0);
    let y = unit_from_texcoord(v, nv).clamp(0.0, 1.0);
    let theta = if y < 0.5 {
        let c = 1.0 - 2.0 * y;
        zenith_horizon * (1.0 - c * c)
    } else {
        let c = 2.0 * y - 1.0;
        zenith_horizon + beta * c * c
    };
    (theta.cos(), 1.0 - 2.0 * x * x)
}

/// How much denser than Hillaire's linear columns the multiple-scattering and irradiance
/// tables' μ_s columns are at the horizon: μ_s = sinh(k·x)/sinh(k) over x ∈ [−1, 1], whose
/// slope at x = 0 is k/sinh(k) (0.30 for k = 3: 3.3× the columns, sparser towards the
/// zenith and the nadir, where the fields change slowly). Twilight is where they change
/// fastest: with Hillaire's linear 32 columns (u = μ_s/2 + 1/2) the sky under a sun at 0°
/// and −3° read +7 % and +18 % against the 4D tables (docs/accuracy.md).
pub const MU_S_HORIZON_STRETCH: f64 = 3.0;

/// x ∈ [−1, 1] of the light's zenith cosine μ_s in those columns (see
/// [`MU_S_HORIZON_STRETCH`]).
#[inline]
pub fn mu_s_unit(mu_s: f64) -> f64 {
    let k = MU_S_HORIZON_STRETCH;
    (mu_s.clamp(-1.0, 1.0) * k.sinh()).asinh() / k
}

/// Inverse of [`mu_s_unit`].
#[inline]
pub fn mu_s_of_unit(x: f64) -> f64 {
    let k = MU_S_HORIZON_STRETCH;
    ((x.clamp(-1.0, 1.0) * k).sinh() / k.sinh()).clamp(-1.0, 1.0)
}

/// The (u, v) of the multiple-scattering and irradiance tables at radius `r` (m) and light
/// zenith cosine `mu_s` between the ground `bottom` and the top `top` (m). Both axes are
/// firmament's change to Hillaire's linear ones. The rows are quadratic in altitude
/// (v = √(h/H)): 32 linear rows over Earth's 60 km put the first above the ground at
/// 1.9 km, above most of the aerosols (scale height 1.2 km), and the sky from 0–1 km under
/// a low sun read 2–3 % dark with p95 8–10 % against the 4D tables; quadratic, the first is
/// at 60 m and those figures fall to 0.8 % and 5 % (docs/accuracy.md). The columns are
/// dense around the horizon ([`MU_S_HORIZON_STRETCH`]).
#[inline]
pub fn altitude_mu_s_uv(
    r: f64,
    bottom: f64,
    top: f64,
    mu_s: f64,
    nmu_s: usize,
    nr: usize,
) -> (f64, f64) {
    let x_r = ((r - bottom) / (top - bottom)).clamp(0.0, 1.0).sqrt();
    let x_mu_s = (mu_s_unit(mu_s) * 0.5 + 0.5).clamp(0.0, 1.0);
    (
        texcoord_from_unit(x_mu_s, nmu_s),
        texcoord_from_unit(x_r, nr),
    )
}

/// Inverse of [`altitude_mu_s_uv`] at texel (x, y): (r, μ_s).
#[inline]
pub fn altitude_mu_s_of_texel(
    x: usize,
    y: usize,
    bottom: f64,
    top: f64,
    nmu_s: usize,
    nr: usize,
) -> (f64, f64) {
    let x_mu_s = unit_from_texcoord((x as f64 + 0.5) / nmu_s as f64, nmu_s);
    let x_r = unit_from_texcoord((y as f64 + 0.5) / nr as f64, nr);
    (
        bottom + x_r * x_r * (top - bottom),
        mu_s_of_unit(2.0 * x_mu_s - 1.0),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sky_view_mapping_round_trips_on_both_sides_of_the_horizon() {
        let bottom: f64 = 6_360e3;
        for r in [bottom, bottom + 10.0, bottom + 5e3, bottom + 80e3] {
            for &mu in &[-1.0, -0.5, -0.01, 0.0, 0.02, 0.3, 0.9, 1.0] {
                for &c in &[-1.0, -0.3, 0.0, 0.7, 1.0] {
                    let (u, v) = sky_view_uv(r, bottom, mu, c, 192, 108);
                    let (mu2, c2) = sky_view_mu_cos_phi(r, bottom, u, v, 192, 108);
                    assert!((mu - mu2).abs() < 1e-9, "r {r} mu {mu}: {mu2}");
                    assert!((c - c2).abs() < 1e-9, "cos phi {c}: {c2}");
                }
            }
        }
    }

    #[test]
    fn the_horizon_lies_between_the_two_middle_rows() {
        let bottom: f64 = 6_360e3;
        for r in [bottom, bottom + 2e3, bottom + 60e3] {
            let mu_h = -safe_sqrt(1.0 - (bottom / r).powi(2));
            let (_, v) = sky_view_uv(r, bottom, mu_h, 1.0, 192, 108);
            assert!((v - 0.5).abs() < 1e-6, "{v}");
        }
    }

    #[test]
    fn altitude_mapping_round_trips() {
        let (b, t) = (6_360e3, 6_420e3);
        for (x, y) in [(0, 0), (5, 17), (31, 31)] {
            let (r, mu_s) = altitude_mu_s_of_texel(x, y, b, t, 32, 32);
            let (u, v) = altitude_mu_s_uv(r, b, t, mu_s, 32, 32);
            assert!((u - (x as f64 + 0.5) / 32.0).abs() < 1e-12);
            assert!((v - (y as f64 + 0.5) / 32.0).abs() < 1e-12);
        }
    }
}

//! Ray geometry in a spherical atmosphere, in the (r, μ) form of Bruneton & Neyret 2008 §4
//! (naming after Bruneton 2017, `functions.glsl`). `r` is the distance to the planet centre
//! in metres, `mu` the cosine of the ray's zenith angle at that point.

use super::Vec3;

/// `sqrt(max(x, 0))`: rounding can make exact-zero discriminants slightly negative.
#[inline]
pub fn safe_sqrt(x: f64) -> f64 {
    x.max(0.0).sqrt()
}

/// Clamp a cosine to [-1, 1].
#[inline]
pub fn clamp_cosine(mu: f64) -> f64 {
    mu.clamp(-1.0, 1.0)
}

/// Distance (m) from a point at radius `r` along direction `mu` to the sphere of radius
/// `top_m` (the point is inside it): the positive root of d² + 2rμd + r² − R_t² = 0.
#[inline]
pub fn distance_to_top_atmosphere_boundary(r: f64, mu: f64, top_m: f64) -> f64 {
    let discriminant = r * r * (mu * mu - 1.0) + top_m * top_m;
    (-r * mu + safe_sqrt(discriminant)).max(0.0)
}

/// Distance (m) from radius `r` along `mu` to the ground sphere of radius `bottom_m`
/// (the smaller root; only meaningful when the ray intersects the ground).
#[inline]
pub fn distance_to_bottom_atmosphere_boundary(r: f64, mu: f64, bottom_m: f64) -> f64 {
    let discriminant = r * r * (mu * mu - 1.0) + bottom_m * bottom_m;
    (-r * mu - safe_sqrt(discriminant)).max(0.0)
}

/// Whether the ray (r, μ) hits the ground: it points down and passes below the ground radius.
#[inline]
pub fn ray_intersects_ground(r: f64, mu: f64, bottom_m: f64) -> bool {
    mu < 0.0 && r * r * (mu * mu - 1.0) + bottom_m * bottom_m >= 0.0
}

/// Distance to the nearest atmosphere boundary along (r, μ): the ground if the ray hits it,
/// the top otherwise.
#[inline]
pub fn distance_to_nearest_atmosphere_boundary(
    r: f64,
    mu: f64,
    bottom_m: f64,
    top_m: f64,
    intersects_ground: bool,
) -> f64 {
    if intersects_ground {
        distance_to_bottom_atmosphere_boundary(r, mu, bottom_m)
    } else {
        distance_to_top_atmosphere_boundary(r, mu, top_m)
    }
}

/// Radius and zenith cosine after travelling `d` metres from (r, μ) (law of cosines),
/// clamped into [bottom, top].
#[inline]
pub fn advance(r: f64, mu: f64, d: f64, bottom_m: f64, top_m: f64) -> (f64, f64) {
    let r_d = safe_sqrt(d * d + 2.0 * r * mu * d + r * r).clamp(bottom_m, top_m);
    let mu_d = clamp_cosine((r * mu + d) / r_d);
    (r_d, mu_d)
}

/// Cosine of the horizon's zenith angle seen from radius `r` (negative): −sqrt(1 − (R_g/r)²).
#[inline]
pub fn horizon_mu(r: f64, bottom_m: f64) -> f64 {
    let rho = bottom_m / r;
    -safe_sqrt(1.0 - rho * rho)
}

/// Distance along a unit direction from a point at radius `r` outside the sphere of radius
/// `top` (r·μ = `rmu`) to where the ray enters that sphere; None when it misses it or the
/// sphere lies behind.
#[inline]
pub fn distance_to_enter_sphere(r: f64, rmu: f64, top: f64) -> Option<f64> {
    let disc = rmu * rmu - r * r + top * top;
    if disc < 0.0 {
        return None;
    }
    let d = -rmu - disc.sqrt();
    (d > 0.0).then_some(d)
}

/// Distances (near, far) along unit `dir` from `origin` to a sphere of `radius` centred at
/// the origin, or None if the line misses it. `near` may be negative (origin inside).
pub fn ray_sphere(origin: Vec3, dir: Vec3, radius: f64) -> Option<(f64, f64)> {
    let b = origin.dot(dir);
    let c = origin.dot(origin) - radius * radius;
    let disc = b * b - c;
    if disc < 0.0 {
        return None;
    }
    let s = disc.sqrt();
    Some((-b - s, -b + s))
}

#[cfg(test)]
mod tests {
    use super::*;

    const RG: f64 = 6_360_000.0;
    const RT: f64 = 6_420_000.0;

    #[test]
    fn vertical_distances_are_altitude_differences() {
        let r = RG + 1000.0;
        assert!((distance_to_top_atmosphere_boundary(r, 1.0, RT) - (RT - r)).abs() < 1e-6);
        assert!((distance_to_bottom_atmosphere_boundary(r, -1.0, RG) - 1000.0).abs() < 1e-6);
        assert!(ray_intersects_ground(r, -1.0, RG));
        assert!(!ray_intersects_ground(r, 0.0, RG));
    }

    #[test]
    fn horizon_ray_grazes_the_ground() {
        let r = RG + 5000.0;
        let mu_h = horizon_mu(r, RG);
        assert!(ray_intersects_ground(r, mu_h - 1e-9, RG));
        assert!(!ray_intersects_ground(r, mu_h + 1e-9, RG));
        // Tangent distance sqrt(r² − R_g²).
        let d = distance_to_bottom_atmosphere_boundary(r, mu_h, RG);
        assert!((d - (r * r - RG * RG).sqrt()).abs() < 1.0);
    }

    #[test]
    fn advance_preserves_the_ray_invariant() {
        // r·sqrt(1 − μ²) is constant along a straight ray.
        let (r, mu) = (RG + 2000.0, 0.3);
        let (r2, mu2) = advance(r, mu, 50_000.0, RG, RT);
        let a = r * (1.0 - mu * mu).sqrt();
        let b = r2 * (1.0 - mu2 * mu2).sqrt();
        assert!((a - b).abs() < 1e-3);
    }
}

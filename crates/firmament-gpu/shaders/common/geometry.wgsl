// Ray geometry in a spherical atmosphere (firmament::math::sphere), with ρ = sqrt(r² − R_g²)
// carried along: wherever a radius difference would cancel in f32 (r − R_g at 6360 km), the
// shaders use r² − R_g² = ρ² and R_t² − r² = H² − ρ² (exact identities, no cancellation).

fn safe_sqrt(x: f32) -> f32 {
    return sqrt(max(x, 0.0));
}

fn clamp_cosine(mu: f32) -> f32 {
    return clamp(mu, -1.0, 1.0);
}

// r from ρ.
fn radius_from_rho(rho_km: f32) -> f32 {
    return sqrt(rho_km * rho_km + atm.bottom_radius_km * atm.bottom_radius_km);
}

// Distance to the top along (r, μ): the positive root of d² + 2rμd + r² − R_t² = 0, in the
// form without cancellation for rays going up.
fn distance_to_top(r_km: f32, rho_km: f32, mu: f32) -> f32 {
    let c = max(atm.h_sq_km2 - rho_km * rho_km, 0.0);
    let root = safe_sqrt(r_km * r_km * mu * mu + c);
    if (mu > 0.0) {
        return c / (r_km * mu + root);
    }
    return max(-r_km * mu + root, 0.0);
}

// Distance to the ground along (r, μ) (the smaller root; meaningful for ground rays).
fn distance_to_bottom(r_km: f32, rho_km: f32, mu: f32) -> f32 {
    let root = safe_sqrt(r_km * r_km * mu * mu - rho_km * rho_km);
    let far = -r_km * mu + root;
    if (far > 0.0) {
        return max(rho_km * rho_km / far, 0.0);
    }
    return max(-r_km * mu - root, 0.0);
}

fn ray_intersects_ground(r_km: f32, rho_km: f32, mu: f32) -> bool {
    return mu < 0.0 && r_km * r_km * mu * mu - rho_km * rho_km >= 0.0;
}

// ρ at distance d along (r, μ), clamped into the atmosphere (geometry::advance).
fn rho_at(r_km: f32, rho_km: f32, mu: f32, d_km: f32) -> f32 {
    return sqrt(clamp(d_km * d_km + 2.0 * r_km * mu * d_km + rho_km * rho_km, 0.0, atm.h_sq_km2));
}

// Altitude (km) of a point given its ρ and r: (r² − R_g²)/(r + R_g).
fn altitude_of(rho_km: f32, r_km: f32) -> f32 {
    return rho_km * rho_km / (r_km + atm.bottom_radius_km);
}

// GLSL smoothstep with the CPU's handling of an empty edge interval (firmament::math::
// smoothstep).
fn smoothstep_safe(e0: f32, e1: f32, x: f32) -> f32 {
    if (e1 <= e0) {
        return select(1.0, 0.0, x < e0);
    }
    let t = clamp((x - e0) / (e1 - e0), 0.0, 1.0);
    return t * t * (3.0 - 2.0 * t);
}

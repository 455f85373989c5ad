// The non-linear μ_s coordinate of the scattering table (firmament::sky::bruneton4d::mu_s_map):
// Bruneton 2017's mapping up to a joint, linear in the sun's zenith angle above it.

// The non-linear μ_s coordinate in [0, 1] (mu_s_map::x_mu_s): Bruneton's mapping below the
// joint (Bruneton's coordinate atm.mu_s_joint_bruneton_x, placed at MU_S_JOINT_X; prelude),
// linear in the sun's zenith angle above it.
fn x_mu_s(mu_s: f32) -> f32 {
    let d_min_km = atm.top_radius_km - atm.bottom_radius_km;
    let d_max_km = atm.h_km;
    let d_km = distance_to_top(atm.bottom_radius_km, 0.0, mu_s);
    let a = (d_km - d_min_km) / (d_max_km - d_min_km);
    let bruneton = clamp(max(1.0 - a / atm.mu_s_big_a, 0.0) / (1.0 + a), 0.0, 1.0);
    if (bruneton <= atm.mu_s_joint_bruneton_x) {
        return MU_S_JOINT_X * bruneton / atm.mu_s_joint_bruneton_x;
    }
    let above = (atm.mu_s_theta_joint - acos(clamp_cosine(mu_s))) / atm.mu_s_theta_joint;
    return clamp(MU_S_JOINT_X + (1.0 - MU_S_JOINT_X) * above, 0.0, 1.0);
}

// Inverse of x_mu_s (mu_s_map::mu_s_from_x).
fn mu_s_from_x(x: f32) -> f32 {
    if (x > MU_S_JOINT_X) {
        let above = min((x - MU_S_JOINT_X) / (1.0 - MU_S_JOINT_X), 1.0);
        return cos(atm.mu_s_theta_joint * (1.0 - above));
    }
    return bruneton_mu_s_from_x(x * atm.mu_s_joint_bruneton_x / MU_S_JOINT_X);
}

// Inverse of Bruneton's mapping alone.
fn bruneton_mu_s_from_x(x: f32) -> f32 {
    let d_min_km = atm.top_radius_km - atm.bottom_radius_km;
    let d_max_km = atm.h_km;
    let big_a = atm.mu_s_big_a;
    let a = (big_a - x * big_a) / (1.0 + x * big_a);
    let d_km = d_min_km + min(a, big_a) * (d_max_km - d_min_km);
    if (d_km == 0.0) {
        return 1.0;
    }
    return clamp_cosine((atm.h_sq_km2 - d_km * d_km) / (2.0 * atm.bottom_radius_km * d_km));
}

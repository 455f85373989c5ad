// The parameterisations of Hillaire 2020's tables (firmament::sky::hillaire2020::params),
// texel-centre exact: the transmittance is the 4D tables' (bruneton4d/params.wgsl), the
// multiple scattering and the sky irradiance are dense around the horizon in μ_s and near
// the ground in altitude (quadratic), and the
// sky view maps the azimuth from the light as sin(φ/2) and the zenith angle split at the
// horizon, each half squashed towards it by a square root. Radii in km; ρ = sqrt(r² − R_g²)
// carried along as in common/geometry.wgsl.

// Zenith angle (rad) of the geometric horizon at (r, ρ): π − acos(ρ/r)
// (params::horizon_zenith_angle).
fn horizon_zenith_angle(r_km: f32, rho_km: f32) -> f32 {
    return PI - acos(clamp(rho_km / r_km, -1.0, 1.0));
}

// The sky-view table's (u, v) for a view of zenith cosine `mu` whose azimuth is `cos_phi`
// from the light's, seen from (r, ρ) (params::sky_view_uv).
fn sky_view_uv(r_km: f32, rho_km: f32, mu: f32, cos_phi: f32) -> vec2<f32> {
    let zenith_horizon = horizon_zenith_angle(r_km, rho_km);
    let beta = PI - zenith_horizon;
    let theta = acos(clamp_cosine(mu));
    var y: f32;
    if (theta < zenith_horizon) {
        y = 0.5 * (1.0 - safe_sqrt(1.0 - theta / zenith_horizon));
    } else {
        y = 0.5 + 0.5 * safe_sqrt((theta - zenith_horizon) / beta);
    }
    let x = safe_sqrt(0.5 - 0.5 * clamp_cosine(cos_phi));
    return vec2<f32>(texcoord_from_unit(x, hillaire.sky_view_azimuth), texcoord_from_unit(min(y, 1.0), hillaire.sky_view_zenith));
}

// (μ, cos φ) at the centre of sky-view texel (x, y) seen from (r, ρ) (params::
// sky_view_mu_cos_phi at the texel's centre, whose unit coordinates are x/(n − 1)).
fn sky_view_mu_cos_phi(r_km: f32, rho_km: f32, x: u32, y: u32) -> vec2<f32> {
    let zenith_horizon = horizon_zenith_angle(r_km, rho_km);
    let beta = PI - zenith_horizon;
    let ux = f32(x) / f32(hillaire.sky_view_azimuth - 1u);
    let uy = f32(y) / f32(hillaire.sky_view_zenith - 1u);
    var theta: f32;
    if (uy < 0.5) {
        let c = 1.0 - 2.0 * uy;
        theta = zenith_horizon * (1.0 - c * c);
    } else {
        let c = 2.0 * uy - 1.0;
        theta = zenith_horizon + beta * c * c;
    }
    return vec2<f32>(cos(theta), 1.0 - 2.0 * ux * ux);
}

// x ∈ [−1, 1] of the light's zenith cosine in those tables' columns: asinh(μ_s·sinh k)/k,
// dense around the horizon (params::mu_s_unit, k = MU_S_HORIZON_STRETCH).
fn mu_s_unit(mu_s: f32) -> f32 {
    return asinh(clamp_cosine(mu_s) * sinh(MU_S_HORIZON_STRETCH)) / MU_S_HORIZON_STRETCH;
}

// Inverse of mu_s_unit (params::mu_s_of_unit); exact at the ends (a zenith light's field
// has no azimuthal terms, which an f32 ratio of sinh a hair below 1 would add).
fn mu_s_of_unit(x: f32) -> f32 {
    if (abs(x) >= 1.0) {
        return sign(x);
    }
    return clamp_cosine(sinh(x * MU_S_HORIZON_STRETCH) / sinh(MU_S_HORIZON_STRETCH));
}

// The (u, v) of the multiple-scattering and irradiance tables (n_mu_s × n_r texels) at
// `altitude_km` under a light at zenith cosine `mu_s` (params::altitude_mu_s_uv: the rows
// quadratic in altitude, dense near the ground).
fn altitude_mu_s_uv(altitude_km: f32, mu_s: f32, n_mu_s: u32, n_r: u32) -> vec2<f32> {
    let x_r = sqrt(clamp(altitude_km / (atm.top_radius_km - atm.bottom_radius_km), 0.0, 1.0));
    let x_mu_s = clamp(mu_s_unit(mu_s) * 0.5 + 0.5, 0.0, 1.0);
    return vec2<f32>(texcoord_from_unit(x_mu_s, n_mu_s), texcoord_from_unit(x_r, n_r));
}

// (r, ρ, μ_s) at the centre of texel (x, y) of those tables (params::altitude_mu_s_of_texel).
fn altitude_mu_s_of_texel(x: u32, y: u32, n_mu_s: u32, n_r: u32) -> vec3<f32> {
    let x_mu_s = f32(x) / f32(n_mu_s - 1u);
    let x_r = f32(y) / f32(n_r - 1u);
    let altitude_km = x_r * x_r * (atm.top_radius_km - atm.bottom_radius_km);
    let r_km = atm.bottom_radius_km + altitude_km;
    let rho_km = sqrt(altitude_km * (r_km + atm.bottom_radius_km));
    return vec3<f32>(r_km, rho_km, mu_s_of_unit(2.0 * x_mu_s - 1.0));
}

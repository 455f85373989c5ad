// The table parameterisations (firmament::sky::bruneton4d::params): texel-centre-exact
// mappings, the horizon split in μ, ν by the azimuth from the sun (μ_s: mu_s_map.wgsl).

fn texcoord_from_unit(x: f32, n: u32) -> f32 {
    return 0.5 / f32(n) + x * (1.0 - 1.0 / f32(n));
}

// Transmittance table (u, v) for (r, μ).
fn transmittance_uv(r_km: f32, rho_km: f32, mu: f32) -> vec2<f32> {
    let d_km = distance_to_top(r_km, rho_km, mu);
    let d_min_km = (atm.h_sq_km2 - rho_km * rho_km) / (atm.top_radius_km + r_km);
    let d_max_km = rho_km + atm.h_km;
    var x_mu = 0.0;
    if (d_max_km > d_min_km) {
        x_mu = (d_km - d_min_km) / (d_max_km - d_min_km);
    }
    return vec2<f32>(texcoord_from_unit(x_mu, atm.transmittance_mu), texcoord_from_unit(rho_km / atm.h_km, atm.transmittance_r));
}

// (r, ρ, μ) at the centre of transmittance texel (x, y).
fn transmittance_texel(x: u32, y: u32) -> vec3<f32> {
    let x_mu = f32(x) / f32(atm.transmittance_mu - 1u);
    let x_r = f32(y) / f32(atm.transmittance_r - 1u);
    let rho_km = atm.h_km * x_r;
    let r_km = radius_from_rho(rho_km);
    let d_min_km = (atm.h_sq_km2 - rho_km * rho_km) / (atm.top_radius_km + r_km);
    let d_max_km = rho_km + atm.h_km;
    let d_km = d_min_km + x_mu * (d_max_km - d_min_km);
    var mu = 1.0;
    if (d_km != 0.0) {
        mu = clamp_cosine((atm.h_sq_km2 - rho_km * rho_km - d_km * d_km) / (2.0 * r_km * d_km));
    }
    return vec3<f32>(r_km, rho_km, mu);
}

// Irradiance table: (u, v) for (altitude, μ_s), linear in both.
fn irradiance_uv(altitude_km: f32, mu_s: f32) -> vec2<f32> {
    let x_r = altitude_km / (atm.top_radius_km - atm.bottom_radius_km);
    let x_mu_s = mu_s * 0.5 + 0.5;
    return vec2<f32>(texcoord_from_unit(x_mu_s, atm.irradiance_mu_s), texcoord_from_unit(x_r, atm.irradiance_r));
}

// (r, ρ, μ_s) at the centre of irradiance texel (x, y).
fn irradiance_texel(x: u32, y: u32) -> vec3<f32> {
    let x_mu_s = f32(x) / f32(atm.irradiance_mu_s - 1u);
    let x_r = f32(y) / f32(atm.irradiance_r - 1u);
    let altitude_km = x_r * (atm.top_radius_km - atm.bottom_radius_km);
    let r_km = atm.bottom_radius_km + altitude_km;
    let rho_km = sqrt(altitude_km * (r_km + atm.bottom_radius_km));
    return vec3<f32>(r_km, rho_km, clamp_cosine(2.0 * x_mu_s - 1.0));
}

// (u_ν, u_μs, u_μ, u_r) of the scattering table (params::scattering_uvwz).
fn scattering_uvwz(r_km: f32, rho_km: f32, mu: f32, mu_s: f32, nu: f32, ground: bool) -> vec4<f32> {
    let u_r = texcoord_from_unit(rho_km / atm.h_km, atm.scattering_r);
    let u_mu = scattering_u_mu(r_km, rho_km, mu, ground);
    let u_mu_s = texcoord_from_unit(x_mu_s(mu_s), atm.scattering_mu_s);
    return vec4<f32>(u_nu_from_nu(mu, mu_s, nu), u_mu_s, u_mu, u_r);
}

// The u_μ coordinate alone (params::scattering_u_mu): the distance to the ground mapped to
// the lower half for rays that hit it, the distance to the top to the upper half otherwise.
fn scattering_u_mu(r_km: f32, rho_km: f32, mu: f32, ground: bool) -> f32 {
    let half = atm.scattering_mu / 2u;
    if (ground) {
        let d_km = distance_to_bottom(r_km, rho_km, mu);
        let d_min_km = rho_km * rho_km / (r_km + atm.bottom_radius_km);
        let d_max_km = rho_km;
        // x = √f of the distance fraction (params::ground_x_from_distance_fraction).
        var x = 0.0;
        if (d_max_km != d_min_km) {
            x = sqrt(clamp((d_km - d_min_km) / (d_max_km - d_min_km), 0.0, 1.0));
        }
        return 0.5 - 0.5 * texcoord_from_unit(x, half);
    }
    let d_km = distance_to_top(r_km, rho_km, mu);
    let d_min_km = (atm.h_sq_km2 - rho_km * rho_km) / (atm.top_radius_km + r_km);
    let d_max_km = rho_km + atm.h_km;
    var x = 0.0;
    if (d_max_km > d_min_km) {
        x = sky_x_from_distance_fraction((d_km - d_min_km) / (d_max_km - d_min_km));
    }
    return 0.5 + 0.5 * texcoord_from_unit(x, half);
}

// The unit coordinate of a sky ray from the fraction f of its distance to the top between
// straight up and the horizon: x = (s + s³)/2 with s = √f, linear in the angle near the
// zenith (params::sky_x_from_distance_fraction).
fn sky_x_from_distance_fraction(f: f32) -> f32 {
    let s = sqrt(clamp(f, 0.0, 1.0));
    return 0.5 * (s + s * s * s);
}

// Inverse of sky_x_from_distance_fraction: s = (2/√3)·sinh(asinh(3√3·x)/3), f = s²
// (params::distance_fraction_from_sky_x).
fn distance_fraction_from_sky_x(x: f32) -> f32 {
    let sqrt_3 = 1.7320508;
    let s = 2.0 / sqrt_3 * sinh(asinh(3.0 * sqrt_3 * clamp(x, 0.0, 1.0)) / 3.0);
    return min(s * s, 1.0);
}

// A scattering texel's parameters.
struct ScatteringTexel {
    r_km: f32,
    rho_km: f32,
    mu: f32,
    mu_s: f32,
    nu: f32,
    ground: bool,
}

// (r, ρ, μ, μ_s, ν, ground) at the centre of texel (x = ν·N_μs + μ_s, y = μ, z = r), ν
// clamped to the range μ and μ_s allow (params::scattering_texel). Texel centres map to
// exact unit coordinates i/(n − 1).
fn scattering_texel(x: u32, y: u32, z: u32) -> ScatteringTexel {
    var t: ScatteringTexel;
    let i_nu = x / atm.scattering_mu_s;
    let i_mu_s = x % atm.scattering_mu_s;
    t.rho_km = atm.h_km * f32(z) / f32(atm.scattering_r - 1u);
    t.r_km = radius_from_rho(t.rho_km);
    let half = atm.scattering_mu / 2u;
    if (y < half) {
        let x_mu = f32(half - 1u - y) / f32(half - 1u);
        // The ground row takes the next row's ground-ray directions (params::ground_row_rho).
        let rho_km = select(t.rho_km, atm.h_km / f32(atm.scattering_r - 1u), z == 0u);
        let r_km = radius_from_rho(rho_km);
        let d_min_km = rho_km * rho_km / (r_km + atm.bottom_radius_km);
        let d_max_km = rho_km;
        let d_km = d_min_km + (d_max_km - d_min_km) * x_mu * x_mu;
        t.mu = -1.0;
        if (d_km != 0.0) {
            t.mu = clamp_cosine(-(rho_km * rho_km + d_km * d_km) / (2.0 * r_km * d_km));
        }
        t.ground = true;
    } else {
        let x_mu = f32(y - half) / f32(half - 1u);
        let d_min_km = (atm.h_sq_km2 - t.rho_km * t.rho_km) / (atm.top_radius_km + t.r_km);
        let d_max_km = t.rho_km + atm.h_km;
        let d_km = d_min_km + (d_max_km - d_min_km) * distance_fraction_from_sky_x(x_mu);
        t.mu = 1.0;
        if (d_km != 0.0) {
            t.mu = clamp_cosine((atm.h_sq_km2 - t.rho_km * t.rho_km - d_km * d_km) / (2.0 * t.r_km * d_km));
        }
        t.ground = false;
    }
    t.mu_s = mu_s_from_x(f32(i_mu_s) / f32(atm.scattering_mu_s - 1u));
    // ν from u_ν once μ and μ_s are known (params::scattering_r_mu_mu_s_nu).
    let nu = nu_from_u_nu(t.mu, t.mu_s, f32(i_nu) / f32(atm.scattering_nu - 1u));
    let spread = sqrt(max((1.0 - t.mu * t.mu) * (1.0 - t.mu_s * t.mu_s), 0.0));
    t.nu = clamp(nu, t.mu * t.mu_s - spread, t.mu * t.mu_s + spread);
    return t;
}

// The texel of flat scattering-table index i (x fastest, then y, then z).
fn scattering_texel_at(i: u32) -> ScatteringTexel {
    let width = scattering_width();
    return scattering_texel(i % width, (i / width) % atm.scattering_mu, i / (width * atm.scattering_mu));
}

fn scattering_width() -> u32 {
    return atm.scattering_nu * atm.scattering_mu_s;
}

fn scattering_texels() -> u32 {
    return scattering_width() * atm.scattering_mu * atm.scattering_r;
}


// The ν coordinate relative to the range of ν that (μ, μ_s) allow (params::u_nu): the
// azimuth φ between the view and the sun around the zenith, cos φ = (ν − μμ_s)/s with
// s = sqrt((1 − μ²)(1 − μ_s²)), and u_ν = 1 − sin(φ/2). (1 − μ)(1 + μ) for 1 − μ²: the
// same value, without the cancellation of f32 near μ = ±1.
fn u_nu_from_nu(mu: f32, mu_s: f32, nu: f32) -> f32 {
    let s = sqrt(max((1.0 - mu) * (1.0 + mu) * (1.0 - mu_s) * (1.0 + mu_s), 0.0));
    if (s <= 1e-12) {
        // φ is undefined and every u_ν holds the same value.
        return 1.0;
    }
    // (1 − cos φ)/2 = sin²(φ/2).
    let x = clamp((mu * mu_s + s - nu) / (2.0 * s), 0.0, 1.0);
    return 1.0 - sqrt(x);
}

// Inverse of u_nu_from_nu at (μ, μ_s) (params::nu_from_u_nu).
fn nu_from_u_nu(mu: f32, mu_s: f32, u_nu: f32) -> f32 {
    let s = sqrt(max((1.0 - mu) * (1.0 + mu) * (1.0 - mu_s) * (1.0 + mu_s), 0.0));
    let x = 1.0 - clamp(u_nu, 0.0, 1.0);
    return clamp_cosine(mu * mu_s + s * (1.0 - 2.0 * x * x));
}

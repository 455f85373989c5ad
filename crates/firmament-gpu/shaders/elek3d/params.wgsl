// The 3D table's parameterisation (firmament::sky::elek3d::params, Yusov 2013's
// `WorldParams2InsctrLUTCoords`), texel-centre exact: u_h = (h/H)^p over the altitude, the
// view zenith split at the horizon with each half's fraction raised to a power, and the sun's
// zenith by Bruneton & Neyret 2008's arctangent (Yusov's) or the 4D tables' mapping
// (bruneton4d/params.wgsl `x_mu_s`). The functions are `Params`'s methods with an `elek3d_`
// prefix (the 4D tables' `x_mu_s` has the name already). Lengths in km; the altitude and the
// horizon come from ρ = sqrt(r² − R_g²), never from r − R_g.

// The mappings' constants (firmament_gpu::elek3d::sky packs them in this order, in f64
// rounded once).
struct Elek3dParams {
    // Altitude, view-zenith (even: two halves) and sun-zenith texels.
    nh: u32,
    nmu: u32,
    nmu_s: u32,
    // The sun's mapping: 0 Yusov's arctangent (SunZenithMapping::Yusov), 1 the 4D tables'
    // (SunZenithMapping::Tables4d).
    sun_mapping: u32,
    // The atmosphere's thickness H = R_t − R_g (km).
    thickness_km: f32,
    // u_h = (h/H)^height_power; each view-zenith half's fraction ^ view_zenith_power.
    height_power: f32,
    view_zenith_power: f32,
    // The arctangent's ends: t_min = atan(μ_s,min·tan t_max), t_max = 1.26·1.1 (where
    // μ_s = 1), and tan t_max.
    t_min: f32,
    t_max: f32,
    tan_t_max: f32,
    pad0: f32,
    pad1: f32,
}

@group(0) @binding(8) var<uniform> elek3d: Elek3dParams;

// Params::power: f^p, f itself for p = 1 (0 at f = 0: WGSL's pow(0, p) is an exp2 of −∞).
fn elek3d_power(f: f32, p: f32) -> f32 {
    if (p == 1.0) {
        return f;
    }
    if (f <= 0.0) {
        return 0.0;
    }
    return pow(f, p);
}

// Params::x_h from the altitude (km; geometry.wgsl's altitude_of): (h/H)^p, clamped to [0, 1].
fn elek3d_x_h(altitude_km: f32) -> f32 {
    let f = clamp(altitude_km / elek3d.thickness_km, 0.0, 1.0);
    if (elek3d.height_power == 0.5) {
        return sqrt(f);
    }
    return elek3d_power(f, elek3d.height_power);
}

// Params::x_mu: the view zenith's unit coordinate within its half, 0 at the horizon, 1
// straight up (`ground` false) or down (`ground` true). The horizon's cosine
// horizon_mu(r, R_g) = −sqrt(1 − (R_g/r)²) is −ρ/r.
fn elek3d_x_mu(r_km: f32, rho_km: f32, mu: f32, ground: bool) -> f32 {
    let mu_h = -rho_km / max(r_km, atm.bottom_radius_km);
    var f: f32;
    if (ground) {
        f = (mu_h - mu) / (1.0 + mu_h);
    } else {
        f = (mu - mu_h) / (1.0 - mu_h);
    }
    return elek3d_power(clamp(f, 0.0, 1.0), elek3d.view_zenith_power);
}

// Params::x_mu_s: (atan(μ_s·tan t_max) − t_min)/(t_max − t_min) with μ_s clamped at
// μ_s,min, or the 4D tables' mapping.
fn elek3d_x_mu_s(mu_s: f32) -> f32 {
    if (elek3d.sun_mapping == 1u) {
        return x_mu_s(mu_s);
    }
    let t = atan(max(mu_s, atm.mu_s_min) * elek3d.tan_t_max);
    return clamp((t - elek3d.t_min) / (elek3d.t_max - elek3d.t_min), 0.0, 1.0);
}

// Params::u_h, a texture coordinate.
fn elek3d_u_h(altitude_km: f32) -> f32 {
    return texcoord_from_unit(elek3d_x_h(altitude_km), elek3d.nh);
}

// Params::u_mu, a texture coordinate: ground rays in [0, ½) (straight down at texel 0), the
// others in (½, 1].
fn elek3d_u_mu(r_km: f32, rho_km: f32, mu: f32, ground: bool) -> f32 {
    let half = texcoord_from_unit(elek3d_x_mu(r_km, rho_km, mu, ground), elek3d.nmu / 2u);
    if (ground) {
        return 0.5 - 0.5 * half;
    }
    return 0.5 + 0.5 * half;
}

// Params::u_mu_s, a texture coordinate.
fn elek3d_u_mu_s(mu_s: f32) -> f32 {
    return texcoord_from_unit(elek3d_x_mu_s(mu_s), elek3d.nmu_s);
}

// Params::coords: (u_h, u_μ, u_μs) at (r, μ, μ_s) on a ray that meets the ground or not.
fn elek3d_coords(r_km: f32, rho_km: f32, mu: f32, mu_s: f32, ground: bool) -> vec3<f32> {
    return vec3<f32>(elek3d_u_h(altitude_of(rho_km, r_km)), elek3d_u_mu(r_km, rho_km, mu, ground), elek3d_u_mu_s(mu_s));
}

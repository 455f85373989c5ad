// Table lookups (firmament::sky::bruneton4d::lookup): transmittance between points and to
// the sun, irradiance, scattering. Passes bind the tables they read at these slots; the
// renderer binds the final tables there (see view.wgsl).

// Slot 3 holds the optical depth τ(r, μ) = −ln T to the top (Tables::optical_depth);
// lookups interpolate τ and take e^{−τ}.
@group(0) @binding(3) var<storage, read> transmittance_table: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read> delta_irradiance_table: array<vec4<f32>>;
// Order 2: ΔS_Rayleigh and ΔS_Mie (single scattering); order ≥ 3: ΔS twice. Also ΔJ for the
// multiple-scattering pass (slot a).
@group(0) @binding(5) var<storage, read> scattering_a: array<vec4<f32>>;
@group(0) @binding(6) var<storage, read> scattering_b: array<vec4<f32>>;

// τ(r, μ) to the top of the atmosphere (Lookup::optical_depth_to_top).
fn optical_depth_to_top(r_km: f32, rho_km: f32, mu: f32, k: u32) -> vec4<f32> {
    let f = table2_filter(transmittance_uv(r_km, rho_km, mu), atm.transmittance_mu, atm.transmittance_r);
    return f.weight.x * transmittance_table[f.index.x + k] + f.weight.y * transmittance_table[f.index.y + k]
        + f.weight.z * transmittance_table[f.index.z + k] + f.weight.w * transmittance_table[f.index.w + k];
}

// T(r, μ) to the top of the atmosphere (ray assumed not to hit the ground).
fn transmittance_to_top(r_km: f32, rho_km: f32, mu: f32, k: u32) -> vec4<f32> {
    return exp(-optical_depth_to_top(r_km, rho_km, mu, k));
}

// e^{−(τ_a − τ_b)} for the optical depths to the top from a ray's two ends, 0 where either
// end's τ stands for T = 0 (Lookup::transmittance).
fn transmittance_between(tau_a: vec4<f32>, tau_b: vec4<f32>) -> vec4<f32> {
    let finite = tau_a < vec4<f32>(MAX_OPTICAL_DEPTH) & tau_b < vec4<f32>(MAX_OPTICAL_DEPTH);
    return select(vec4<f32>(0.0), exp(-max(tau_a - tau_b, vec4<f32>(0.0))), finite);
}

// Transmittance over d km from (r, μ), from differences of table optical depths; the
// reversed ray when it hits the ground (Bruneton 2017 `GetTransmittance`).
fn transmittance(r_km: f32, rho_km: f32, mu: f32, d_km: f32, ground: bool, k: u32) -> vec4<f32> {
    let rho_d_km = rho_at(r_km, rho_km, mu, d_km);
    let r_d_km = radius_from_rho(rho_d_km);
    let mu_d = clamp_cosine((r_km * mu + d_km) / r_d_km);
    var a: vec4<f32>;
    var b: vec4<f32>;
    if (ground) {
        a = optical_depth_to_top(r_d_km, rho_d_km, -mu_d, k);
        b = optical_depth_to_top(r_km, rho_km, -mu, k);
    } else {
        a = optical_depth_to_top(r_km, rho_km, mu, k);
        b = optical_depth_to_top(r_d_km, rho_d_km, mu_d, k);
    }
    return transmittance_between(a, b);
}

// Visible fraction of the sun's disk above the planet (smoothstep in μ_s over ± the sun's
// angular radius around the horizon).
fn sun_visible_fraction(r_km: f32, rho_km: f32, mu_s: f32) -> f32 {
    let sin_theta_h = atm.bottom_radius_km / r_km;
    let cos_theta_h = -rho_km / r_km;
    let e = sin_theta_h * atm.sun_angular_radius;
    return smoothstep_safe(-e, e, mu_s - cos_theta_h);
}

// Transmittance to the sun times its visible fraction (Bruneton 2017 `GetTransmittanceToSun`).
fn transmittance_to_sun(r_km: f32, rho_km: f32, mu_s: f32, k: u32) -> vec4<f32> {
    let fraction = sun_visible_fraction(r_km, rho_km, mu_s);
    if (fraction <= 0.0) {
        return vec4<f32>(0.0);
    }
    return transmittance_to_top(r_km, rho_km, mu_s, k) * fraction;
}

// The irradiance table at slot 4 (ΔE in the precomputation, E when rendering) at texture
// coordinates uv (Lookup::irradiance, Table2::sample_irradiance_into): each row along μ_s
// (linear, or in a twilight cell the twilight blend), then along r by r_blend.wgsl's rule
// (rows even in altitude).
fn irradiance_at(uv: vec2<f32>, k: u32) -> vec4<f32> {
    let w = atm.irradiance_mu_s;
    let m = mu_s_filter(uv.x, w, atm.irradiance_twilight_cells);
    let rf = r_filter_altitude_rows(uv.y, atm.irradiance_r);
    let e0 = irradiance_row(m, rf.z0 * w, k);
    if (rf.t == 0.0) {
        return e0;
    }
    return r_blend(e0, irradiance_row(m, rf.z1 * w, k), rf);
}

// One row of the irradiance table (first texel `base`) along μ_s, channel group k.
fn irradiance_row(m: MuSFilter, base: u32, k: u32) -> vec4<f32> {
    let g = atm.groups;
    let a = delta_irradiance_table[(base + m.s0) * g + k];
    let b = delta_irradiance_table[(base + m.s1) * g + k];
    if (m.twilight) {
        return mu_s_blend_at(m, delta_irradiance_table[(base + m.below) * g + k], a, b, delta_irradiance_table[(base + m.above) * g + k]);
    }
    return a + m.t * (b - a);
}

// ΔE at (altitude, μ_s).
fn delta_irradiance(altitude_km: f32, mu_s: f32, k: u32) -> vec4<f32> {
    return irradiance_at(irradiance_uv(altitude_km, mu_s), k);
}

// The two ν columns (ν0, ν1) of one (r, μ) row of a 4D lookup, blended along μ_s.
struct Columns {
    c0: vec4<f32>,
    c1: vec4<f32>,
}

// Table4::sample_rows_into from each row's columns (rows z0 y0, z0 y1, z1 y0, z1 y1): per
// (μ, ν) texel the blend along r (r_blend.wgsl), then bilinear in (μ, ν).
fn blend_rows(f: Filter4, z0y0: Columns, z0y1: Columns, z1y0: Columns, z1y1: Columns) -> vec4<f32> {
    let y0 = f.wnu.x * r_blend(z0y0.c0, z1y0.c0, f.r) + f.wnu.y * r_blend(z0y0.c1, z1y0.c1, f.r);
    let y1 = f.wnu.x * r_blend(z0y1.c0, z1y1.c0, f.r) + f.wnu.y * r_blend(z0y1.c1, z1y1.c1, f.r);
    return f.wy.x * y0 + f.wy.y * y1;
}

// The columns of one row from the texels at s0 and s1 of its ν0 column (a0, a1) and its ν1
// column (d0, d1): linear along μ_s.
fn linear_columns(f: Filter4, a0: vec4<f32>, a1: vec4<f32>, d0: vec4<f32>, d1: vec4<f32>) -> Columns {
    var c: Columns;
    c.c0 = a0 + f.mu_s.t * (a1 - a0);
    c.c1 = d0 + f.mu_s.t * (d1 - d0);
    return c;
}

// In a twilight cell: each ν column's samples below s0, at s0, at s1 and above s1 blended
// by mu_s_blend.wgsl.
fn twilight_columns(f: Filter4, b0: vec4<f32>, a0: vec4<f32>, a1: vec4<f32>, c0: vec4<f32>,
    b1: vec4<f32>, d0: vec4<f32>, d1: vec4<f32>, c1: vec4<f32>) -> Columns {
    var c: Columns;
    c.c0 = mu_s_blend_at(f.mu_s, b0, a0, a1, c0);
    c.c1 = mu_s_blend_at(f.mu_s, b1, d0, d1, c1);
    return c;
}

fn scattering_a_columns(f: Filter4, row: u32, k: u32) -> Columns {
    let g = atm.groups;
    let a0 = scattering_a[(row + f.col.x) * g + k];
    let a1 = scattering_a[(row + f.col.y) * g + k];
    let d0 = scattering_a[(row + f.col.z) * g + k];
    let d1 = scattering_a[(row + f.col.w) * g + k];
    if (f.mu_s.twilight) {
        return twilight_columns(f, scattering_a[(row + f.colb.x) * g + k], a0, a1, scattering_a[(row + f.cola.x) * g + k],
            scattering_a[(row + f.colb.y) * g + k], d0, d1, scattering_a[(row + f.cola.y) * g + k]);
    }
    return linear_columns(f, a0, a1, d0, d1);
}

fn scattering_b_columns(f: Filter4, row: u32, k: u32) -> Columns {
    let g = atm.groups;
    let a0 = scattering_b[(row + f.col.x) * g + k];
    let a1 = scattering_b[(row + f.col.y) * g + k];
    let d0 = scattering_b[(row + f.col.z) * g + k];
    let d1 = scattering_b[(row + f.col.w) * g + k];
    if (f.mu_s.twilight) {
        return twilight_columns(f, scattering_b[(row + f.colb.x) * g + k], a0, a1, scattering_b[(row + f.cola.x) * g + k],
            scattering_b[(row + f.colb.y) * g + k], d0, d1, scattering_b[(row + f.cola.y) * g + k]);
    }
    return linear_columns(f, a0, a1, d0, d1);
}

// The 4D lookup of the table at slot a (Table4::sample_into), channel group k.
fn sample_scattering_a(f: Filter4, k: u32) -> vec4<f32> {
    return blend_rows(f, scattering_a_columns(f, f.row.x, k), scattering_a_columns(f, f.row.y, k),
        scattering_a_columns(f, f.row.z, k), scattering_a_columns(f, f.row.w, k));
}

fn sample_scattering_b(f: Filter4, k: u32) -> vec4<f32> {
    return blend_rows(f, scattering_b_columns(f, f.row.x, k), scattering_b_columns(f, f.row.y, k),
        scattering_b_columns(f, f.row.z, k), scattering_b_columns(f, f.row.w, k));
}

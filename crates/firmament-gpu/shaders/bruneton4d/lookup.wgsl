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
// coordinates uv (Lookup::irradiance, Table2::sample_twilight_into): bilinear, or in a
// twilight cell the twilight blend along μ_s per row and then linear in r.
fn irradiance_at(uv: vec2<f32>, k: u32) -> vec4<f32> {
    let w = atm.irradiance_mu_s;
    let m = mu_s_filter(uv.x, w, atm.irradiance_twilight_cells);
    if (!m.twilight) {
        let f = table2_filter(uv, w, atm.irradiance_r);
        return f.weight.x * delta_irradiance_table[f.index.x + k] + f.weight.y * delta_irradiance_table[f.index.y + k]
            + f.weight.z * delta_irradiance_table[f.index.z + k] + f.weight.w * delta_irradiance_table[f.index.w + k];
    }
    let ly = lerp_weights(uv.y, atm.irradiance_r);
    let g = atm.groups;
    let r0 = ly.i0 * w;
    let r1 = ly.i1 * w;
    let e0 = mu_s_blend_at(m, delta_irradiance_table[(r0 + m.below) * g + k], delta_irradiance_table[(r0 + m.s0) * g + k],
        delta_irradiance_table[(r0 + m.s1) * g + k], delta_irradiance_table[(r0 + m.above) * g + k]);
    let e1 = mu_s_blend_at(m, delta_irradiance_table[(r1 + m.below) * g + k], delta_irradiance_table[(r1 + m.s0) * g + k],
        delta_irradiance_table[(r1 + m.s1) * g + k], delta_irradiance_table[(r1 + m.above) * g + k]);
    return (1.0 - ly.t) * e0 + ly.t * e1;
}

// ΔE at (altitude, μ_s).
fn delta_irradiance(altitude_km: f32, mu_s: f32, k: u32) -> vec4<f32> {
    return irradiance_at(irradiance_uv(altitude_km, mu_s), k);
}

// Σ over the four (ν, μ_s) columns of one (r, μ) row, channel group k; in a twilight cell
// the twilight blend along μ_s of each ν column, then linear in ν.
fn scattering_a_row(f: Filter4, row: u32, k: u32) -> vec4<f32> {
    let g = atm.groups;
    if (f.mu_s.twilight) {
        let c0 = mu_s_blend_at(f.mu_s, scattering_a[(row + f.colb.x) * g + k], scattering_a[(row + f.col.x) * g + k],
            scattering_a[(row + f.col.y) * g + k], scattering_a[(row + f.cola.x) * g + k]);
        let c1 = mu_s_blend_at(f.mu_s, scattering_a[(row + f.colb.y) * g + k], scattering_a[(row + f.col.z) * g + k],
            scattering_a[(row + f.col.w) * g + k], scattering_a[(row + f.cola.y) * g + k]);
        return f.wnu.x * c0 + f.wnu.y * c1;
    }
    return f.wcol.x * scattering_a[(row + f.col.x) * g + k] + f.wcol.y * scattering_a[(row + f.col.y) * g + k]
        + f.wcol.z * scattering_a[(row + f.col.z) * g + k] + f.wcol.w * scattering_a[(row + f.col.w) * g + k];
}

fn scattering_b_row(f: Filter4, row: u32, k: u32) -> vec4<f32> {
    let g = atm.groups;
    if (f.mu_s.twilight) {
        let c0 = mu_s_blend_at(f.mu_s, scattering_b[(row + f.colb.x) * g + k], scattering_b[(row + f.col.x) * g + k],
            scattering_b[(row + f.col.y) * g + k], scattering_b[(row + f.cola.x) * g + k]);
        let c1 = mu_s_blend_at(f.mu_s, scattering_b[(row + f.colb.y) * g + k], scattering_b[(row + f.col.z) * g + k],
            scattering_b[(row + f.col.w) * g + k], scattering_b[(row + f.cola.y) * g + k]);
        return f.wnu.x * c0 + f.wnu.y * c1;
    }
    return f.wcol.x * scattering_b[(row + f.col.x) * g + k] + f.wcol.y * scattering_b[(row + f.col.y) * g + k]
        + f.wcol.z * scattering_b[(row + f.col.z) * g + k] + f.wcol.w * scattering_b[(row + f.col.w) * g + k];
}

fn sample_scattering_a(f: Filter4, k: u32) -> vec4<f32> {
    return f.wrow.x * scattering_a_row(f, f.row.x, k) + f.wrow.y * scattering_a_row(f, f.row.y, k)
        + f.wrow.z * scattering_a_row(f, f.row.z, k) + f.wrow.w * scattering_a_row(f, f.row.w, k);
}

fn sample_scattering_b(f: Filter4, k: u32) -> vec4<f32> {
    return f.wrow.x * scattering_b_row(f, f.row.x, k) + f.wrow.y * scattering_b_row(f, f.row.y, k)
        + f.wrow.z * scattering_b_row(f, f.row.z, k) + f.wrow.w * scattering_b_row(f, f.row.w, k);
}

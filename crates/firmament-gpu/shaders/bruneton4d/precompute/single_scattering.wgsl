// Single scattering (Bruneton & Neyret 2008 eq. 7; Bruneton 2017 `ComputeSingleScattering`;
// Rust twin precompute/single_scattering.rs, `compute_single_scattering`): Rayleigh and Mie
// integrated apart without phase functions, RAY_INTERVALS intervals along the view ray (in pairs
// graded by its optical depth, ray.wgsl `ray_pair_end_km`) with
// the exponentially fitted Simpson rule (ray.wgsl `exponential_simpson_weights`), pair of
// intervals by pair. The Rayleigh part is also the final `Tables::single_rayleigh`
// (multiple scattering is summed apart, multiple_scattering.wgsl).

@group(0) @binding(7) var<storage, read_write> rayleigh_out: array<vec4<f32>>;
@group(0) @binding(8) var<storage, read_write> mie_out: array<vec4<f32>>;

// One ray sample: the transmittance from the ray origin, and the Rayleigh and Mie
// integrands without it (β_s times the transmittance to the sun).
struct SingleSample {
    t: vec4<f32>,
    // Each group's β_s·T, which the quadrature's exponential fit follows.
    f_r: vec4<f32>,
    f_m: vec4<f32>,
    g_r: vec4<f32>,
    g_m: vec4<f32>,
}

fn single_sample(t: ScatteringTexel, d_km: f32, k: u32) -> SingleSample {
    let rho_d_km = rho_at(t.r_km, t.rho_km, t.mu, d_km);
    let r_d_km = radius_from_rho(rho_d_km);
    let mu_s_d = clamp_cosine((t.r_km * t.mu_s + d_km * t.nu) / r_d_km);
    let sun = transmittance_to_sun(r_d_km, rho_d_km, mu_s_d, k);
    let altitude_km = altitude_of(rho_d_km, r_d_km);
    var s: SingleSample;
    s.t = transmittance(t.r_km, t.rho_km, t.mu, d_km, t.ground, k);
    let beta_r = group_scattering(0u, altitude_km, k);
    let beta_m = group_scattering(1u, altitude_km, k);
    s.f_r = beta_r * s.t;
    s.f_m = beta_m * s.t;
    s.g_r = sun * beta_r;
    s.g_m = sun * beta_m;
    return s;
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = invocation_index(gid, nwg);
    if (i >= scattering_texels()) {
        return;
    }
    let k = gid.z;
    let t = scattering_texel_at(i);
    let length_km = ray_length_km(t);
    let row = i / scattering_width();
    var acc_r = vec4<f32>(0.0);
    var acc_m = vec4<f32>(0.0);
    // Samples 2p, 2p + 1, 2p + 2 of pair p; the last is the next pair's first.
    var s0 = single_sample(t, 0.0, k);
    var d0_km = 0.0;
    for (var p = 0u; p < RAY_INTERVALS / 2u; p++) {
        let d2_km = ray_pair_end_km(row, p + 1u, length_km);
        let step_km = 0.5 * (d2_km - d0_km);
        let s1 = single_sample(t, d0_km + step_km, k);
        let s2 = single_sample(t, d2_km, k);
        let w_r = exponential_simpson_weights(s0.t, s1.t, s2.t, s0.f_r, s1.f_r, s2.f_r);
        let w_m = exponential_simpson_weights(s0.t, s1.t, s2.t, s0.f_m, s1.f_m, s2.f_m);
        acc_r += step_km * (w_r.w0 * s0.g_r + w_r.w1 * s1.g_r + w_r.w2 * s2.g_r);
        acc_m += step_km * (w_m.w0 * s0.g_m + w_m.w1 * s1.g_m + w_m.w2 * s2.g_m);
        s0 = s2;
        d0_km = d2_km;
    }
    // Clamped at 0 as on the CPU: the fitted rule's end weight is negative for a pair with
    // Δτ > 2.9, so a sum can round below zero.
    let e = solar_irradiance(k);
    let o = i * atm.groups + k;
    rayleigh_out[o] = max(acc_r * e, vec4<f32>(0.0));
    mie_out[o] = max(acc_m * e, vec4<f32>(0.0));
}

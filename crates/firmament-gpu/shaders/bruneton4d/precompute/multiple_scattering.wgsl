// Multiple scattering ΔS of order n from ΔJ (paper eq. 12, Bruneton 2017
// `ComputeMultipleScattering`; Rust twin precompute/multiple_scattering.rs,
// `compute_multiple_scattering`): RAY_INTERVALS intervals along the view ray (graded pairs,
// ray.wgsl `ray_pair_end_km`) with the
// exponentially fitted Simpson rule (ray.wgsl `exponential_simpson_weights`), pair of
// intervals by pair. ΔJ is looked up at each sample with u_ν from (μ, μ_s) at that sample
// (params::u_nu: the azimuth relative to the range of ν there). Adds ΔS, as radiance, to
// the multiple-scattering sum (`Tables::multiple`; not divided by a phase function). Reads
// ΔJ at slot a.

@group(0) @binding(7) var<storage, read_write> delta_multiple_out: array<vec4<f32>>;
@group(0) @binding(8) var<storage, read_write> multiple_sum: array<vec4<f32>>;

// One ray sample: the transmittance from the ray origin, the total β_s·T (which the
// quadrature's exponential fit follows: ΔJ is β_s times a smooth field) and ΔJ there
// (the table's ΔJ/β_s, interpolated, times β_s at the sample).
struct MultipleSample {
    t: vec4<f32>,
    f: vec4<f32>,
    j: vec4<f32>,
}

fn multiple_sample(t: ScatteringTexel, d_km: f32, k: u32) -> MultipleSample {
    let rho_d_km = rho_at(t.r_km, t.rho_km, t.mu, d_km);
    let r_d_km = radius_from_rho(rho_d_km);
    let mu_d = clamp_cosine((t.r_km * t.mu + d_km) / r_d_km);
    let uvwz = scattering_uvwz(r_d_km, rho_d_km, mu_d, 0.0, 0.0, t.ground);
    let mu_s_d = clamp_cosine((t.r_km * t.mu_s + d_km * t.nu) / r_d_km);
    let u_mu_s = texcoord_from_unit(x_mu_s(mu_s_d), atm.scattering_mu_s);
    let u_nu = u_nu_from_nu(mu_d, mu_s_d, t.nu);
    let f = scattering_filter_rows(u_nu, u_mu_s, lerp_weights(uvwz.z, atm.scattering_mu), r_filter_linear(uvwz.w, atm.scattering_r));
    var s: MultipleSample;
    s.t = transmittance(t.r_km, t.rho_km, t.mu, d_km, t.ground, k);
    let altitude_km = altitude_of(rho_d_km, r_d_km);
    let beta_s = group_scattering(0u, altitude_km, k) + group_scattering(1u, altitude_km, k);
    s.f = beta_s * s.t;
    // The table holds ΔJ/β_s (scattering_density.wgsl).
    s.j = sample_density_rows_first(f, k) * beta_s;
    return s;
}

// ΔJ at slot a at one column of the filter, (r, μ)-filtered.
fn density_column(f: Filter4, col: u32, k: u32) -> vec4<f32> {
    let g = atm.groups;
    return f.wrow.x * scattering_a[(f.row.x + col) * g + k] + f.wrow.y * scattering_a[(f.row.y + col) * g + k]
        + f.wrow.z * scattering_a[(f.row.z + col) * g + k] + f.wrow.w * scattering_a[(f.row.w + col) * g + k];
}

// ΔJ at a sample as compute_multiple_scattering filters it: the (μ, r)-filtered columns
// (linear in r: ΔJ/β_s is smooth there), blended along μ_s (in a twilight cell by
// mu_s_blend.wgsl) and ν.
fn sample_density_rows_first(f: Filter4, k: u32) -> vec4<f32> {
    if (!f.mu_s.twilight) {
        return f.wcol.x * density_column(f, f.col.x, k) + f.wcol.y * density_column(f, f.col.y, k)
            + f.wcol.z * density_column(f, f.col.z, k) + f.wcol.w * density_column(f, f.col.w, k);
    }
    let c0 = mu_s_blend_at(f.mu_s, density_column(f, f.colb.x, k), density_column(f, f.col.x, k),
        density_column(f, f.col.y, k), density_column(f, f.cola.x, k));
    let c1 = mu_s_blend_at(f.mu_s, density_column(f, f.colb.y, k), density_column(f, f.col.z, k),
        density_column(f, f.col.w, k), density_column(f, f.cola.y, k));
    return f.wnu.x * c0 + f.wnu.y * c1;
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
    var acc = vec4<f32>(0.0);
    // Samples 2p, 2p + 1, 2p + 2 of pair p; the last is the next pair's first.
    var s0 = multiple_sample(t, 0.0, k);
    var d0_km = 0.0;
    for (var p = 0u; p < RAY_INTERVALS / 2u; p++) {
        let d2_km = ray_pair_end_km(row, p + 1u, length_km);
        let step_km = 0.5 * (d2_km - d0_km);
        let s1 = multiple_sample(t, d0_km + step_km, k);
        let s2 = multiple_sample(t, d2_km, k);
        let w = exponential_simpson_weights(s0.t, s1.t, s2.t, s0.f, s1.f, s2.f);
        acc += step_km * (w.w0 * s0.j + w.w1 * s1.j + w.w2 * s2.j);
        s0 = s2;
        d0_km = d2_km;
    }
    // Clamped at 0 as on the CPU (a negative end weight can take a sum below zero).
    let o = i * atm.groups + k;
    let delta = max(acc, vec4<f32>(0.0));
    delta_multiple_out[o] = delta;
    multiple_sum[o] += delta;
}

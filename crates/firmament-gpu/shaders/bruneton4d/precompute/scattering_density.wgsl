// Second half of the scattering density ΔJ (paper eq. 11, Bruneton 2017
// `ComputeScatteringDensity`; Rust twin precompute/scattering_density.rs,
// `compute_scattering_density`, its convolution): the incident field's azimuthal harmonics
// convolved with the phase functions' harmonics (exact for the band-limited field), then
// evaluated at each texel's view azimuth, times β_s(r).

@group(0) @binding(7) var<storage, read> kernels: array<f32>;
@group(0) @binding(8) var<storage, read> coefficients: array<vec4<f32>>;
@group(0) @binding(9) var<storage, read_write> density_out: array<vec4<f32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = invocation_index(gid, nwg);
    let nmu_s = atm.scattering_mu_s;
    let nmu = atm.scattering_mu;
    if (i >= atm.scattering_r * nmu * nmu_s) {
        return;
    }
    let k = gid.z;
    let i_mu_s = i % nmu_s;
    let y = (i / nmu_s) % nmu;
    let z = i / (nmu_s * nmu);
    let t0 = scattering_texel(i_mu_s, y, z);
    let mu_s = t0.mu_s;
    let sin_s = sqrt(max(1.0 - mu_s * mu_s, 0.0));
    let altitude_km = altitude_of(t0.rho_km, t0.r_km);
    // Each group's share of the total β_s in place of its β_s: the table holds ΔJ/β_s,
    // smooth in r (scattering_density.rs); multiple_scattering.wgsl multiplies by β_s.
    let beta_0 = group_scattering(0u, altitude_km, k);
    let beta_1 = group_scattering(1u, altitude_km, k);
    let total = beta_0 + beta_1;
    let inv = select(vec4<f32>(0.0), 1.0 / max(total, vec4<f32>(1e-30)), total > vec4<f32>(0.0));
    var beta = array<vec4<f32>, 2>(beta_0 * inv, beta_1 * inv);
    var present = array<bool, 2>(atm.group0_present != 0u, atm.group1_present != 0u);
    let dtheta = PI / f32(DENSITY_THETA);
    var acc: array<vec4<f32>, 2u * HARMONICS>;
    for (var m = 0u; m < 2u * HARMONICS; m++) {
        acc[m] = vec4<f32>(0.0);
    }
    for (var l = 0u; l < DENSITY_THETA; l++) {
        let solid = dtheta * sin((f32(l) + 0.5) * dtheta);
        let c_base = ((z * nmu_s + i_mu_s) * DENSITY_THETA + l) * HARMONICS;
        let k_base = ((z * nmu + y) * DENSITY_THETA + l) * 2u * HARMONICS;
        for (var g = 0u; g < 2u; g++) {
            if (!present[g]) {
                continue;
            }
            for (var m = 0u; m < HARMONICS; m++) {
                let b = kernels[k_base + g * HARMONICS + m] * solid;
                acc[g * HARMONICS + m] += b * coefficients[(c_base + m) * atm.groups + k];
            }
        }
    }
    let width = scattering_width();
    for (var i_nu = 0u; i_nu < atm.scattering_nu; i_nu++) {
        let x = i_nu * nmu_s + i_mu_s;
        let t = scattering_texel(x, y, z);
        let sin_v = sqrt(max(1.0 - t.mu * t.mu, 0.0));
        let denom = sin_v * sin_s;
        var cos_phi_v = 1.0;
        if (denom > 1e-12) {
            cos_phi_v = clamp((t.nu - t.mu * mu_s) / denom, -1.0, 1.0);
        }
        let phi_v = acos(cos_phi_v);
        var o = vec4<f32>(0.0);
        for (var g = 0u; g < 2u; g++) {
            if (!present[g]) {
                continue;
            }
            for (var m = 0u; m < HARMONICS; m++) {
                let w = select(PI * cos(f32(m) * phi_v), 2.0 * PI, m == 0u);
                o += w * acc[g * HARMONICS + m] * beta[g];
            }
        }
        density_out[((z * nmu + y) * width + x) * atm.groups + k] = o;
    }
}

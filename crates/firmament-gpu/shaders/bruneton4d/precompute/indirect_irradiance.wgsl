// Indirect ground irradiance ΔE from the previous order (paper eq. 15, Bruneton 2017
// `ComputeIndirectIrradiance`; Rust twin precompute/indirect_irradiance.rs,
// `compute_indirect_irradiance`): midpoint rule over the upper hemisphere,
// IRRADIANCE_THETA zeniths × IRRADIANCE_PHI azimuths (half circle counted twice by symmetry
// about the sun). Adds ΔE to the irradiance sum.

@group(0) @binding(7) var<storage, read_write> delta_irradiance_out: array<vec4<f32>>;
@group(0) @binding(8) var<storage, read_write> irradiance_sum: array<vec4<f32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = invocation_index(gid, nwg);
    if (i >= atm.irradiance_mu_s * atm.irradiance_r) {
        return;
    }
    let k = gid.z;
    let t = irradiance_texel(i % atm.irradiance_mu_s, i / atm.irradiance_mu_s);
    let r_km = t.x;
    let rho_km = t.y;
    let mu_s = t.z;
    let sin_s = sqrt(max(1.0 - mu_s * mu_s, 0.0));
    let dtheta = PI / 2.0 / f32(IRRADIANCE_THETA);
    let dphi = 2.0 * PI / f32(IRRADIANCE_PHI);
    var acc = vec4<f32>(0.0);
    for (var j = 0u; j < IRRADIANCE_THETA; j++) {
        let theta = (f32(j) + 0.5) * dtheta;
        let sin_t = sin(theta);
        let cos_t = cos(theta);
        let domega = dtheta * dphi * sin_t;
        var ring = vec4<f32>(0.0);
        for (var p = 0u; p < IRRADIANCE_PHI / 2u; p++) {
            let phi = (f32(p) + 0.5) * dphi;
            let nu = clamp(cos(phi) * sin_t * sin_s + cos_t * mu_s, -1.0, 1.0);
            ring += previous_radiance(r_km, rho_km, cos_t, mu_s, nu, false, k);
        }
        acc += 2.0 * ring * cos_t * domega;
    }
    let o = i * atm.groups + k;
    delta_irradiance_out[o] = acc;
    irradiance_sum[o] += acc;
}

// Direct sun irradiance on a horizontal surface, E_sun·T·(mean cosine over the visible part
// of the disk) (Bruneton 2017 `ComputeDirectIrradiance`; Rust twin
// precompute/direct_irradiance.rs). Also clears the irradiance sum.

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
    let alpha_s = atm.sun_angular_radius;
    var cos_factor = 0.0;
    if (mu_s > alpha_s) {
        cos_factor = mu_s;
    } else if (mu_s >= -alpha_s) {
        cos_factor = (mu_s + alpha_s) * (mu_s + alpha_s) / (4.0 * alpha_s);
    }
    let e = solar_irradiance(k) * transmittance_to_top(r_km, rho_km, mu_s, k) * cos_factor;
    delta_irradiance_out[i * atm.groups + k] = e;
    irradiance_sum[i * atm.groups + k] = vec4<f32>(0.0);
}

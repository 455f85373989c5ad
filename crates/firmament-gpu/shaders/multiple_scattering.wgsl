// Multiple scattering ΔS of order n from ΔJ (paper eq. 12, Bruneton 2017
// `ComputeMultipleScattering`; lut::precompute::compute_multiple_scattering): 50 Simpson
// intervals along the view ray. Adds ΔS/P_molecules(ν) to the scattering sum (the table
// stores Rayleigh-like radiance divided by the phase function applied at render time).
// Reads ΔJ at slot a.

@group(0) @binding(7) var<storage, read_write> delta_multiple_out: array<vec4<f32>>;
@group(0) @binding(8) var<storage, read_write> scattering_sum: array<vec4<f32>>;

const RAY_INTERVALS: u32 = 50u;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = invocation_index(gid, nwg);
    if (i >= scattering_texels()) {
        return;
    }
    let k = gid.z;
    let width = scattering_width();
    let x = i % width;
    let y = (i / width) % atm.scattering_mu;
    let z = i / (width * atm.scattering_mu);
    let t = scattering_texel(x, y, z);
    var ray_length: f32;
    if (t.ground) {
        ray_length = distance_to_bottom(t.r, t.rho, t.mu);
    } else {
        ray_length = distance_to_top(t.r, t.rho, t.mu);
    }
    let dx = ray_length / f32(RAY_INTERVALS);
    let u_nu = u_nu_from_nu(t.nu);
    var acc = vec4<f32>(0.0);
    for (var s = 0u; s <= RAY_INTERVALS; s++) {
        let d = f32(s) * dx;
        let rho_d = rho_at(t.r, t.rho, t.mu, d);
        let r_d = radius_from_rho(rho_d);
        let mu_d = clamp_cosine((t.r * t.mu + d) / r_d);
        let uvwz = scattering_uvwz(r_d, rho_d, mu_d, 0.0, 0.0, t.ground);
        let mu_s_d = clamp_cosine((t.r * t.mu_s + d * t.nu) / r_d);
        let u_mu_s = texcoord_from_unit(x_mu_s(mu_s_d), atm.scattering_mu_s);
        let f = scattering_filter_rows(u_nu, u_mu_s, lerp_weights(uvwz.z, atm.scattering_mu), lerp_weights(uvwz.w, atm.scattering_r));
        let w = ray_weight(s);
        acc += w * transmittance(t.r, t.rho, t.mu, d, t.ground, k) * sample_scattering_a(f, k);
    }
    let o = i * atm.groups + k;
    let delta = acc * dx;
    delta_multiple_out[o] = delta;
    scattering_sum[o] += delta / max(group_phase(0u, t.nu), 1e-6);
}

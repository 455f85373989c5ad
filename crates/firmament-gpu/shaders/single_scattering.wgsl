// Single scattering (Bruneton & Neyret 2008 eq. 7; Bruneton 2017 `ComputeSingleScattering`):
// Rayleigh and Mie integrated apart without phase functions, 50 Simpson intervals along the
// view ray. Also initialises the scattering sum with the Rayleigh part.

@group(0) @binding(7) var<storage, read_write> rayleigh_out: array<vec4<f32>>;
@group(0) @binding(8) var<storage, read_write> mie_out: array<vec4<f32>>;
@group(0) @binding(9) var<storage, read_write> scattering_sum: array<vec4<f32>>;

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
    var acc_r = vec4<f32>(0.0);
    var acc_m = vec4<f32>(0.0);
    for (var s = 0u; s <= RAY_INTERVALS; s++) {
        let d = f32(s) * dx;
        let rho_d = rho_at(t.r, t.rho, t.mu, d);
        let r_d = radius_from_rho(rho_d);
        let mu_s_d = clamp_cosine((t.r * t.mu_s + d * t.nu) / r_d);
        let w = ray_weight(s);
        let tr = w * transmittance(t.r, t.rho, t.mu, d, t.ground, k) * transmittance_to_sun(r_d, rho_d, mu_s_d, k);
        let altitude = altitude_of(rho_d, r_d);
        acc_r += tr * group_scattering(0u, altitude, k);
        acc_m += tr * group_scattering(1u, altitude, k);
    }
    let e = solar_irradiance(k) * dx;
    let o = i * atm.groups + k;
    rayleigh_out[o] = acc_r * e;
    mie_out[o] = acc_m * e;
    scattering_sum[o] = acc_r * e;
}

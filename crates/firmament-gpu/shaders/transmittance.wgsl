// Optical depth τ(r, μ) to the top of the atmosphere (lut::precompute::compute_optical_depth;
// the lookups interpolate τ and take e^{−τ}):
// 4-point Gauss–Legendre on 128 segments of the ray, per channel group, capped at
// MAX_OPTICAL_DEPTH (T = 0 in f32).

@group(0) @binding(7) var<storage, read_write> transmittance_out: array<vec4<f32>>;

const TRANSMITTANCE_SEGMENTS: u32 = 128u;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = invocation_index(gid, nwg);
    if (i >= atm.transmittance_mu * atm.transmittance_r) {
        return;
    }
    let k = gid.z;
    let t = transmittance_texel(i % atm.transmittance_mu, i / atm.transmittance_mu);
    let r = t.x;
    let rho = t.y;
    let mu = t.z;
    let ray_length = distance_to_top(r, rho, mu);
    var gl_x = array<f32, 4>(-0.8611363115940526, -0.3399810435848563, 0.3399810435848563, 0.8611363115940526);
    var gl_w = array<f32, 4>(0.3478548451374539, 0.6521451548625461, 0.6521451548625461, 0.3478548451374539);
    var tau = vec4<f32>(0.0);
    if (ray_length > 0.0) {
        let h = ray_length / f32(TRANSMITTANCE_SEGMENTS);
        for (var s = 0u; s < TRANSMITTANCE_SEGMENTS; s++) {
            let c = (f32(s) + 0.5) * h;
            var segment = vec4<f32>(0.0);
            for (var q = 0u; q < 4u; q++) {
                let d = c + 0.5 * h * gl_x[q];
                let rho_d_sq = max(d * d + 2.0 * r * mu * d + rho * rho, 0.0);
                let radius = sqrt(rho_d_sq + atm.bottom_radius * atm.bottom_radius);
                segment += gl_w[q] * extinction(rho_d_sq / (radius + atm.bottom_radius), k);
            }
            tau += segment;
        }
        tau *= 0.5 * h;
    }
    transmittance_out[i * atm.groups + k] = min(tau, vec4<f32>(MAX_OPTICAL_DEPTH));
}

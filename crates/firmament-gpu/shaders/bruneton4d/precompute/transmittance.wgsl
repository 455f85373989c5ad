// Optical depth τ(r, μ) to the top of the atmosphere (firmament::sky::bruneton4d::
// precompute::transmittance::compute_optical_depth; the lookups interpolate τ and take
// e^{−τ}): the composite 4-point Gauss–Legendre rule (math::quadrature::GL4) on
// TRANSMITTANCE_SEGMENTS panels of the ray, per channel group, capped at MAX_OPTICAL_DEPTH
// (T = 0 in f32).

@group(0) @binding(7) var<storage, read_write> transmittance_out: array<vec4<f32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = invocation_index(gid, nwg);
    if (i >= atm.transmittance_mu * atm.transmittance_r) {
        return;
    }
    let k = gid.z;
    let t = transmittance_texel(i % atm.transmittance_mu, i / atm.transmittance_mu);
    let r_km = t.x;
    let rho_km = t.y;
    let mu = t.z;
    let ray_length_km = distance_to_top(r_km, rho_km, mu);
    var nodes = GL4_NODES;
    var weights = GL4_WEIGHTS;
    var tau = vec4<f32>(0.0);
    if (ray_length_km > 0.0) {
        let h_km = ray_length_km / f32(TRANSMITTANCE_SEGMENTS);
        for (var s = 0u; s < TRANSMITTANCE_SEGMENTS; s++) {
            let c_km = (f32(s) + 0.5) * h_km;
            var segment = vec4<f32>(0.0);
            for (var q = 0u; q < 4u; q++) {
                // Nodes c ∓ h·x_j/2 of each positive node x_j.
                let side = select(1.0, -1.0, q % 2u == 0u);
                let d_km = c_km + side * 0.5 * h_km * nodes[q / 2u];
                let rho_d_sq_km2 = max(d_km * d_km + 2.0 * r_km * mu * d_km + rho_km * rho_km, 0.0);
                let radius_km = sqrt(rho_d_sq_km2 + atm.bottom_radius_km * atm.bottom_radius_km);
                segment += weights[q / 2u] * extinction(rho_d_sq_km2 / (radius_km + atm.bottom_radius_km), k);
            }
            tau += segment;
        }
        tau *= 0.5 * h_km;
    }
    transmittance_out[i * atm.groups + k] = min(tau, vec4<f32>(MAX_OPTICAL_DEPTH));
}

// Factors q/(1 − q) of the geometric tail of the orders beyond the last one, N (Rust twin
// precompute/order_tail.rs, `order_tail_factors`): q = Σ ΔS_N / Σ ΔS_{N−1} per channel over
// the order row sums (order_sums.wgsl, read at slot a), capped at ORDER_RATIO_CAP; 0 where either sum
// is 0 or the orders do not decrease (no convergent series to extrapolate); then capped so
// that no irradiance texel passes the sun outside the air (`cap_by_energy`). N is the pass
// order. One invocation per channel group.

@group(0) @binding(7) var<storage, read_write> tail_factors: array<vec4<f32>>;
// The sky's irradiance summed over the orders so far (the last order's ΔE is at the
// irradiance slot): the cap of `cap_by_energy`.
@group(0) @binding(8) var<storage, read> irradiance_so_far: array<vec4<f32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    if (invocation_index(gid, nwg) > 0u) {
        return;
    }
    let k = gid.z;
    let rows = atm.scattering_r * atm.scattering_mu;
    let n = pass_params.order;
    var last = vec4<f32>(0.0);
    var before = vec4<f32>(0.0);
    for (var row = 0u; row < rows; row++) {
        last += scattering_a[((n - 1u) * rows + row) * atm.groups + k];
        before += scattering_a[((n - 2u) * rows + row) * atm.groups + k];
    }
    let valid = (before > vec4<f32>(0.0)) & (last > vec4<f32>(0.0)) & (last < before);
    let q = select(vec4<f32>(0.0), min(last / before, vec4<f32>(ORDER_RATIO_CAP)), valid);
    var f = q / (1.0 - q);
    // cap_by_energy: no irradiance texel passes the sun's irradiance outside the air.
    let solar = solar_irradiance(k);
    for (var i = 0u; i < atm.irradiance_mu_s * atm.irradiance_r; i++) {
        let o = i * atm.groups + k;
        let room = max(solar - irradiance_so_far[o], vec4<f32>(0.0));
        let d = delta_irradiance_table[o];
        f = select(f, min(f, room / max(d, vec4<f32>(1e-30))), d > vec4<f32>(0.0));
    }
    tail_factors[k] = f;
}

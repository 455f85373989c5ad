// Per-row sums of one scattering order's radiance (for `Tables::order_means`; Rust twin
// precompute/order_tail.rs, `table_mean_radiance` and `table_mean`): order 1 sums the
// single-scattering tables with the phase functions at each texel's ν, order n ≥ 2 sums
// ΔS. Slots a and b.

@group(0) @binding(7) var<storage, read_write> row_sums: array<vec4<f32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = invocation_index(gid, nwg);
    let rows = atm.scattering_r * atm.scattering_mu;
    if (i >= rows) {
        return;
    }
    let k = gid.z;
    let width = scattering_width();
    var sum = vec4<f32>(0.0);
    for (var x = 0u; x < width; x++) {
        let idx = (i * width + x) * atm.groups + k;
        if (pass_params.order == 1u) {
            let t = scattering_texel(x, i % atm.scattering_mu, i / atm.scattering_mu);
            sum += scattering_a[idx] * group_phase(0u, t.nu) + scattering_b[idx] * group_phase(1u, t.nu);
        } else {
            sum += scattering_a[idx];
        }
    }
    row_sums[((pass_params.order - 1u) * rows + i) * atm.groups + k] = sum;
}

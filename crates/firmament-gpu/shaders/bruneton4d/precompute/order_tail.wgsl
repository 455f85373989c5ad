// The geometric tail of the orders beyond the last one, N (Rust twin precompute/order_tail.rs,
// applied by `add_scaled` in precompute/mod.rs): multiple += ΔS_N·f and irradiance +=
// ΔE_{N−1}·f, with f from order_tail_factors.wgsl. Reads ΔS_N at slot a, ΔE at the
// irradiance slot, the factors at slot b.

@group(0) @binding(7) var<storage, read_write> multiple_sum: array<vec4<f32>>;
@group(0) @binding(8) var<storage, read_write> irradiance_sum: array<vec4<f32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = invocation_index(gid, nwg);
    let k = gid.z;
    let f = scattering_b[k];
    let o = i * atm.groups + k;
    if (i < scattering_texels()) {
        multiple_sum[o] += scattering_a[o] * f;
    }
    if (i < atm.irradiance_mu_s * atm.irradiance_r) {
        irradiance_sum[o] += delta_irradiance_table[o] * f;
    }
}

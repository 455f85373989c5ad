// Azimuthal harmonics of each scattering group's phase function, for every table radius,
// view zenith (table μ) and incident zenith: b_m with P(Δφ) = Σ b_m cos(mΔφ), by the
// trapezoid rule over [0, π] (Rust twin precompute/phase_kernels.rs, `PhaseKernels::new`).
// Computed once: they do not depend on the scattering order.

@group(0) @binding(7) var<storage, read_write> kernels_out: array<f32>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = invocation_index(gid, nwg);
    if (i >= atm.scattering_r * atm.scattering_mu * DENSITY_THETA * 2u) {
        return;
    }
    let g = i % 2u;
    let l = (i / 2u) % DENSITY_THETA;
    let row = i / (2u * DENSITY_THETA);
    let base = i * HARMONICS;
    var o: array<f32, HARMONICS>;
    for (var m = 0u; m < HARMONICS; m++) {
        o[m] = 0.0;
    }
    let present = select(atm.group1_present, atm.group0_present, g == 0u);
    if (present != 0u) {
        let t = scattering_texel(0u, row % atm.scattering_mu, row / atm.scattering_mu);
        let mu_v = t.mu;
        let sin_v = sqrt(max(1.0 - mu_v * mu_v, 0.0));
        let theta = (f32(l) + 0.5) * PI / f32(DENSITY_THETA);
        let sin_i = sin(theta);
        let cos_i = cos(theta);
        for (var s = 0u; s <= KERNEL_STEPS; s++) {
            let dphi = PI * f32(s) / f32(KERNEL_STEPS);
            let p = group_phase(g, clamp(mu_v * cos_i + sin_v * sin_i * cos(dphi), -1.0, 1.0));
            let w = select(1.0, 0.5, s == 0u || s == KERNEL_STEPS);
            for (var m = 0u; m < HARMONICS; m++) {
                o[m] += w * p * cos(f32(m) * dphi);
            }
        }
        // b_0 = (1/π)∫P, b_m = (2/π)∫P cos(mΔ), with the trapezoid step π/KERNEL_STEPS.
        for (var m = 0u; m < HARMONICS; m++) {
            o[m] *= select(2.0, 1.0, m == 0u) / f32(KERNEL_STEPS);
        }
    }
    for (var m = 0u; m < HARMONICS; m++) {
        kernels_out[base + m] = o[m];
    }
}

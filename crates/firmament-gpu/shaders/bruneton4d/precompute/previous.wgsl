// The radiance field of the previous scattering order (firmament::sky::bruneton4d::
// precompute::Previous), read by the scattering density and indirect irradiance passes.

// Radiance of the previous order towards (r, μ) for the sun at (μ_s, ν): single scattering
// with the phase functions applied (mode 0), or ΔS (mode 1).
fn previous_radiance(r_km: f32, rho_km: f32, mu: f32, mu_s: f32, nu: f32, ground: bool, k: u32) -> vec4<f32> {
    let f = scattering_filter(scattering_uvwz(r_km, rho_km, mu, mu_s, nu, ground));
    if (pass_params.mode == 0u) {
        return sample_scattering_a(f, k) * group_phase(0u, nu) + sample_scattering_b(f, k) * group_phase(1u, nu);
    }
    return sample_scattering_a(f, k);
}

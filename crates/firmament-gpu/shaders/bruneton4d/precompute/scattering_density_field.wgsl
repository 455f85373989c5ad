// First half of the scattering density ΔJ (Rust twin precompute/scattering_density.rs,
// `compute_scattering_density`, its incident-field loop): for each (r, μ_s) and incident
// zenith θ_l, the incident radiance of the previous order (plus the light reflected by the
// ground) at DENSITY_PHI/2 azimuths of the half circle in the sun's frame, expanded as a
// cosine series in azimuth (HARMONICS harmonics).

@group(0) @binding(7) var<storage, read_write> coefficients_out: array<vec4<f32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = invocation_index(gid, nwg);
    if (i >= atm.scattering_r * atm.scattering_mu_s * DENSITY_THETA) {
        return;
    }
    let k = gid.z;
    let l = i % DENSITY_THETA;
    let i_mu_s = (i / DENSITY_THETA) % atm.scattering_mu_s;
    let z = i / (DENSITY_THETA * atm.scattering_mu_s);
    let t = scattering_texel(i_mu_s, 0u, z);
    let r_km = t.r_km;
    let rho_km = t.rho_km;
    let mu_s = t.mu_s;
    let sin_s = sqrt(max(1.0 - mu_s * mu_s, 0.0));
    let dtheta = PI / f32(DENSITY_THETA);
    let dphi = 2.0 * PI / f32(DENSITY_PHI);
    let theta = (f32(l) + 0.5) * dtheta;
    let sin_i = sin(theta);
    let cos_i = cos(theta);
    let ground = ray_intersects_ground(r_km, rho_km, cos_i);
    var d_ground_km = 0.0;
    var t_ground = vec4<f32>(0.0);
    if (ground) {
        d_ground_km = distance_to_bottom(r_km, rho_km, cos_i);
        t_ground = transmittance(r_km, rho_km, cos_i, d_ground_km, true, k);
    }
    let albedo = ground_albedo(k) / PI;
    var field: array<vec4<f32>, DENSITY_PHI / 2u>;
    for (var j = 0u; j < DENSITY_PHI / 2u; j++) {
        let phi = (f32(j) + 0.5) * dphi;
        let w_i = vec3<f32>(cos(phi) * sin_i, sin(phi) * sin_i, cos_i);
        let nu_i = clamp(w_i.x * sin_s + w_i.z * mu_s, -1.0, 1.0);
        var radiance = previous_radiance(r_km, rho_km, cos_i, mu_s, nu_i, ground, k);
        if (ground) {
            // Light reflected by the Lambertian ground: T·(α/π)·ΔE(n·ω_s).
            let p = vec3<f32>(d_ground_km * w_i.x, d_ground_km * w_i.y, r_km + d_ground_km * w_i.z);
            let mu_g = (p.x * sin_s + p.z * mu_s) / length(p);
            radiance += t_ground * albedo * delta_irradiance(0.0, clamp(mu_g, -1.0, 1.0), k);
        }
        field[j] = radiance;
    }
    // Cosine series of the even field: c_0 = (2/N)Σ_half, c_m = (4/N)Σ_half cos(mφ_j).
    for (var m = 0u; m < HARMONICS; m++) {
        let scale = select(4.0, 2.0, m == 0u) / f32(DENSITY_PHI);
        var c = vec4<f32>(0.0);
        for (var j = 0u; j < DENSITY_PHI / 2u; j++) {
            c += scale * cos(f32(m) * (f32(j) + 0.5) * dphi) * field[j];
        }
        coefficients_out[(i * HARMONICS + m) * atm.groups + k] = c;
    }
}

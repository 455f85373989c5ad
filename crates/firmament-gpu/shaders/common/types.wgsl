// The atmosphere and pass parameters as every shader reads them (firmament_gpu::bruneton4d::
// atmosphere::pack fills the uniform in this field order). Lengths in km (f32 precision),
// coefficients in km⁻¹.

// Atmosphere and table sizes: one uniform buffer per atmosphere, never baked into the shader
// source (changing the atmosphere compiles nothing).
struct Atmosphere {
    bottom_radius_km: f32,
    top_radius_km: f32,
    h_km: f32,
    h_sq_km2: f32,
    mu_s_min: f32,
    mu_s_big_a: f32,
    // The sun's zenith angle at the joint of the μ_s mapping (rad; params::MuSMap::theta_joint).
    mu_s_theta_joint: f32,
    sun_angular_radius: f32,
    channels: u32,
    groups: u32,
    constituents: u32,
    transmittance_mu: u32,
    transmittance_r: u32,
    scattering_r: u32,
    scattering_mu: u32,
    scattering_mu_s: u32,
    scattering_nu: u32,
    irradiance_mu_s: u32,
    irradiance_r: u32,
    solar_offset: u32,
    albedo_offset: u32,
    constituent_offset: u32,
    layer_offset: u32,
    phase0_kind: u32,
    phase0_offset: u32,
    phase0_count: u32,
    phase0_a: f32,
    phase0_b: f32,
    phase0_c: f32,
    phase1_kind: u32,
    phase1_offset: u32,
    phase1_count: u32,
    phase1_a: f32,
    phase1_b: f32,
    phase1_c: f32,
    group0_present: u32,
    group1_present: u32,
    // The μ_s cells of the scattering and the irradiance tables that take the twilight
    // blend (firmament::sky::bruneton4d::mu_s_blend::twilight_cells, irradiance_twilight_cells).
    mu_s_twilight_cells: u32,
    irradiance_twilight_cells: u32,
    // Bruneton's coordinate at the joint of the μ_s mapping (params::MuSMap::joint_bruneton_x:
    // 26/31, or higher over a shell thin for its planet).
    mu_s_joint_bruneton_x: f32,
    // Where the precomputation's view rays are sampled (in `data`, vec4s from here; 0 outside
    // the precomputation): the interior ends of the RAY_INTERVALS / 2 pairs, as fractions of
    // each (r, μ) row's ray length (firmament::sky::bruneton4d::precompute::ray_grading).
    ray_fractions_offset: u32,
}

// Which radiance field a pass reads (0: single scattering, phase functions applied at lookup;
// 1: the previous order's ΔS as it is) and the scattering order.
struct PassParams {
    mode: u32,
    order: u32,
    pad0: u32,
    pad1: u32,
}

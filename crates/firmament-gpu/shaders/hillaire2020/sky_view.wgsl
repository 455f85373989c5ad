// The sky-view table (firmament::sky::hillaire2020::sky_view; Hillaire 2020 §5.3): for the
// observer and each light, the radiance per unit light irradiance scattered towards the
// observer along every direction of params.wgsl's (azimuth, zenith) parameterisation,
// marched once per texel (`sky_view`, dispatched before each frame: the method's per-view
// cache, as the 4D tables' slice); a view ray then costs one bilinear lookup
// (`sky_view_sample`). Rays that meet the ground end there.

// Light l's table: texel e (azimuth fastest), channel group k at (l·texels + e)·groups + k.
@group(0) @binding(13) var<storage, read_write> sky_view_table: array<vec4<f32>>;

// The observer and the lights the tables are built for (firmament_gpu::hillaire2020::render
// fills it, in f64 rounded once).
struct SkyViewCoordinates {
    // Per light: (μ_s at the observer, the light's angular radius (rad), 0, 0).
    at: array<vec4<f32>, MAX_LIGHTS>,
    // The observer's radius and ρ = sqrt(r² − R_g²) (km), and the lights.
    r_km: f32,
    rho_km: f32,
    lights: u32,
    pad0: u32,
}

@group(0) @binding(15) var<uniform> sky_view_coordinates: SkyViewCoordinates;

// Texels per light's table.
fn sky_view_texels() -> u32 {
    return hillaire.sky_view_azimuth * hillaire.sky_view_zenith;
}

// Texel e of light l's table, channel group k (sky_view::compute): the march to the ground or
// the top with the groups' phase functions at the texel's ν and the multiple scattering.
@compute @workgroup_size(64)
fn sky_view(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = invocation_index(gid, nwg);
    let texels = sky_view_texels();
    if (i >= texels * sky_view_coordinates.lights) {
        return;
    }
    let light = i / texels;
    let e = i % texels;
    let k = gid.z;
    let r_km = sky_view_coordinates.r_km;
    let rho_km = sky_view_coordinates.rho_km;
    let mu_s = sky_view_coordinates.at[light].x;
    let mc = sky_view_mu_cos_phi(r_km, rho_km, e % hillaire.sky_view_azimuth, e / hillaire.sky_view_azimuth);
    let mu = mc.x;
    let sin_s = safe_sqrt(1.0 - mu_s * mu_s);
    let ground = ray_intersects_ground(r_km, rho_km, mu);
    var ray: MarchRay;
    ray.r_km = r_km;
    ray.rho_km = rho_km;
    ray.mu = mu;
    ray.mu_s = mu_s;
    ray.nu = clamp_cosine(mu * mu_s + safe_sqrt(1.0 - mu * mu) * sin_s * mc.y);
    ray.length_km = select(distance_to_top(r_km, rho_km, mu), distance_to_bottom(r_km, rho_km, mu), ground);
    ray.angular_radius = sky_view_coordinates.at[light].y;
    let phases = vec2<f32>(group_phase(0u, ray.nu), group_phase(1u, ray.nu));
    let m = march(ray, hillaire.sky_view_steps, phases, lighting_all(), true, k);
    sky_view_table[(light * texels + e) * atm.groups + k] = m.radiance;
}

// Radiance per unit light irradiance along (μ, cos φ) from (r, ρ), bilinear in light
// `light`'s table (sky_view::sample), channel group k.
fn sky_view_sample(light: u32, r_km: f32, rho_km: f32, mu: f32, cos_phi: f32, k: u32) -> vec4<f32> {
    let f = table2_filter(sky_view_uv(r_km, rho_km, mu, cos_phi), hillaire.sky_view_azimuth, hillaire.sky_view_zenith);
    let base = light * sky_view_texels() * atm.groups + k;
    return f.weight.x * sky_view_table[base + f.index.x] + f.weight.y * sky_view_table[base + f.index.y]
        + f.weight.z * sky_view_table[base + f.index.z] + f.weight.w * sky_view_table[base + f.index.w];
}

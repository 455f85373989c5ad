// The multiple-scattering pass (firmament::sky::hillaire2020::multiple_scattering; Hillaire
// 2020 §5.5, eq. 5–10): at each (μ_s, altitude) texel the light scattered once towards the
// point (and reflected by the Lambertian ground), L′(ω), gathered over the sphere with the
// transfer f_ms of a unit isotropic radiance through one more scattering (eq. 8); the orders
// beyond the second sum to the second times 1/(1 − f_ms) (eq. 9–10). The field is projected
// on the harmonics of harmonics.wgsl (degree 0 alone for the isotropic model, Ψ_ms =
// ⟨L′⟩/(1 − f_ms)).
//
// Two entry points where the CPU has one loop: `gather` marches each (texel, gather
// direction) ray once; `main` projects those rays' L′ on one coefficient per invocation
// (no array of coefficients in private memory) and sums the series.

@group(0) @binding(7) var<storage, read_write> multiple_scattering_out: array<vec4<f32>>;
// Per texel i, gather direction j and channel group k: L′ at (2(i·D + j))·groups + k and
// ∫T·σ_s dt at (2(i·D + j) + 1)·groups + k, D the directions per texel.
@group(0) @binding(22) var<storage, read_write> gathered: array<vec4<f32>>;
// f_ms per texel and channel group, which the host reads back to refuse the atmospheres
// whose series breaks (F_MS_LIMIT).
@group(0) @binding(23) var<storage, read_write> f_ms_out: array<vec4<f32>>;

// Directions per texel.
fn gather_count() -> u32 {
    return (hillaire.gather_below + hillaire.gather_above) * hillaire.gather_phi;
}

// A gather direction in the point's frame (z up, the light in the x–z plane), its azimuth's
// cosine and its solid angle (sr; the mirror image across the light's plane included).
struct GatherDirection {
    dir: vec3<f32>,
    cos_phi: f32,
    weight: f32,
}

// Direction j of the gather rule at (r, ρ) (gather_directions): Gauss–Legendre in μ on
// each side of the horizon μ_h = −ρ/r (the rule below it first), `gather_phi` midpoints in
// φ over [0, π], μ-major.
fn gather_direction(r_km: f32, rho_km: f32, j: u32) -> GatherDirection {
    let mu_h = -rho_km / r_km;
    let i_mu = j / hillaire.gather_phi;
    let i_phi = j % hillaire.gather_phi;
    var a = -1.0;
    var b = mu_h;
    if (i_mu >= hillaire.gather_below) {
        a = mu_h;
        b = 1.0;
    }
    let node = hillaire_data[hillaire.gather_offset + i_mu];
    let mu = 0.5 * (a + b) + 0.5 * (b - a) * node.x;
    let w_mu = 0.5 * (b - a) * node.y;
    let s = safe_sqrt(1.0 - mu * mu);
    let phi = PI * (f32(i_phi) + 0.5) / f32(hillaire.gather_phi);
    var g: GatherDirection;
    g.cos_phi = cos(phi);
    g.dir = vec3<f32>(s * g.cos_phi, s * sin(phi), mu);
    g.weight = w_mu * 2.0 * PI / f32(hillaire.gather_phi);
    return g;
}

// L′ and ∫T·σ_s along gather direction j of texel i, channel group k (the inner loop of
// multiple_scattering::compute): the march without the multiple-scattering field, with an
// isotropic phase (the isotropic model) or the groups' own (the harmonics), plus the
// Lambertian ground lit by the light where the ray meets it (eq. 6).
@compute @workgroup_size(64)
fn gather(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = invocation_index(gid, nwg);
    let d = gather_count();
    if (i >= hillaire.ms_mu_s * hillaire.ms_r * d) {
        return;
    }
    let k = gid.z;
    let texel = i / d;
    let j = i % d;
    let p = altitude_mu_s_of_texel(texel % hillaire.ms_mu_s, texel / hillaire.ms_mu_s, hillaire.ms_mu_s, hillaire.ms_r);
    let sun = vec3<f32>(safe_sqrt(1.0 - p.z * p.z), 0.0, p.z);
    let g = gather_direction(p.x, p.y, j);
    let mu = g.dir.z;
    let ground = ray_intersects_ground(p.x, p.y, mu);
    var ray: MarchRay;
    ray.r_km = p.x;
    ray.rho_km = p.y;
    ray.mu = mu;
    ray.mu_s = p.z;
    ray.nu = clamp_cosine(dot(g.dir, sun));
    ray.length_km = select(distance_to_top(p.x, p.y, mu), distance_to_bottom(p.x, p.y, mu), ground);
    ray.angular_radius = atm.sun_angular_radius;
    var phases = vec2<f32>(INV_4PI);
    if (hillaire.ms_degree > 0u) {
        phases = vec2<f32>(group_phase(0u, ray.nu), group_phase(1u, ray.nu));
    }
    let m = march(ray, hillaire.ms_steps, phases, lighting_all(), false, k);
    var l = m.radiance;
    if (ground) {
        // The ground point (r = R_g, ρ = 0) and the light's zenith cosine there.
        let mu_s_ground = clamp_cosine((ray.r_km * ray.mu_s + ray.length_km * ray.nu) / atm.bottom_radius_km);
        let t_light = transmittance_to_light_at(atm.bottom_radius_km, 0.0, mu_s_ground, atm.sun_angular_radius, k);
        l += m.transmittance * t_light * max(mu_s_ground, 0.0) * ground_albedo(k) / PI;
    }
    let base = 2u * (texel * d + j) * atm.groups;
    gathered[base + k] = l;
    gathered[base + atm.groups + k] = m.scattered;
}

// Coefficient c of texel i, channel group k (multiple_scattering::compute after the gather):
// Σ_j w_j·Y_c(ω_j)·L′_j; for c = 0 also f_ms = Σ_j w_j·p_u·∫T·σ_s, the series' factor
// 1/(1 − f_ms) (guarded at F_MS_GUARD; the host refuses f_ms above F_MS_LIMIT), and f_ms
// written out.
@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = invocation_index(gid, nwg);
    let n = hillaire.ms_coefficients;
    if (i >= hillaire.ms_mu_s * hillaire.ms_r * n) {
        return;
    }
    let k = gid.z;
    let texel = i / n;
    let c = i % n;
    let lm = harmonic_degree_order(c);
    let p = altitude_mu_s_of_texel(texel % hillaire.ms_mu_s, texel / hillaire.ms_mu_s, hillaire.ms_mu_s, hillaire.ms_r);
    let d = gather_count();
    var field = vec4<f32>(0.0);
    var f_ms = vec4<f32>(0.0);
    for (var j = 0u; j < d; j++) {
        let g = gather_direction(p.x, p.y, j);
        let base = 2u * (texel * d + j) * atm.groups;
        field += g.weight * harmonic(lm.x, lm.y, g.dir.z, g.cos_phi) * gathered[base + k];
        if (c == 0u) {
            f_ms += g.weight * INV_4PI * gathered[base + atm.groups + k];
        }
    }
    if (c == 0u) {
        // Degree 0 carries the second order's mean and the isotropic series of the higher
        // orders.
        field /= 1.0 - min(f_ms, vec4<f32>(F_MS_GUARD));
        f_ms_out[texel * atm.groups + k] = f_ms;
    }
    multiple_scattering_out[(texel * n + c) * atm.groups + k] = field;
}

// The sky's irradiance on a horizontal surface, E(r, μ_s) = ∫_{μ>0} L(ω)·μ dω per unit light
// irradiance (firmament::sky::hillaire2020::irradiance): the method's own radiance (single
// scattering with the groups' phase functions plus σ_s·Ψ_ms) marched along the
// `irradiance_directions` directions of a Fibonacci lattice on the upper hemisphere (each
// 2π/n sr, uploaded from the CPU's `band_directions`), one invocation per texel and channel
// group.

@group(0) @binding(7) var<storage, read_write> irradiance_out: array<vec4<f32>>;

// Texel i, channel group k (irradiance::compute): Σ over the directions of the march's
// radiance times μ and the solid angle.
@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = invocation_index(gid, nwg);
    let w = hillaire.irradiance_mu_s;
    if (i >= w * hillaire.irradiance_r) {
        return;
    }
    let k = gid.z;
    let p = altitude_mu_s_of_texel(i % w, i / w, w, hillaire.irradiance_r);
    let sun = vec3<f32>(safe_sqrt(1.0 - p.z * p.z), 0.0, p.z);
    let n = hillaire.irradiance_directions;
    let weight = 2.0 * PI / f32(n);
    var e = vec4<f32>(0.0);
    for (var j = 0u; j < n; j++) {
        let d = hillaire_data[hillaire.directions_offset + j].xyz;
        var ray: MarchRay;
        ray.r_km = p.x;
        ray.rho_km = p.y;
        ray.mu = d.z;
        ray.mu_s = p.z;
        ray.nu = clamp_cosine(dot(d, sun));
        ray.length_km = distance_to_top(p.x, p.y, d.z);
        ray.angular_radius = atm.sun_angular_radius;
        let phases = vec2<f32>(group_phase(0u, ray.nu), group_phase(1u, ray.nu));
        let m = march(ray, hillaire.irradiance_steps, phases, lighting_all(), true, k);
        e += m.radiance * d.z * weight;
    }
    irradiance_out[i * atm.groups + k] = e;
}

// The sky's irradiance on a horizontal surface, E(r, μ_s) = ∫_{μ>0} L(ω)·μ dω per unit light
// irradiance (firmament::sky::hillaire2020::irradiance): the method's own radiance (single
// scattering with the groups' phase functions plus σ_s·Ψ_ms) marched along the
// `irradiance_directions` directions of a Fibonacci lattice on the upper hemisphere (each
// 2π/n sr, uploaded from the CPU's `band_directions`). Two entry points where the CPU has
// one loop: `gather` marches each (texel, direction) ray once, `main` sums a texel's rays.
// (llvmpipe, lavapipe's compiler, ends every loop of an invocation once all its loops
// together have run LP_MAX_TGSI_LOOP_ITERATIONS = 65 535 iterations: one invocation marching
// all 32 directions of a texel, with the harmonics' loops at each step, passes that from
// degree 3 on and read 6× low at degree 6.)

@group(0) @binding(7) var<storage, read_write> irradiance_out: array<vec4<f32>>;
// Per texel i, direction j and channel group k: the ray's radiance × μ × its solid angle at
// (i·irradiance_directions + j)·groups + k.
@group(0) @binding(22) var<storage, read_write> irradiance_rays: array<vec4<f32>>;

// Direction j of texel i, channel group k (the loop body of irradiance::compute): the march's
// radiance times μ and the solid angle 2π/n.
@compute @workgroup_size(64)
fn gather(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = invocation_index(gid, nwg);
    let w = hillaire.irradiance_mu_s;
    let n = hillaire.irradiance_directions;
    if (i >= w * hillaire.irradiance_r * n) {
        return;
    }
    let k = gid.z;
    let texel = i / n;
    let j = i % n;
    let p = altitude_mu_s_of_texel(texel % w, texel / w, w, hillaire.irradiance_r);
    let sun = vec3<f32>(safe_sqrt(1.0 - p.z * p.z), 0.0, p.z);
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
    irradiance_rays[i * atm.groups + k] = m.radiance * d.z * (2.0 * PI / f32(n));
}

// Texel i, channel group k (irradiance::compute): the sum of its rays, in direction order.
@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = invocation_index(gid, nwg);
    if (i >= hillaire.irradiance_mu_s * hillaire.irradiance_r) {
        return;
    }
    let k = gid.z;
    let n = hillaire.irradiance_directions;
    var e = vec4<f32>(0.0);
    for (var j = 0u; j < n; j++) {
        e += irradiance_rays[(i * n + j) * atm.groups + k];
    }
    irradiance_out[i * atm.groups + k] = e;
}

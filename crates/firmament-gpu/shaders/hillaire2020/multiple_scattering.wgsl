// The multiple-scattering pass (firmament::sky::hillaire2020::multiple_scattering; Hillaire
// 2020 §5.5, eq. 5–10): at each (μ_s, altitude) texel the light scattered once towards the
// point (and reflected by the Lambertian ground), L′(ω), gathered over the sphere with the
// transfer f_ms of a unit isotropic radiance through one more scattering (eq. 8); the orders
// beyond the second sum to the second times 1/(1 − f_ms) (eq. 9–10). The field is projected
// on the harmonics of harmonics.wgsl (degree 0 alone for the isotropic model, Ψ_ms =
// ⟨L′⟩/(1 − f_ms)). With multiple_scattering_orders = n > 2 the fields of orders 2 … n − 1
// are gathered too, each marched through the previous one's (no single scattering) with the
// ground lit by the previous one's upward irradiance, on a coarser rule and degree
// (HIGHER_ORDERS_DIRECTIONS, HIGHER_ORDERS_DEGREE: the build's copies of the `Hillaire`
// uniform for those orders), and the orders beyond by the tail (`tail`).
//
// Entry points where the CPU has one loop: `gather` marches each (texel, gather direction)
// ray of the first order once; `main` projects those rays' L′ on one coefficient per
// invocation (no array of coefficients in private memory); `gather_next` and `project_next`
// do the same for each higher order; `tail` adds the orders beyond the last one.
//
// An order's field (binding 24 as it is written, binding 20 as the next order reads it):
// texel i, coefficient c, channel group k at (i·order_coefficients + c)·groups + k, then the
// upward irradiance of the bottom row's texel x at (texels·order_coefficients + x)·groups
// + k (Gathered::up_irradiance: the next order's ground).

@group(0) @binding(7) var<storage, read_write> multiple_scattering_out: array<vec4<f32>>;
// Per texel i, gather direction j and channel group k: L′ at (2(i·D + j))·groups + k and
// ∫T·σ_s dt at (2(i·D + j) + 1)·groups + k, D the directions per texel.
@group(0) @binding(22) var<storage, read_write> gathered: array<vec4<f32>>;
// f_ms per texel and channel group, which the host reads back to refuse the atmospheres
// whose series breaks (F_MS_LIMIT).
@group(0) @binding(23) var<storage, read_write> f_ms_out: array<vec4<f32>>;
// The field of the order a pass gathers (see above); in `tail`, the last order's.
@group(0) @binding(24) var<storage, read_write> order_field: array<vec4<f32>>;

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

// A gather ray: direction j of texel `texel` to the boundary it ends on, and whether that
// is the ground (Grid::gather's MarchRay).
struct GatherRay {
    ray: MarchRay,
    ground: bool,
}

fn gather_ray(texel: u32, j: u32) -> GatherRay {
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
    return GatherRay(ray, ground);
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
    let gr = gather_ray(texel, j);
    let ray = gr.ray;
    let ground = gr.ground;
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

// Σ_j w_j·μ_j·L_j over the gather directions above the horizontal of texel `texel`, channel
// group k (Grid::gather's `up`: the irradiance the order's field delivers to a horizontal
// surface facing up), from the radiances `gather` or `gather_next` left.
fn up_irradiance(texel: u32, k: u32) -> vec4<f32> {
    let p = altitude_mu_s_of_texel(texel % hillaire.ms_mu_s, texel / hillaire.ms_mu_s, hillaire.ms_mu_s, hillaire.ms_r);
    let d = gather_count();
    var up = vec4<f32>(0.0);
    for (var j = 0u; j < d; j++) {
        let g = gather_direction(p.x, p.y, j);
        if (g.dir.z > 0.0) {
            up += g.weight * g.dir.z * gathered[2u * (texel * d + j) * atm.groups + k];
        }
    }
    return up;
}

// Σ_j w_j·Y_c(ω_j)·L_j over the gather directions of texel `texel` (Grid::gather's
// projection), coefficient c, channel group k.
fn project(texel: u32, c: u32, k: u32) -> vec4<f32> {
    let lm = harmonic_degree_order(c);
    let p = altitude_mu_s_of_texel(texel % hillaire.ms_mu_s, texel / hillaire.ms_mu_s, hillaire.ms_mu_s, hillaire.ms_r);
    let d = gather_count();
    var field = vec4<f32>(0.0);
    for (var j = 0u; j < d; j++) {
        let g = gather_direction(p.x, p.y, j);
        field += g.weight * harmonic(lm.x, lm.y, g.dir.z, g.cos_phi) * gathered[2u * (texel * d + j) * atm.groups + k];
    }
    return field;
}

// Texel `texel` of the bottom row's upward irradiance after an order's field of
// `coefficients` coefficients (the layout above).
fn up_irradiance_index(texel: u32, coefficients: u32, k: u32) -> u32 {
    return (hillaire.ms_mu_s * hillaire.ms_r * coefficients + texel) * atm.groups + k;
}

// Coefficient c of texel i, channel group k of the first order's field (multiple_scattering::
// compute after the first gather): Σ_j w_j·Y_c(ω_j)·L′_j into the table and the order's
// buffer; for c = 0 also f_ms = Σ_j w_j·p_u·∫T·σ_s, written out (the host refuses f_ms
// above F_MS_LIMIT; `tail` sums the series with it), and at the bottom row the upward
// irradiance.
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
    let field = project(texel, c, k);
    if (c == 0u) {
        let p = altitude_mu_s_of_texel(texel % hillaire.ms_mu_s, texel / hillaire.ms_mu_s, hillaire.ms_mu_s, hillaire.ms_r);
        let d = gather_count();
        var f_ms = vec4<f32>(0.0);
        for (var j = 0u; j < d; j++) {
            let g = gather_direction(p.x, p.y, j);
            f_ms += g.weight * INV_4PI * gathered[(2u * (texel * d + j) + 1u) * atm.groups + k];
        }
        f_ms_out[texel * atm.groups + k] = f_ms;
        if (texel < hillaire.ms_mu_s) {
            order_field[up_irradiance_index(texel, n, k)] = up_irradiance(texel, k);
        }
    }
    multiple_scattering_out[(texel * n + c) * atm.groups + k] = field;
    order_field[(texel * n + c) * atm.groups + k] = field;
}

// L along gather direction j of texel i, channel group k, for a higher order (the closure
// of the loop over orders in multiple_scattering::compute): the march through the previous
// order's field (binding 20; its phase functions by Funk–Hecke, no single scattering), plus
// the Lambertian ground lit by the previous order's upward irradiance at the bottom row,
// linear in μ_s (`ground_table` sampled at (u, 0.5)), where the ray meets it.
@compute @workgroup_size(64)
fn gather_next(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = invocation_index(gid, nwg);
    let d = gather_count();
    if (i >= hillaire.ms_mu_s * hillaire.ms_r * d) {
        return;
    }
    let k = gid.z;
    let texel = i / d;
    let j = i % d;
    let gr = gather_ray(texel, j);
    let ray = gr.ray;
    let ground = gr.ground;
    let m = march(ray, hillaire.ms_steps, vec2<f32>(0.0), Lighting(lit_none(), lit_all()), true, k);
    var l = m.radiance;
    if (ground) {
        let mu_s_ground = clamp_cosine((ray.r_km * ray.mu_s + ray.length_km * ray.nu) / atm.bottom_radius_km);
        let w = hillaire.ms_mu_s;
        let x = lerp_weights(altitude_mu_s_uv(0.0, mu_s_ground, w, hillaire.ms_r).x, w);
        let n = hillaire.ms_coefficients;
        let e = (1.0 - x.t) * multiple_scattering_table[up_irradiance_index(x.i0, n, k)]
            + x.t * multiple_scattering_table[up_irradiance_index(x.i1, n, k)];
        l += m.transmittance * e * ground_albedo(k) / PI;
    }
    gathered[2u * (texel * d + j) * atm.groups + k] = l;
}

// Coefficient c of texel i, channel group k of a higher order's field (degree ≤
// HIGHER_ORDERS_DEGREE): into the order's buffer and added to the table (`add_field` with
// factors 1); for c = 0 at the bottom row, the upward irradiance for the next order.
@compute @workgroup_size(64)
fn project_next(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = invocation_index(gid, nwg);
    let n = hillaire.order_coefficients;
    if (i >= hillaire.ms_mu_s * hillaire.ms_r * n) {
        return;
    }
    let k = gid.z;
    let texel = i / n;
    let c = i % n;
    let field = project(texel, c, k);
    if (c == 0u && texel < hillaire.ms_mu_s) {
        order_field[up_irradiance_index(texel, n, k)] = up_irradiance(texel, k);
    }
    order_field[(texel * n + c) * atm.groups + k] = field;
    multiple_scattering_out[(texel * hillaire.table_coefficients + c) * atm.groups + k] += field;
}

// Per lane, the two sums of the table-wide means (the last order's, the one before).
var<workgroup> last_sums: array<vec4<f32>, WORKGROUP>;
var<workgroup> before_sums: array<vec4<f32>, WORKGROUP>;

// The orders beyond the last explicit one, channel group k = the workgroup's z, one
// workgroup per group (the end of multiple_scattering::compute). From 4 orders the geometric
// tail of the last two: `degree_zero_means` of both (the last order's field at binding 24,
// the one before at binding 20; the CPU keeps every order's means, the factors read only
// those two), `order_tail_factors`' q = min(mean_N/mean_{N−1}, ORDER_RATIO_CAP) (0 where either is 0
// or the orders do not decrease) and the last field × q/(1 − q) added to the table. Below 4
// orders, Hillaire's series on the last order's degree 0, texel by texel: × f/(1 − f) with
// the first order's f_ms (guarded at F_MS_GUARD).
@compute @workgroup_size(64)
fn tail(@builtin(local_invocation_index) lane: u32, @builtin(workgroup_id) wid: vec3<u32>) {
    let k = wid.z;
    let texels = hillaire.ms_mu_s * hillaire.ms_r;
    let n = hillaire.order_coefficients;
    let g = atm.groups;
    if (hillaire.orders >= 4u) {
        var last = vec4<f32>(0.0);
        var before = vec4<f32>(0.0);
        for (var i = lane; i < texels; i += WORKGROUP) {
            last += order_field[i * n * g + k];
            before += multiple_scattering_table[i * hillaire.ms_coefficients * g + k];
        }
        last_sums[lane] = last;
        before_sums[lane] = before;
        workgroupBarrier();
        for (var half = WORKGROUP / 2u; half > 0u; half /= 2u) {
            if (lane < half) {
                last_sums[lane] += last_sums[lane + half];
                before_sums[lane] += before_sums[lane + half];
            }
            workgroupBarrier();
        }
        let mean_last = last_sums[0] / f32(texels);
        let mean_before = before_sums[0] / f32(texels);
        let valid = (mean_before > vec4<f32>(0.0)) & (mean_last > vec4<f32>(0.0)) & (mean_last < mean_before);
        let q = select(vec4<f32>(0.0), min(mean_last / mean_before, vec4<f32>(ORDER_RATIO_CAP)), valid);
        let factor = q / (1.0 - q);
        for (var e = lane; e < texels * n; e += WORKGROUP) {
            let texel = e / n;
            let c = e % n;
            multiple_scattering_out[(texel * hillaire.table_coefficients + c) * g + k] += factor * order_field[e * g + k];
        }
    } else {
        for (var i = lane; i < texels; i += WORKGROUP) {
            let f = min(f_ms_out[i * g + k], vec4<f32>(F_MS_GUARD));
            multiple_scattering_out[i * hillaire.table_coefficients * g + k] += order_field[i * n * g + k] * f / (1.0 - f);
        }
    }
}

// The terrain as a surface (firmament::scene::terrain::heightfield): the nearest hit of a ray
// (the max-mip walk, then the exact root of the ray against each cell's bilinear patch,
// refined by Newton steps), the smooth shading normal, exact shadow rays, the sky's
// visibility, and where a ray ends on a surface.

// refine: two Newton steps on the exact height minus the patch from the root s of the cell's
// quadratic f.
fn refine(ray: GridRay, cell: CellSpan, s: f32, f: vec3<f32>) -> f32 {
    let span = cell.t1 - cell.t0;
    var t = cell.t0 + s * span;
    if (s <= 0.0) {
        return t;
    }
    let slope = (f.y + 2.0 * f.z * s) / span;
    if (slope >= 0.0) {
        return t;
    }
    let c = corners(terrain.heights, cell.i, cell.j);
    for (var k = 0; k < 2; k++) {
        let g = ray_grid_xy(ray, t);
        let ab = fractions(g, cell.i, cell.j);
        let gap = ray_height(ray, t) - bilinear(c, ab.x, ab.y);
        t = clamp(t - gap / slope, cell.t0, cell.t1);
    }
    return t;
}

// Surface::intersect for the heightfield: the nearest hit's parameter in (t_min, t_max), or
// −1. Rays leaving the surface start a hair above it.
fn intersect(ray: GridRay, t_max: f32) -> f32 {
    let t_min = 1e-3;
    var w = walk_start(ray, terrain.pyramid, NONE, NONE, t_min, t_max);
    loop {
        let cell = walk_next(&w);
        if (!cell.valid) {
            return -1.0;
        }
        let f = gap_in_cell(ray, terrain.heights, cell);
        let s = first_descent(f);
        if (s >= 0.0) {
            let t = refine(ray, cell, s, f);
            if (t > t_min && t < t_max) {
                return t;
            }
            return -1.0;
        }
    }
    return -1.0;
}

// Grid::gradient of the heights: central differences at the vertices, interpolated
// bilinearly (per metre, along x′ and y′ = east and north: the heights' grid is not rotated).
fn height_gradient(g: vec2<f32>) -> vec2<f32> {
    let x = split(g.x, terrain.nx);
    let y = split(g.y, terrain.ny);
    let i = u32(x.x);
    let j = u32(y.x);
    var gx: vec4<f32>;
    var gy: vec4<f32>;
    for (var k = 0u; k < 4u; k++) {
        let vx = i + (k & 1u);
        let vy = j + (k >> 1u);
        let x0 = select(vx - 1u, 0u, vx == 0u);
        let x1 = min(vx + 1u, terrain.nx - 1u);
        let y0 = select(vy - 1u, 0u, vy == 0u);
        let y1 = min(vy + 1u, terrain.ny - 1u);
        gx[k] = (field_at(terrain.heights, x1, vy) - field_at(terrain.heights, x0, vy)) / (f32(x1 - x0) * terrain.spacing_m);
        gy[k] = (field_at(terrain.heights, vx, y1) - field_at(terrain.heights, vx, y0)) / (f32(y1 - y0) * terrain.spacing_m);
    }
    return vec2<f32>(bilinear(gx, x.y, y.y), bilinear(gy, x.y, y.y));
}

// Heightfield::normal_at: the normal of S(u, v) = (R + H(u, v))·n̂(u, v) at local point q,
// n̂ = (u, v, R)/|(u, v, R)|.
fn normal_at(q: vec3<f32>) -> vec3<f32> {
    let r = terrain.radius_m;
    let uv = r * q.xy / (r + q.z);
    let g = cell_coords(uv);
    let grad = height_gradient(g);
    let h = field_bilinear(terrain.heights, g);
    let p = vec3<f32>(uv, r);
    let len = length(p);
    let n = p / len;
    let dn_du = (vec3<f32>(1.0, 0.0, 0.0) - n * n.x) / len;
    let dn_dv = (vec3<f32>(0.0, 1.0, 0.0) - n * n.y) / len;
    let su = grad.x * n + (r + h) * dn_du;
    let sv = grad.y * n + (r + h) * dn_dv;
    return normalize(cross(su, sv));
}

// Heightfield::height_below: the terrain's height (m) under local point q (0 off the grid).
fn height_below(q: vec3<f32>) -> f32 {
    let r = terrain.radius_m;
    if (r + q.z <= 0.0) {
        return 0.0;
    }
    let g = cell_coords(r * q.xy / (r + q.z));
    if (!grid_contains(g)) {
        return 0.0;
    }
    return field_bilinear(terrain.heights, g);
}

// The local up (unit) at local point q.
fn up_at(q: vec3<f32>) -> vec3<f32> {
    return normalize(vec3<f32>(q.xy, terrain.radius_m + q.z));
}

// Heightfield::occludes: an exact shadow ray from q towards `light`.
fn occludes(q: vec3<f32>, light: vec3<f32>) -> bool {
    var ray: GridRay;
    ray.origin = q;
    ray.dir = light;
    return intersect(ray, 3.4e38) >= 0.0;
}

// Heightfield::end_in_shadow: when the ray ends at t_end on a surface (within 0.5 m), whether
// `light` is hidden there (1) or not (0), by a shadow ray from 5 cm above it; −1 when the
// ray does not end on a surface.
fn end_in_shadow(ray: GridRay, light: vec3<f32>, t_end: f32) -> i32 {
    if (t_end >= 3.0e38) {
        return -1;
    }
    let q = ray.origin + t_end * ray.dir;
    if (ray_height(ray, t_end) > height_below(q) + 0.5) {
        return -1;
    }
    return select(0, 1, occludes(q + 0.05 * up_at(q), light));
}

// Surface::sky_visibility: the terrain's ambient occlusion at local point q (1 off its grid
// or without occlusion).
fn sky_visibility(q: vec3<f32>) -> f32 {
    if ((terrain.flags & TERRAIN_OCCLUSION) == 0u) {
        return 1.0;
    }
    let cell = visibility_cell(q);
    if (cell.x < 0.0) {
        return 1.0;
    }
    let k = terrain.visibility + u32(cell.y) * terrain.visibility_nx + u32(cell.x);
    let v = vec4<f32>(terrain_data[k], terrain_data[k + 1u], terrain_data[k + terrain.visibility_nx], terrain_data[k + terrain.visibility_nx + 1u]);
    return bilinear(v, cell.z, cell.w);
}

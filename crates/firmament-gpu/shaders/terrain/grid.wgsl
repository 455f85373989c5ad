// A field of values on a regular grid over the planet (firmament::scene::terrain::grid): the
// gnomonic grid (every grid line is a plane through the planet's centre, so a ray's walk
// through the cells is exact on the curved planet), its max-mip pyramid, and the ray against
// a cell's bilinear patch. The walk through the pyramid is walk.wgsl.
//
// f32 geometry in metres relative to the observer's foot F = (0, 0, R): a point p = F + q
// with q small (tens of km), so the planet's radius never cancels: the height above the
// sphere is (q_x² + q_y² + q_z(2R + q_z))/(|p| + R), the plane coordinates R·q_xy/(R + q_z).
//
// The fields live in `terrain_data` (terrain.wgsl): a field of the grid's size at an offset,
// and a pyramid at an offset with the levels' sizes and offsets of `terrain.levels` (the
// same for every field on the grid).

// ---------------------------------------------------------------------------------------
// The grid.

// Grid::cell_coords: plane (u, v) → grid coordinates (x′, y′) in cells.
fn cell_coords(uv: vec2<f32>) -> vec2<f32> {
    let c = terrain.axis.x;
    let s = terrain.axis.y;
    return vec2<f32>(
        ((c * uv.x + s * uv.y) - terrain.origin_u) / terrain.spacing_m,
        ((-s * uv.x + c * uv.y) - terrain.origin_v) / terrain.spacing_m,
    );
}

// Grid::at on the field at `base`.
fn field_at(base: u32, i: u32, j: u32) -> f32 {
    return terrain_data[base + j * terrain.nx + i];
}

// Grid::corners: [v00, v10, v01, v11] of cell (i, j).
fn corners(base: u32, i: u32, j: u32) -> vec4<f32> {
    let k = base + j * terrain.nx + i;
    return vec4<f32>(terrain_data[k], terrain_data[k + 1u], terrain_data[k + terrain.nx], terrain_data[k + terrain.nx + 1u]);
}

// grid::bilinear.
fn bilinear(c: vec4<f32>, a: f32, b: f32) -> f32 {
    let low = c.x + (c.y - c.x) * a;
    let high = c.z + (c.w - c.z) * a;
    return low + (high - low) * b;
}

// The cell index and fraction of a grid coordinate on an axis of n vertices (clamped).
fn split(g: f32, n: u32) -> vec2<f32> {
    let gc = clamp(g, 0.0, f32(n - 1u));
    let i = min(floor(gc), f32(n - 2u));
    return vec2<f32>(i, gc - i);
}

// Grid::bilinear at grid coordinates on the field at `base` (clamped to the grid).
fn field_bilinear(base: u32, g: vec2<f32>) -> f32 {
    let x = split(g.x, terrain.nx);
    let y = split(g.y, terrain.ny);
    return bilinear(corners(base, u32(x.x), u32(y.x)), x.y, y.y);
}

// Grid::contains.
fn grid_contains(g: vec2<f32>) -> bool {
    return g.x >= 0.0 && g.y >= 0.0 && g.x <= f32(terrain.nx - 1u) && g.y <= f32(terrain.ny - 1u);
}

// grid::fractions: the fractions within cell (i, j), clamped to [0, 1].
fn fractions(g: vec2<f32>, i: u32, j: u32) -> vec2<f32> {
    return clamp(g - vec2<f32>(f32(i), f32(j)), vec2<f32>(0.0), vec2<f32>(1.0));
}

// grid::along_segment: the bilinear patch along a straight segment from fractions a0b0 to
// a1b1, as q0 + q1·s + q2·s².
fn along_segment(c: vec4<f32>, ab0: vec2<f32>, ab1: vec2<f32>) -> vec3<f32> {
    let k1 = c.y - c.x;
    let k2 = c.z - c.x;
    let k3 = c.w - c.y - c.z + c.x;
    let d = ab1 - ab0;
    return vec3<f32>(
        c.x + k1 * ab0.x + k2 * ab0.y + k3 * ab0.x * ab0.y,
        k1 * d.x + k2 * d.y + k3 * (ab0.x * d.y + ab0.y * d.x),
        k3 * d.x * d.y,
    );
}

// MaxPyramid::node: the value of node (i, j) at `level` of the pyramid at `base`, or
// −∞ (never above a ray) off the pyramid.
fn pyramid_node(base: u32, level: u32, i: i32, j: i32) -> f32 {
    let l = terrain.levels[level];
    if (i < 0 || j < 0 || u32(i) >= l.x || u32(j) >= l.y) {
        return -3.4e38;
    }
    return terrain_data[base + l.z + u32(j) * l.x + u32(i)];
}

fn pyramid_max(base: u32) -> f32 {
    return pyramid_node(base, terrain.level_count - 1u, 0, 0);
}

// ---------------------------------------------------------------------------------------
// The ray.

// GridRay: origin relative to the observer's foot (m), unit direction.
struct GridRay {
    origin: vec3<f32>,
    dir: vec3<f32>,
}

// GridRay::height: metres above the sphere at t.
fn ray_height(ray: GridRay, t: f32) -> f32 {
    let q = ray.origin + t * ray.dir;
    let r = terrain.radius_m;
    let p2 = q.x * q.x + q.y * q.y + q.z * (2.0 * r + q.z);
    let len = sqrt(q.x * q.x + q.y * q.y + (r + q.z) * (r + q.z));
    return p2 / (len + r);
}

// The parameter of the ray's closest approach to the planet's centre.
fn ray_closest(ray: GridRay) -> f32 {
    let r = terrain.radius_m;
    return -(ray.origin.x * ray.dir.x + ray.origin.y * ray.dir.y + (r + ray.origin.z) * ray.dir.z);
}

// GridRay::above: the ray higher than `height` (m) everywhere over [t0, t1].
fn ray_above(ray: GridRay, t0: f32, t1: f32, height: f32) -> bool {
    return ray_height(ray, clamp(ray_closest(ray), t0, t1)) > height;
}

// GridRay::below_at_ends: both ends (so the whole span) lower than `height` (m).
fn ray_below_at_ends(ray: GridRay, t0: f32, t1: f32, height: f32) -> bool {
    return max(ray_height(ray, t0), ray_height(ray, t1)) < height;
}

// GridRay::plane: plane coordinates (u, v) at t.
fn ray_plane(ray: GridRay, t: f32) -> vec2<f32> {
    let q = ray.origin + t * ray.dir;
    return terrain.radius_m * q.xy / (terrain.radius_m + q.z);
}

// GridRay::grid_xy.
fn ray_grid_xy(ray: GridRay, t: f32) -> vec2<f32> {
    return cell_coords(ray_plane(ray, t));
}

// GridRay::line: the side of grid line g (cells) along x′ (axis 0) or y′ (axis 1) as
// a + b·t, positive beyond it: R·(c_u·p_x + c_v·p_y) − offset·p_z written as
// R·(c_u·q_x + c_v·q_y − offset) − offset·q_z.
fn ray_line(ray: GridRay, g: f32, axis: u32) -> vec2<f32> {
    let c = terrain.axis.x;
    let s = terrain.axis.y;
    var cu = c;
    var cv = s;
    var offset = terrain.origin_u + g * terrain.spacing_m;
    if (axis == 1u) {
        cu = -s;
        cv = c;
        offset = terrain.origin_v + g * terrain.spacing_m;
    }
    let r = terrain.radius_m;
    let a = r * (cu * ray.origin.x + cv * ray.origin.y - offset) - offset * ray.origin.z;
    let b = r * (cu * ray.dir.x + cv * ray.dir.y) - offset * ray.dir.z;
    return vec2<f32>(a, b);
}

// GridRay::clip: the part of [t0, t1] over the grid's rectangle, on the near hemisphere and
// below `max_height` (m); x > y when empty.
fn ray_clip(ray: GridRay, t0: f32, t1: f32, max_height: f32) -> vec2<f32> {
    var lo = t0;
    var hi = t1;
    // a + b·t ≥ 0 for each side.
    var sides: array<vec2<f32>, 5>;
    let r = terrain.radius_m;
    sides[0] = vec2<f32>(r + ray.origin.z, ray.dir.z);
    sides[1] = ray_line(ray, 0.0, 0u);
    sides[2] = -ray_line(ray, f32(terrain.nx - 1u), 0u);
    sides[3] = ray_line(ray, 0.0, 1u);
    sides[4] = -ray_line(ray, f32(terrain.ny - 1u), 1u);
    for (var k = 0u; k < 5u; k++) {
        let ab = sides[k];
        if (ab.y > 0.0) {
            lo = max(lo, -ab.x / ab.y);
        } else if (ab.y < 0.0) {
            hi = min(hi, -ab.x / ab.y);
        } else if (ab.x < 0.0) {
            hi = -3.4e38;
        }
    }
    // Below the shell |p| = R + max_height: |o + t d|² = (R + h)² with
    // |o|² − (R + h)² = |q|² + 2R q_z − 2R h − h² (no cancellation).
    let b = -ray_closest(ray);
    let q = ray.origin;
    let c = q.x * q.x + q.y * q.y + q.z * (2.0 * r + q.z) - max_height * (2.0 * r + max_height);
    let disc = b * b - c;
    if (disc <= 0.0) {
        return vec2<f32>(1.0, 0.0);
    }
    let root = sqrt(disc);
    // The nearer root without cancellation: c/(−b + root) when b < 0.
    var near = -b - root;
    if (b < 0.0) {
        near = c / (-b + root);
    }
    lo = max(lo, near);
    hi = min(hi, -b + root);
    if (hi > lo) {
        return vec2<f32>(lo, hi);
    }
    return vec2<f32>(1.0, 0.0);
}

// CellSpan: a cell the walk reaches (or, with `below`, a whole node the ray crosses below its
// lowest value), with the ray's parameters where it enters and leaves.
struct CellSpan {
    valid: bool,
    below: bool,
    i: u32,
    j: u32,
    t0: f32,
    t1: f32,
}

// GridRay::gap_in_cell: the ray's height minus the field's patch across the cell, as
// q0 + q1·s + q2·s² from entry (s = 0) to exit (s = 1).
fn gap_in_cell(ray: GridRay, base: u32, cell: CellSpan) -> vec3<f32> {
    let g0 = ray_grid_xy(ray, cell.t0);
    let g1 = ray_grid_xy(ray, cell.t1);
    let h0 = ray_height(ray, cell.t0);
    let h1 = ray_height(ray, cell.t1);
    let q = along_segment(corners(base, cell.i, cell.j), fractions(g0, cell.i, cell.j), fractions(g1, cell.i, cell.j));
    return vec3<f32>(h0 - q.x, (h1 - h0) - q.y, -q.z);
}

// grid::roots: the real roots of q0 + q1·s + q2·s², ascending, in a vec2 with a count.
struct Roots {
    count: u32,
    r: vec2<f32>,
}

fn roots(q: vec3<f32>) -> Roots {
    var out: Roots;
    let c = q.x;
    let b = q.y;
    let a = q.z;
    let scale = max(abs(a), max(abs(b), abs(c)));
    if (abs(a) <= 1e-6 * scale) {
        if (b != 0.0) {
            out.count = 1u;
            out.r = vec2<f32>(-c / b, 0.0);
        }
        return out;
    }
    let disc = b * b - 4.0 * a * c;
    if (disc < 0.0) {
        return out;
    }
    let sq = sqrt(disc);
    var sign_b = 1.0;
    if (b < 0.0) {
        sign_b = -1.0;
    }
    let k = -0.5 * (b + sign_b * sq);
    var r1 = -0.5 * b / a;
    var r2 = r1;
    if (k != 0.0) {
        r1 = k / a;
        r2 = c / k;
    }
    out.count = 2u;
    out.r = vec2<f32>(min(r1, r2), max(r1, r2));
    return out;
}

// grid::first_descent: the smallest root in [0, 1] where the function goes from positive to
// non-positive (0 when it starts non-positive), or −1.
fn first_descent(q: vec3<f32>) -> f32 {
    if (q.x <= 0.0) {
        return 0.0;
    }
    let rs = roots(q);
    for (var k = 0u; k < rs.count; k++) {
        let s = rs.r[k];
        if (s >= 0.0 && s <= 1.0 && q.y + 2.0 * q.z * s <= 0.0) {
            return s;
        }
    }
    return -1.0;
}

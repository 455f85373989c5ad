// The ray's walk through a grid's max-mip pyramid (firmament::scene::terrain::walk; Tevs,
// Ihrke & Seidel 2008), stackless: `walk_start`, then `walk_next` until a span is not valid.
// Uses the grid, its pyramid and the ray's geometry of grid.wgsl.

struct Walk {
    ray: GridRay,
    // The pyramid walked, and those that skip (nonzero) or take whole (floors) nodes, by
    // offset (NONE: not used).
    pyramid: u32,
    nonzero: u32,
    floors: u32,
    level: i32,
    i: i32,
    j: i32,
    t: f32,
    exits: vec2<f32>,
    end: f32,
    step: vec2<i32>,
    done: bool,
}

// Walk::TOLERANCE in f32: a crossing this close (m) behind the walk's parameter is at it.
fn walk_tolerance(t: f32) -> f32 {
    return 0.05 + 1e-4 * abs(t);
}

// Walk::crossing_ahead.
fn crossing_ahead(w: ptr<function, Walk>, g: i32, axis: u32) -> f32 {
    let ab = ray_line((*w).ray, f32(g), axis);
    var t = 3.4e38;
    if (ab.y != 0.0) {
        t = -ab.x / ab.y;
    }
    if (t < (*w).t - walk_tolerance((*w).t)) {
        return 3.4e38;
    }
    return max(t, (*w).t);
}

// Walk::face.
fn walk_face(w: ptr<function, Walk>, idx: i32, axis: u32) -> f32 {
    let size = 1 << u32((*w).level);
    let step = (*w).step[axis];
    if (step == 0) {
        return 3.4e38;
    }
    if (step > 0) {
        return crossing_ahead(w, (idx + 1) * size, axis);
    }
    return crossing_ahead(w, idx * size, axis);
}

fn sign_of(d: f32) -> i32 {
    if (d > 1e-6) {
        return 1;
    }
    if (d < -1e-6) {
        return -1;
    }
    return 0;
}

// Walk::new.
fn walk_start(ray: GridRay, pyramid: u32, nonzero: u32, floors: u32, t0: f32, t1: f32) -> Walk {
    var w: Walk;
    w.ray = ray;
    w.pyramid = pyramid;
    w.nonzero = nonzero;
    w.floors = floors;
    let clipped = ray_clip(ray, t0, t1, pyramid_max(pyramid));
    w.done = !(clipped.y > clipped.x);
    w.t = clipped.x;
    w.end = clipped.y;
    let g0 = ray_grid_xy(ray, clipped.x);
    let g1 = ray_grid_xy(ray, clipped.y);
    w.step = vec2<i32>(sign_of(g1.x - g0.x), sign_of(g1.y - g0.y));
    // Start in the cell holding the clipped start (on a line, the one ahead).
    w.level = 0;
    w.i = walk_leaf(g0.x, w.step.x, terrain.nx - 1u);
    w.j = walk_leaf(g0.y, w.step.y, terrain.ny - 1u);
    w.exits = vec2<f32>(walk_face(&w, w.i, 0u), walk_face(&w, w.j, 1u));
    return w;
}

// The cell index of grid coordinate g on an axis of `cells` cells, the one ahead on a line.
fn walk_leaf(g: f32, step: i32, cells: u32) -> i32 {
    var i = floor(g);
    if (step < 0 && g == i) {
        i -= 1.0;
    }
    return i32(clamp(i, 0.0, f32(cells - 1u)));
}

// Walk::half: whether the child holding the point at the walk's parameter is the upper one
// along `axis` (beyond midline `mid`), and its exit on that axis, in a vec2 (x: 1 upper).
fn walk_half(w: ptr<function, Walk>, mid: i32, axis: u32) -> vec2<f32> {
    let step = (*w).step[axis];
    let ab = ray_line((*w).ray, f32(mid), axis);
    let t = (*w).t;
    var upper = ab.x + ab.y * t >= 0.0;
    if (step != 0 && ab.y != 0.0 && abs(t + ab.x / ab.y) <= walk_tolerance(t)) {
        upper = step > 0;
    }
    let near = (step > 0 && !upper) || (step < 0 && upper);
    var exit = (*w).exits[axis];
    if (near) {
        exit = crossing_ahead(w, mid, axis);
    }
    return vec2<f32>(select(0.0, 1.0, upper), exit);
}

// Walk::advance: leave the node through the nearer face ahead, climb to the highest new
// ancestor of the neighbour; false when the walk is over.
fn walk_advance(w: ptr<function, Walk>) -> bool {
    let t_exit = min((*w).exits.x, (*w).exits.y);
    if (t_exit >= (*w).end) {
        return false;
    }
    (*w).t = t_exit;
    let i0 = (*w).i;
    let j0 = (*w).j;
    var i1 = i0;
    var j1 = j0;
    if ((*w).exits.x <= t_exit) {
        i1 += (*w).step.x;
    }
    if ((*w).exits.y <= t_exit) {
        j1 += (*w).step.y;
    }
    let top = i32(terrain.level_count) - 1;
    var k = 1;
    while ((*w).level + k <= top && ((i0 >> u32(k)) != (i1 >> u32(k)) || (j0 >> u32(k)) != (j1 >> u32(k)))) {
        k += 1;
    }
    (*w).level += k - 1;
    (*w).i = i1 >> u32(k - 1);
    (*w).j = j1 >> u32(k - 1);
    // A neighbour at the same level keeps the exit of the axis not stepped along.
    if (k > 1 || i1 != i0) {
        (*w).exits.x = walk_face(w, (*w).i, 0u);
    }
    if (k > 1 || j1 != j0) {
        (*w).exits.y = walk_face(w, (*w).j, 1u);
    }
    return true;
}

// Walk::next: the next cell (or whole node below its floor); not valid at the end.
fn walk_next(w: ptr<function, Walk>) -> CellSpan {
    var span: CellSpan;
    span.valid = false;
    // A bound on the nodes one ray may test (a walk visits at most a few per cell crossed).
    for (var guard = 0u; guard < 1000000u; guard++) {
        if ((*w).done) {
            return span;
        }
        let level = u32((*w).level);
        let i = (*w).i;
        let j = (*w).j;
        let l = terrain.levels[level];
        if (i < 0 || j < 0 || u32(i) >= l.x || u32(j) >= l.y) {
            (*w).done = true;
            return span;
        }
        let max_value = pyramid_node((*w).pyramid, level, i, j);
        let t0 = (*w).t;
        let t1 = min(min((*w).exits.x, (*w).exits.y), (*w).end);
        var skip = t1 <= t0 || ray_above((*w).ray, t0, t1, max_value);
        if (!skip && (*w).nonzero != NONE) {
            skip = pyramid_node((*w).nonzero, level, i, j) <= 0.0;
        }
        if (!skip) {
            var below = false;
            if ((*w).floors != NONE) {
                below = ray_below_at_ends((*w).ray, t0, t1, -pyramid_node((*w).floors, level, i, j));
            }
            if (below || level == 0u) {
                span.valid = true;
                span.below = below;
                span.i = u32(i);
                span.j = u32(j);
                span.t0 = t0;
                span.t1 = t1;
            } else {
                let half = 1 << (level - 1u);
                let hx = walk_half(w, (2 * i + 1) * half, 0u);
                let hy = walk_half(w, (2 * j + 1) * half, 1u);
                (*w).level -= 1;
                (*w).i = 2 * i + i32(hx.x);
                (*w).j = 2 * j + i32(hy.x);
                (*w).exits = vec2<f32>(hx.y, hy.y);
                continue;
            }
        }
        if (!walk_advance(w)) {
            (*w).done = true;
        }
        if (span.valid) {
            return span;
        }
    }
    (*w).done = true;
    return span;
}

// The terrain's shadow in the air (firmament::scene::terrain::shadow): a light's shadow
// heights S on the terrain's grid (computed on the host by the sweep along the light's
// azimuth), walked along a view ray: the ray is lit where it is above S interpolated in
// each cell (a quadratic per cell), so the lit intervals come out exactly per cell, as on
// the CPU. ShadowField::shadowed_intervals and render's lit_intervals in one: `lit_start`,
// then `lit_next` yields the lit intervals (m from the observer) in order, the shadow at the
// ray's end settled by an exact shadow ray as the CPU does. The walk through the field
// (`lit_walk`) is a variable of its own beside the LitWalk (WGSL passes pointers to whole
// variables only).

// Merge tolerance (m) between a shadowed interval and the next (push_merged's, in f32).
fn merge_tolerance(t: f32) -> f32 {
    return 1e-3 + 1e-6 * abs(t);
}

struct LitWalk {
    ray: GridRay,
    light: vec3<f32>,
    light_index: u32,
    // The shadow field's S offset, and the ray's end (m; ≥ 3e38 for a sky ray).
    field: u32,
    end: f32,
    // The start of the current lit run (the end of the last shadow), where the last shadow
    // began, whether any shadow was seen.
    lit_from: f32,
    shadow_from: f32,
    shadowed: bool,
    // The last span walked, and whether it was a whole node in shadow.
    piece: vec2<f32>,
    whole: bool,
    // Lit intervals ready to yield (at most two per cell), and the state: 0 walking, 1 the
    // walk is over, 2 done.
    ready: array<vec2<f32>, 3>,
    ready_count: u32,
    ready_next: u32,
    state: u32,
}

// The walk of `ray` up to `end` (m) through the shadow field of light `light_index`:
// ShadowField's pyramid of S, skipping the nodes lit to the ground (the raise's pyramid),
// taking whole those the ray crosses below their lowest S.
fn lit_walk(ray: GridRay, light_index: u32, end: f32) -> Walk {
    let f = terrain.shadow[light_index];
    return walk_start(ray, f.y, f.z, f.w, 0.0, end);
}

// The lit intervals of `ray` up to `end` (m) for light `light_index` (its direction `light`).
fn lit_start(ray: GridRay, light_index: u32, light: vec3<f32>, end: f32) -> LitWalk {
    var lw: LitWalk;
    let f = terrain.shadow[light_index];
    lw.ray = ray;
    lw.light = light;
    lw.light_index = light_index;
    lw.field = f.x;
    lw.end = end;
    lw.lit_from = 0.0;
    lw.shadowed = false;
    lw.state = 0u;
    return lw;
}

// push_merged for the streaming walk: a shadowed interval [a, b] after those seen; the lit
// run before it, when it does not touch the last shadow, is ready.
fn lit_shadow(lw: ptr<function, LitWalk>, a: f32, b: f32) {
    if ((*lw).shadowed && a <= (*lw).lit_from + merge_tolerance((*lw).lit_from)) {
        (*lw).lit_from = max((*lw).lit_from, b);
        return;
    }
    if (a > (*lw).lit_from) {
        (*lw).ready[(*lw).ready_count] = vec2<f32>((*lw).lit_from, a);
        (*lw).ready_count += 1u;
    }
    (*lw).shadow_from = a;
    (*lw).lit_from = max((*lw).lit_from, b);
    (*lw).shadowed = true;
}

// ShadowField::end_in_shadow: at a surface the ray ends on, the field's verdict where the
// signed clearance at the four corners of the end's cell agrees by the margin, an exact
// shadow ray (heightfield.wgsl) near the shadow's edge and off the grid; −1 when the ray
// does not end on a surface.
fn field_end_in_shadow(lw: ptr<function, LitWalk>, light_index: u32) -> i32 {
    let end = (*lw).end;
    if (end >= 3.0e38) {
        return -1;
    }
    let ray = (*lw).ray;
    let g = ray_grid_xy(ray, end);
    if (grid_contains(g)) {
        let i = min(u32(floor(g.x)), terrain.nx - 2u);
        let j = min(u32(floor(g.y)), terrain.ny - 2u);
        let hc = corners(terrain.heights, i, j);
        let ab = fractions(g, i, j);
        if (ray_height(ray, end) <= bilinear(hc, ab.x, ab.y) + 0.5) {
            let margin = terrain.zones.w * terrain.spacing_m;
            let c = corners(terrain.per_light[light_index].x, i, j);
            if (all(c < vec4<f32>(-margin))) {
                return 0;
            }
            if (all(c > vec4<f32>(margin))) {
                return 1;
            }
        }
    }
    return end_in_shadow(ray, (*lw).light, end);
}

// ShadowField::shadowed_intervals's ending: the shadow at a surface the ray ends on comes
// from an exact shadow ray (cut where the field's interpolated edge reaches a lit surface,
// added where the exact ray hides an end the field lit); then the last lit run.
fn lit_finish(lw: ptr<function, LitWalk>) {
    let end = (*lw).end;
    let near_end = end - merge_tolerance(end);
    let touches = (*lw).shadowed && (*lw).lit_from >= near_end;
    let exact = field_end_in_shadow(lw, (*lw).light_index);
    if (exact == 0 && touches) {
        var cut = (*lw).piece.x;
        if ((*lw).whole) {
            cut = end - terrain.spacing_m;
        }
        // The last shadow ends at the cut (or goes): light from there to the end.
        let from_m = max(min((*lw).lit_from, cut), (*lw).shadow_from);
        (*lw).ready[(*lw).ready_count] = vec2<f32>(from_m, end);
        (*lw).ready_count += 1u;
        return;
    }
    if (exact == 1 && !touches) {
        var from_m = end - merge_tolerance(end);
        if ((*lw).piece.y >= near_end) {
            from_m = (*lw).piece.x;
        }
        if (from_m > (*lw).lit_from) {
            (*lw).ready[(*lw).ready_count] = vec2<f32>((*lw).lit_from, from_m);
            (*lw).ready_count += 1u;
        }
        return;
    }
    if (!touches) {
        (*lw).ready[(*lw).ready_count] = vec2<f32>((*lw).lit_from, end);
        (*lw).ready_count += 1u;
    }
}

// The next lit interval [x, y] (m from the observer); z is 1 when valid, 0 at the end.
fn lit_next(lw: ptr<function, LitWalk>, walk: ptr<function, Walk>) -> vec3<f32> {
    loop {
        if ((*lw).ready_next < (*lw).ready_count) {
            let r = (*lw).ready[(*lw).ready_next];
            (*lw).ready_next += 1u;
            return vec3<f32>(r, 1.0);
        }
        (*lw).ready_count = 0u;
        (*lw).ready_next = 0u;
        if ((*lw).state == 2u) {
            return vec3<f32>(0.0);
        }
        if ((*lw).state == 1u) {
            lit_finish(lw);
            (*lw).state = 2u;
            continue;
        }
        let cell = walk_next(walk);
        if (!cell.valid) {
            (*lw).state = 1u;
            continue;
        }
        (*lw).piece = vec2<f32>(cell.t0, cell.t1);
        (*lw).whole = cell.below;
        if (cell.below) {
            lit_shadow(lw, cell.t0, cell.t1);
            continue;
        }
        // g(s) = ray height − S: shadowed where negative.
        let g = gap_in_cell((*lw).ray, (*lw).field, cell);
        let rs = roots(g);
        var cuts = array<f32, 4>(0.0, 1.0, 1.0, 1.0);
        var n = 1u;
        for (var k = 0u; k < rs.count; k++) {
            let s = rs.r[k];
            if (s > 0.0 && s < 1.0) {
                cuts[n] = s;
                n += 1u;
            }
        }
        cuts[n] = 1.0;
        let span = cell.t1 - cell.t0;
        for (var k = 0u; k < n; k++) {
            let s0 = cuts[k];
            let s1 = cuts[k + 1u];
            let m = 0.5 * (s0 + s1);
            if (g.x + m * (g.y + m * g.z) < 0.0) {
                lit_shadow(lw, cell.t0 + s0 * span, cell.t0 + s1 * span);
            }
        }
    }
    return vec3<f32>(0.0);
}

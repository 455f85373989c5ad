// The terrain's horizons (firmament::scene::terrain::occlusion::Occlusion): the horizon's
// elevation in HORIZON_AZIMUTHS azimuths at every vertex of the visibility grid (its
// origin and axis the heights', its spacing `visibility_spacing_m`), one vertex's together.

struct Horizons {
    // False off the grid (or without horizons).
    valid: bool,
    // Elevation (rad) towards azimuth k: (cos 2πk/K, sin 2πk/K) in (east, north).
    beta: array<f32, HORIZON_AZIMUTHS>,
}

// The cell (xy) and fractions (zw) of local point q on the visibility grid; x < 0 off it.
fn visibility_cell(q: vec3<f32>) -> vec4<f32> {
    let r = terrain.radius_m;
    let uv = r * q.xy / (r + q.z);
    let c = terrain.axis.x;
    let s = terrain.axis.y;
    let g = vec2<f32>((c * uv.x + s * uv.y) - terrain.origin_u, (-s * uv.x + c * uv.y) - terrain.origin_v) / terrain.visibility_spacing_m;
    let n = vec2<f32>(f32(terrain.visibility_nx - 1u), f32(terrain.visibility_ny - 1u));
    if (g.x < 0.0 || g.y < 0.0 || g.x > n.x || g.y > n.y) {
        return vec4<f32>(-1.0);
    }
    let i = min(floor(g), n - 1.0);
    return vec4<f32>(i, g - i);
}

// Occlusion::horizons_at: the horizons at local point q, interpolated bilinearly.
fn horizons_at(q: vec3<f32>) -> Horizons {
    var h: Horizons;
    if (terrain.horizons == NONE) {
        return h;
    }
    let cell = visibility_cell(q);
    if (cell.x < 0.0) {
        return h;
    }
    h.valid = true;
    let f = cell.zw;
    let v00 = terrain.horizons + (u32(cell.y) * terrain.visibility_nx + u32(cell.x)) * HORIZON_AZIMUTHS;
    let v10 = v00 + HORIZON_AZIMUTHS;
    let v01 = v00 + terrain.visibility_nx * HORIZON_AZIMUTHS;
    let v11 = v01 + HORIZON_AZIMUTHS;
    for (var k = 0u; k < HORIZON_AZIMUTHS; k++) {
        let low = terrain_data[v00 + k] + (terrain_data[v10 + k] - terrain_data[v00 + k]) * f.x;
        let high = terrain_data[v01 + k] + (terrain_data[v11 + k] - terrain_data[v01 + k]) * f.x;
        h.beta[k] = low + (high - low) * f.y;
    }
    return h;
}

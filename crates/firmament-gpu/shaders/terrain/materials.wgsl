// What the terrain reflects (firmament::scene::terrain::materials): snow, rock, grass and
// forest spectra (the uniform's `albedo` rows, from data/terrain_albedo.csv at the model's
// wavelengths) mixed by height and slope with patchy edges, or one albedo everywhere.

// math::hash::hash32 (the twin of math/hash.rs): Wellons's lowbias32 chained over the salt
// and the coordinates.
fn lowbias32(v_in: u32) -> u32 {
    var v = v_in;
    v ^= v >> 16u;
    v *= 0x7feb352du;
    v ^= v >> 15u;
    v *= 0x846ca68bu;
    return v ^ (v >> 16u);
}

fn hash32(salt: u32, x: i32, y: i32) -> u32 {
    return lowbias32(bitcast<u32>(x) ^ lowbias32(bitcast<u32>(y) ^ lowbias32(salt)));
}

fn lattice_value(salt: u32, x: i32, y: i32) -> f32 {
    return f32(hash32(salt, x, y) >> 8u) / 8388608.0 - 1.0;
}

// materials::patchiness: smooth value noise in [−1, 1) over cells of `cell_m` (planet-centred x, y
// are the local ones: the observer's foot is on the z axis).
fn patchiness(p: vec2<f32>, cell_m: f32, salt: u32) -> f32 {
    let x = p / cell_m;
    let xi = floor(x);
    let f = x - xi;
    let i = vec2<i32>(xi);
    let s = f * f * (3.0 - 2.0 * f);
    let v00 = lattice_value(salt, i.x, i.y);
    let v10 = lattice_value(salt, i.x + 1, i.y);
    let v01 = lattice_value(salt, i.x, i.y + 1);
    let v11 = lattice_value(salt, i.x + 1, i.y + 1);
    let low = v00 + (v10 - v00) * s.x;
    let high = v01 + (v11 - v01) * s.x;
    return low + (high - low) * s.y;
}

// The four materials' weights at a point (Materials::albedo): snow, rock, forest (grass is
// what is left), from the height (m above the sphere), the slope (degrees) and the patches.
struct MaterialWeights {
    snow: f32,
    rock: f32,
    forest: f32,
}

fn material_weights(p: vec2<f32>, height_m: f32, slope_deg: f32) -> MaterialWeights {
    let snow_line = terrain.zones.x;
    let tree_line = terrain.zones.y;
    let n = 0.65 * patchiness(p, 150.0, 1u) + 0.35 * patchiness(p, 40.0, 2u);
    var w: MaterialWeights;
    w.snow = smoothstep_safe(-150.0, 150.0, height_m - snow_line + 260.0 * n)
        * (1.0 - smoothstep_safe(38.0, 52.0, slope_deg - 8.0 * n));
    w.rock = max(smoothstep_safe(28.0, 42.0, slope_deg + 10.0 * n),
        smoothstep_safe(0.0, 250.0, height_m - tree_line - 150.0 + 120.0 * n));
    w.forest = (1.0 - smoothstep_safe(-200.0, 50.0, height_m - tree_line + 150.0 * n))
        * smoothstep_safe(-0.15, 0.2, n) * (1.0 - smoothstep_safe(30.0, 40.0, slope_deg));
    return w;
}

// Materials::albedo of channel group k (rows: snow, rock, grass, forest per group).
fn terrain_albedo(w: MaterialWeights, k: u32) -> vec4<f32> {
    let snow = terrain.albedo[4u * k];
    if ((terrain.flags & TERRAIN_UNIFORM_ALBEDO) != 0u) {
        return snow;
    }
    let rock = terrain.albedo[4u * k + 1u];
    let grass = terrain.albedo[4u * k + 2u];
    let forest = terrain.albedo[4u * k + 3u];
    let ground = grass + w.forest * (forest - grass);
    let bare = ground + w.rock * (rock - ground);
    return bare + w.snow * (snow - bare);
}

// The clouds' shadow below them (firmament::render::cloud_shadow::CloudShadow, computed on
// the CPU and uploaded): each light's map of the layers' optical depth towards it over
// their lowest base sphere, SHADOW_TEXELS² texels over ±map_half_extent (40–80 km) of planar
// coordinates around the observer's place, in cloud_data from clouds.shadow_at[light]; and
// the stretches of a view ray the map puts in shadow, for the air's light shafts.

// The most shadowed stretches a ray keeps (more merge into the last).
const MAX_SHADOWED: u32 = 16u;

struct ShadowList {
    n: u32,
    s: array<vec2<f32>, MAX_SHADOWED>,
}

// cloud_shadow::map_half_extent_m: the mapped square's half side (m) for a light in `dir`
// (local, z up) over the clouds' base: MIN_SHADOW_HALF_EXTENT_M + h_b / tan(elevation), at
// most SHADOW_HALF_EXTENT_M; h_b above the tables' ground (which may be lifted to a
// terrain's floor), as the CPU's map takes it.
fn map_half_extent(dir: vec3<f32>) -> f32 {
    if (dir.z <= 0.0) {
        return SHADOW_HALF_EXTENT_M;
    }
    let h_b = clouds.planet_radius_m + clouds.shadow_base_m - 1000.0 * atm.bottom_radius_km;
    let s = h_b * length(dir.xy) / dir.z;
    return min(MIN_SHADOW_HALF_EXTENT_M + s, SHADOW_HALF_EXTENT_M);
}

// CloudShadow::entry_texel: where the ray from local `x` along `dir` enters the base sphere,
// in texels of a map of `size` per side (fractional, centred; z < 0: x lies at or above the
// base, or the ray does not reach it).
fn map_entry(x: vec3<f32>, dir: vec3<f32>, size: u32) -> vec3<f32> {
    return map_entry_along(x, dir, dir, size);
}

// CloudShadow::entry_texel_along: as map_entry for the ray along `ray_dir` (a direction in
// the disk of the light in `dir`, whose map it is).
fn map_entry_along(x: vec3<f32>, ray_dir: vec3<f32>, dir: vec3<f32>, size: u32) -> vec3<f32> {
    if (cloud_point(x).alt_m >= clouds.shadow_base_m) {
        return vec3<f32>(0.0, 0.0, -1.0);
    }
    let far = shell_sphere(x, ray_dir, clouds.shadow_base_m).y;
    if (far <= 0.0) {
        return vec3<f32>(0.0, 0.0, -1.0);
    }
    let e = x + far * ray_dir;
    let ez = clouds.planet_radius_m + e.z;
    if (ez <= 0.0) {
        return vec3<f32>(0.0, 0.0, -1.0);
    }
    let half = map_half_extent(dir);
    let step = 2.0 * half / f32(size);
    return vec3<f32>((e.xy * (clouds.planet_radius_m / ez) + half) / step - 0.5, 1.0);
}

// CloudShadow::optical_depth: the layers' depth from local `x` towards light `l` (< 0: the
// map does not cover the point, or it lies at or above the base).
fn map_optical_depth(l: u32, x: vec3<f32>, dir: vec3<f32>) -> f32 {
    if (clouds.shadow_at[l] == NONE) {
        return -1.0;
    }
    return map_texel_depth(l, map_entry(x, dir, SHADOW_TEXELS));
}

// CloudShadow::disk_optical_depth: the layers' depth from a surface at local `x` towards
// light l's whole disk (angular radius `alpha`), −ln of the transmittance averaged over
// the disk: the map read along the light's azimuth where the disk's directions tilted by
// u·α towards the zenith enter the base (quadratic through u = −1, 0, 1), one read more
// than the texels they span (at most PENUMBRA_TAPS), by the midpoint rule weighted by
// √(1 − u²) (< 0: as map_optical_depth).
fn map_disk_optical_depth(l: u32, x: vec3<f32>, dir: vec3<f32>, alpha: f32) -> f32 {
    if (clouds.shadow_at[l] == NONE) {
        return -1.0;
    }
    let c = map_entry(x, dir, SHADOW_TEXELS);
    if (c.z < 0.0) {
        return -1.0;
    }
    let up = normalize(vec3<f32>(x.xy, clouds.planet_radius_m + x.z));
    let towards = up - dir * dot(dir, up);
    let len = length(towards);
    if (len <= 0.0) {
        return map_texel_depth(l, c);
    }
    let t = towards / len;
    let a = map_entry_along(x, dir * cos(alpha) + t * sin(alpha), dir, SHADOW_TEXELS);
    let b = map_entry_along(x, dir * cos(alpha) - t * sin(alpha), dir, SHADOW_TEXELS);
    let spread = length(a.xy - b.xy);
    if (a.z < 0.0 || b.z < 0.0 || spread < 1.0) {
        return map_texel_depth(l, c);
    }
    let taps = min(u32(ceil(spread)) + 1u, PENUMBRA_TAPS);
    var sum = 0.0;
    var weights = 0.0;
    for (var i = 0u; i < taps; i++) {
        let u = -1.0 + f32(2u * i + 1u) / f32(taps);
        let f = c.xy + 0.5 * u * (a.xy - b.xy) + u * u * (0.5 * (a.xy + b.xy) - c.xy);
        let tau = map_texel_depth(l, vec3<f32>(f, 1.0));
        if (tau >= 0.0) {
            let w = sqrt(max(1.0 - u * u, 0.0));
            sum += w * exp(-tau);
            weights += w;
        }
    }
    if (weights <= 0.0) {
        return map_texel_depth(l, c);
    }
    return -log(max(sum / weights, 1e-30));
}

// CloudShadow::texel_depth: light l's map at the entry `e` (map_entry's; bilinear), < 0
// outside the map.
fn map_texel_depth(l: u32, e: vec3<f32>) -> f32 {
    let f = e.xy;
    let max_f = f32(SHADOW_TEXELS - 1u);
    if (e.z < 0.0 || f.x < 0.0 || f.y < 0.0 || f.x >= max_f || f.y >= max_f) {
        return -1.0;
    }
    let i = vec2<u32>(f);
    let t = f - vec2<f32>(i);
    let row0 = clouds.shadow_at[l] + i.y * SHADOW_TEXELS + i.x;
    let row1 = row0 + SHADOW_TEXELS;
    let lo = mix(cloud_data[row0], cloud_data[row0 + 1u], t.x);
    let hi = mix(cloud_data[row1], cloud_data[row1 + 1u], t.x);
    return mix(lo, hi, t.y);
}

// CloudShadow::mean_transmittance: the coarse map's mean transmittance towards light `l` of
// the block local `x`'s ray enters (beyond the map, its edge, unless the clouds differ there,
// clouds.shadow_extends = 0: the air there is lit; < 0: x lies at or above the base, or
// beyond a map that does not extend).
fn map_mean_transmittance(l: u32, x: vec3<f32>, dir: vec3<f32>) -> f32 {
    let e = map_entry(x, dir, COARSE_TEXELS);
    if (e.z < 0.0) {
        return -1.0;
    }
    let max_f = f32(COARSE_TEXELS - 1u);
    let inside = all(e.xy >= vec2<f32>(0.0)) && all(e.xy <= vec2<f32>(max_f));
    if (clouds.shadow_extends == 0u && !inside) {
        return -1.0;
    }
    let f = clamp(e.xy, vec2<f32>(0.0), vec2<f32>(max_f));
    let i = min(vec2<u32>(f), vec2<u32>(COARSE_TEXELS - 2u));
    let t = f - vec2<f32>(i);
    let row0 = clouds.shadow_at[l] + SHADOW_TEXELS * SHADOW_TEXELS + i.y * COARSE_TEXELS + i.x;
    let row1 = row0 + COARSE_TEXELS;
    let lo = mix(cloud_data[row0], cloud_data[row0 + 1u], t.x);
    let hi = mix(cloud_data[row1], cloud_data[row1 + 1u], t.x);
    return mix(lo, hi, t.y);
}

// Append [a, b] to the list, merging it with the last stretch across a gap under
// SHADOW_MERGE_FRACTION of its distance (cloud_shadow::merge_close), or whatever the gap
// when the list is full, keeping the lit length: the merged shadow shrinks by half the gap
// at each end.
fn push_shadowed(list: ptr<function, ShadowList>, a: f32, b: f32) {
    let n = (*list).n;
    if (n > 0u && (a - (*list).s[n - 1u].y <= SHADOW_MERGE_FRACTION * a || n == MAX_SHADOWED)) {
        let g = max(a - (*list).s[n - 1u].y, 0.0);
        (*list).s[n - 1u] = vec2<f32>((*list).s[n - 1u].x + 0.5 * g, b - 0.5 * g);
        return;
    }
    (*list).s[n] = vec2<f32>(a, b);
    (*list).n = n + 1u;
}

// CloudShadow::shadowed_intervals: the stretches of the ray from local `q` along `dir`
// before `end_m` (and below the base) in light l's shadow: to SHADOW_MAX_DISTANCE_M in steps
// of max(250 m, t/50), the first 1 − T of each (T the texels' transmittance at its middle,
// snapped to 0 or 1 within SHADOW_SNAP); beyond, in pieces [a, SHADOW_FAR_PIECE_RATIO·a] each in shadow over the fraction 1 − T̄ of
// its length (T̄ the coarse map's mean along it), at both ends, lit in the middle.
fn shadowed_intervals(l: u32, light_dir: vec3<f32>, q: vec3<f32>, dir: vec3<f32>, end_m: f32) -> ShadowList {
    var list: ShadowList;
    list.n = 0u;
    if (clouds.shadow_at[l] == NONE) {
        return list;
    }
    let far = shell_sphere(q, dir, clouds.shadow_base_m);
    if (far.x > far.y || far.y <= 0.0) {
        return list;
    }
    let limit = min(far.y, end_m);
    let near = min(limit, SHADOW_MAX_DISTANCE_M);
    var t = 0.0;
    // The start of a shadowed stretch reaching t (< 0: none).
    var start = -1.0;
    loop {
        if (t >= near) {
            break;
        }
        let dt = min(max(0.02 * t, 250.0), near - t);
        let x = q + (t + 0.5 * dt) * dir;
        let tau = map_optical_depth(l, x, light_dir);
        var lit = 1.0;
        if (tau >= 0.0) {
            lit = exp(-tau);
        }
        var dark = (1.0 - lit) * dt;
        if (lit < SHADOW_SNAP) {
            dark = dt;
        } else if (lit > 1.0 - SHADOW_SNAP) {
            dark = 0.0;
        }
        if (dark >= dt) {
            if (start < 0.0) {
                start = t;
            }
        } else if (dark > 0.0) {
            push_shadowed(&list, select(t, start, start >= 0.0), t + dark);
            start = -1.0;
        } else if (start >= 0.0) {
            push_shadowed(&list, start, t);
            start = -1.0;
        }
        t += dt;
    }
    if (start >= 0.0) {
        push_shadowed(&list, start, near);
    }
    var a = near;
    loop {
        if (a >= limit) {
            break;
        }
        let b = far_piece_end(a, limit);
        // The mean transmittance along the piece (beyond the map and not extended: lit).
        var s = a;
        var sum = 0.0;
        loop {
            if (s >= b) {
                break;
            }
            let dt = min(max(0.02 * s, 250.0), b - s);
            let mean = map_mean_transmittance(l, q + (s + 0.5 * dt) * dir, light_dir);
            sum += select(clamp(mean, 0.0, 1.0), 1.0, mean < 0.0) * dt;
            s += dt;
        }
        let shade = 0.5 * (b - a - sum);
        if (shade > 0.0) {
            push_shadowed(&list, a, a + shade);
            push_shadowed(&list, b - shade, b);
        }
        a = b;
    }
    return list;
}

// cloud_shadow::far_piece_end: SHADOW_FAR_PIECE_RATIO·a, or `limit` when less than half a
// piece would remain after it.
fn far_piece_end(a: f32, limit: f32) -> f32 {
    let b = a * SHADOW_FAR_PIECE_RATIO;
    return select(b, limit, b + 0.5 * (b - a) >= limit);
}

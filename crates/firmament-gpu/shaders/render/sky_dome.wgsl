// The sky's irradiance on a surface under a horizon, weighted by the sky's radiance
// (firmament::render::sky_dome): per light, the moments M_k(b) = ∫∫_{e > b} L ω cos e de dφ
// of the sky's radiance over HORIZON_AZIMUTHS sectors from each elevation node to the
// zenith (computed on the CPU from the observer's view, in terrain_data at
// terrain.per_light[l].y: ((k·nodes + j)·3 + axis)·channels + c, then the open plane's
// irradiance per channel), summed as n·M_k(max(β_k, e₀,k)) over the sectors.

// sky_dome::node_of: the node below elevation b (rad, in [0, 90°)) and the fraction
// towards the next (DOME_PIECES: uniform pieces (start, end, step) in degrees).
fn dome_node_of(b: f32) -> vec2<f32> {
    let d = degrees(b);
    var first = 0u;
    for (var p = 0u; p < 3u; p++) {
        let piece = DOME_PIECES[p];
        let len = u32(round((piece.y - piece.x) / piece.z));
        if (d < piece.y) {
            let x = max(d - piece.x, 0.0) / piece.z;
            let i = min(u32(x), len - 1u);
            return vec2<f32>(f32(first + i), x - f32(i));
        }
        first += len;
    }
    return vec2<f32>(f32(first - 1u), 1.0);
}

// One channel of a dome's moment (sector k, node j, axis a).
fn dome_moment(base: u32, k: u32, j: u32, a: u32, c: u32) -> f32 {
    return terrain_data[base + ((k * terrain.dome_nodes + j) * 3u + a) * atm.channels + c];
}

// SkyDome::share of light `light`, channel group k: the sky's irradiance on a surface with
// unit `normal` whose local vertical is `up`, under horizons `h`, as a share of the open
// horizontal plane's.
fn dome_share(light: u32, up: vec3<f32>, normal: vec3<f32>, h: Horizons, k: u32) -> vec4<f32> {
    let base = terrain.per_light[light].y;
    let n = atm.channels;
    let east = normalize(vec3<f32>(1.0, 0.0, 0.0) - up * up.x);
    let north = cross(up, east);
    let ne = dot(normal, east);
    let nn = dot(normal, north);
    let nu = dot(normal, up);
    let width = 2.0 * PI / f32(HORIZON_AZIMUTHS);
    var sum = vec4<f32>(0.0);
    for (var s = 0u; s < HORIZON_AZIMUTHS; s++) {
        let theta = width * f32(s);
        let a = ne * cos(theta) + nn * sin(theta);
        var b = h.beta[s];
        if (a < 0.0) {
            b = max(b, atan2(-a, nu));
        }
        if (b >= 0.5 * PI) {
            continue;
        }
        let jf = dome_node_of(b);
        let j = u32(jf.x);
        let f = jf.y;
        for (var lane = 0u; lane < 4u; lane++) {
            let c = 4u * k + lane;
            if (c < n) {
                var v = 0.0;
                let w = array<f32, 3>(ne, nn, nu);
                for (var axis = 0u; axis < 3u; axis++) {
                    let lo = dome_moment(base, s, j, axis, c);
                    let hi = dome_moment(base, s, j + 1u, axis, c);
                    v += w[axis] * (lo + f * (hi - lo));
                }
                sum[lane] += max(v, 0.0);
            }
        }
    }
    var out = vec4<f32>(0.0);
    let open_at = base + HORIZON_AZIMUTHS * terrain.dome_nodes * 3u * n;
    for (var lane = 0u; lane < 4u; lane++) {
        let c = 4u * k + lane;
        if (c < n) {
            let open = terrain_data[open_at + c];
            if (open > 0.0) {
                out[lane] = sum[lane] / open;
            }
        }
    }
    return out;
}

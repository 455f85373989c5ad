// The planet's weather (firmament::scene::clouds::planetary::PlanetaryWeather) of a layer
// with weather_wrap = "planet": an equirectangular map of PLANET_CHANNELS values [w, t, p]
// per texel in cloud_data from the layer's `planet_at`, row 0 at 90° N, column 0 at 180° W,
// read bilinearly wrapping in longitude and clamped in latitude (planet::bilinear_wrap); and
// its fine detail, two tiled maps of w alone from `planet_detail_at` (their tiles incommensurate).

// Texel (i, j) of layer l's planetary map.
fn planet_texel(l: CloudLayerParams, i: u32, j: u32) -> vec3<f32> {
    let at = l.planet_at + PLANET_CHANNELS * (j * l.planet_width + i);
    return vec3<f32>(cloud_data[at], cloud_data[at + 1u], cloud_data[at + 2u]);
}

// PlanetaryWeather::sample: [w, t, p] above the local unit direction `up` (the observer's
// frame: x east, y north, z up), through the planet-fixed direction (PlanetaryWeather::fixed).
fn planet_sample(l: CloudLayerParams, up: vec3<f32>) -> vec3<f32> {
    let d = up.x * l.planet_east + up.y * l.planet_north + up.z * l.planet_up;
    let lat = asin(clamp(d.z, -1.0, 1.0));
    let lon = atan2(d.y, d.x);
    let size = vec2<f32>(f32(l.planet_width), f32(l.planet_height));
    let x = (lon / (2.0 * PI) + 0.5) * size.x - 0.5;
    let y = clamp((0.5 - lat / PI) * size.y - 0.5, 0.0, size.y - 1.0);
    let c = floor(vec2<f32>(x, y));
    let f = vec2<f32>(x, y) - c;
    // Columns wrap (x ≥ −1 and < width), rows are clamped.
    let i0 = select(u32(max(c.x, 0.0)), l.planet_width - 1u, c.x < 0.0);
    let i1 = select(i0 + 1u, 0u, i0 + 1u >= l.planet_width);
    let j0 = u32(c.y);
    let j1 = min(j0 + 1u, l.planet_height - 1u);
    let lo = mix(planet_texel(l, i0, j0), planet_texel(l, i1, j0), f.x);
    let hi = mix(planet_texel(l, i0, j1), planet_texel(l, i1, j1), f.x);
    return mix(lo, hi, f.y);
}

// PlanetaryWeather::detail: PLANET_DETAIL_GAIN·(½(a + b) − ½) of the two detail maps' w at
// planar coordinates (x, y) (m, with the wind), about in [−½, ½].
fn planet_detail(l: CloudLayerParams, xy: vec2<f32>) -> f32 {
    var sum = 0.0;
    for (var k = 0u; k < 2u; k++) {
        sum += weather_value(l.planet_detail_at[k], l.planet_detail_width[k], l.planet_detail_height[k], l.planet_detail_tile_m[k], xy);
    }
    return PLANET_DETAIL_GAIN * (0.5 * sum - 0.5);
}

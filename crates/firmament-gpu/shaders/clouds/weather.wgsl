// A layer's weather map (firmament::scene::clouds::weather::WeatherMap::sample): width ×
// height texels of WEATHER_CHANNELS values [coverage w, type t, precipitation p, warp x,
// warp y] in cloud_data from the layer's `weather_at`, row-major from the tile's south-west
// corner, read bilinearly with wrap-around at (x, y) m in the layer's planar coordinates.

struct Weather {
    w: f32,
    t: f32,
    precipitation: f32,
    warp: vec2<f32>,
}

fn weather_texel(at: u32, i: u32) -> Weather {
    let b = at + i * WEATHER_CHANNELS;
    var out: Weather;
    out.w = cloud_data[b];
    out.t = cloud_data[b + 1u];
    out.precipitation = cloud_data[b + 2u];
    out.warp = vec2<f32>(cloud_data[b + 3u], cloud_data[b + 4u]);
    return out;
}

fn weather_mix(a: Weather, b: Weather, t: f32) -> Weather {
    var out: Weather;
    out.w = mix(a.w, b.w, t);
    out.t = mix(a.t, b.t, t);
    out.precipitation = mix(a.precipitation, b.precipitation, t);
    out.warp = mix(a.warp, b.warp, t);
    return out;
}

fn weather_sample(l: CloudLayerParams, xy: vec2<f32>) -> Weather {
    let size = vec2<u32>(l.weather_width, l.weather_height);
    let uv = xy / l.weather_tile_m;
    let fxy = (uv - floor(uv)) * vec2<f32>(size) - 0.5;
    let c = floor(fxy);
    let t = fxy - c;
    let i0 = vec2<u32>(select(vec2<i32>(c), vec2<i32>(size) - 1, c < vec2<f32>(0.0)));
    let i1 = select(i0 + 1u, vec2<u32>(0u), i0 + 1u >= size);
    let a = weather_texel(l.weather_at, i0.y * size.x + i0.x);
    let b = weather_texel(l.weather_at, i0.y * size.x + i1.x);
    let c0 = weather_texel(l.weather_at, i1.y * size.x + i0.x);
    let d = weather_texel(l.weather_at, i1.y * size.x + i1.x);
    return weather_mix(weather_mix(a, b, t.x), weather_mix(c0, d, t.x), t.y);
}

// WeatherMap::sample's first value (w) of a map of one value per texel (width × height in
// cloud_data from `at`, row-major from the tile's south-west corner) tiling every `tile_m`,
// bilinear with wrap-around at (x, y) m: the planet's detail maps (planetary.wgsl).
fn weather_value(at: u32, width: u32, height: u32, tile_m: f32, xy: vec2<f32>) -> f32 {
    let size = vec2<u32>(width, height);
    let uv = xy / tile_m;
    let fxy = (uv - floor(uv)) * vec2<f32>(size) - 0.5;
    let c = floor(fxy);
    let t = fxy - c;
    let i0 = vec2<u32>(select(vec2<i32>(c), vec2<i32>(size) - 1, c < vec2<f32>(0.0)));
    let i1 = select(i0 + 1u, vec2<u32>(0u), i0 + 1u >= size);
    let row0 = at + i0.y * size.x;
    let row1 = at + i1.y * size.x;
    let lo = mix(cloud_data[row0 + i0.x], cloud_data[row0 + i1.x], t.x);
    let hi = mix(cloud_data[row1 + i0.x], cloud_data[row1 + i1.x], t.x);
    return mix(lo, hi, t.y);
}

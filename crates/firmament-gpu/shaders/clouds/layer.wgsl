// The cloud layers (firmament::scene::clouds::layer::CloudLayer): shells between two
// altitudes following the planet, their density from the weather map's coverage and type,
// the type's height profile and the two noise volumes (Hillaire 2016 §5.2, Schneider 2015).
// Positions are local (m): the observer's foot at the origin, x east, y north, z up, the
// planet's centre at (0, 0, −clouds.planet_radius_m); altitudes are taken without
// cancellation so that f32 keeps the layer's structure anywhere in view.

// One layer's settings (firmament_gpu::clouds writes them).
struct CloudLayerParams {
    kind: u32,
    weather_width: u32,
    weather_height: u32,
    weather_at: u32,
    bottom_m: f32,
    top_m: f32,
    coverage: f32,
    extinction_per_m: f32,
    albedo: f32,
    // Dual-lobe HG: forward g, backward g, forward weight; its mean cosine.
    g1: f32,
    g2: f32,
    weight: f32,
    mean_cosine: f32,
    weather_tile_m: f32,
    shape_tile_m: f32,
    detail_tile_m: f32,
    horizontal_stretch: f32,
    wind_x_m: f32,
    wind_y_m: f32,
    // The two-stream tables' offset (NONE: octaves), their δ-scaling and asymmetry.
    two_stream_at: u32,
    ts_scattering_scale: f32,
    ts_extinction_scale: f32,
    ts_asymmetry: f32,
    // Octaves (Volume::octaves): count, a, b, c.
    octaves: u32,
    octave_scattering: f32,
    octave_extinction: f32,
    octave_eccentricity: f32,
    pad0: u32,
}

struct Clouds {
    layers: u32,
    base_size: u32,
    detail_size: u32,
    base_at: u32,
    detail_at: u32,
    // The march's octaves (the most any layer asks for) and its extinction gain.
    octave_count: u32,
    octave_extinction: f32,
    // The marcher's step at the closest (m; Volume::feature_size_m, the smallest).
    feature_m: f32,
    planet_radius_m: f32,
    // The shadow maps' base sphere (altitude, m) and each light's map (NONE without).
    shadow_base_m: f32,
    // The observer's altitude above the clouds' planet (m).
    observer_alt_m: f32,
    pad1: u32,
    shadow_at: vec4<u32>,
    layer: array<CloudLayerParams, MAX_CLOUD_LAYERS>,
}

@group(0) @binding(19) var<storage, read> cloud_data: array<f32>;
@group(0) @binding(20) var<uniform> clouds: Clouds;

// A local point's unit vector from the planet's centre and its altitude (m).
struct CloudPoint {
    up: vec3<f32>,
    alt_m: f32,
}

fn cloud_point(q: vec3<f32>) -> CloudPoint {
    let r0 = clouds.planet_radius_m;
    let c = vec3<f32>(q.xy, r0 + q.z);
    let r = length(c);
    var p: CloudPoint;
    p.up = c / r;
    // r − R = (x² + y² + z(2R + z))/(r + R).
    p.alt_m = (dot(q.xy, q.xy) + q.z * (2.0 * r0 + q.z)) / (r + r0);
    return p;
}

// CloudLayer::planar: the gnomonic projection of the cube face `up` falls on, at the
// planet's radius (the +z face is the observer's: x east, y north).
fn cloud_planar(up: vec3<f32>) -> vec2<f32> {
    let a = abs(up);
    let r = clouds.planet_radius_m;
    if (a.z >= a.x && a.z >= a.y) {
        return up.xy * (r / a.z);
    }
    if (a.x >= a.y) {
        return vec2<f32>(up.y, up.z) * (r / a.x) + vec2<f32>(4.0 * r, 0.0);
    }
    return vec2<f32>(up.x, up.z) * (r / a.y) + vec2<f32>(8.0 * r, 0.0);
}

// noise::remap.
fn remap(v: f32, lo: f32, hi: f32, new_lo: f32, new_hi: f32) -> f32 {
    return new_lo + (v - lo) / (hi - lo) * (new_hi - new_lo);
}

// The weather's local coverage c_loc = clamp(c + WEATHER_CONTRAST·(w − ½), 0, 1).
fn local_coverage(l: CloudLayerParams, w: f32) -> f32 {
    return clamp(l.coverage + WEATHER_CONTRAST * (w - 0.5), 0.0, 1.0);
}

// CloudLayer::density_with (dimensionless: the extinction over extinction_per_m).
fn cloud_layer_density(i: u32, p: CloudPoint, eroded: bool) -> f32 {
    let l = clouds.layer[i];
    if (p.alt_m < l.bottom_m || p.alt_m > l.top_m) {
        return 0.0;
    }
    let h = (p.alt_m - l.bottom_m) / (l.top_m - l.bottom_m);
    if (l.kind == CLOUD_UNIFORM) {
        return 1.0;
    }
    let xy = cloud_planar(p.up) + vec2<f32>(l.wind_x_m, l.wind_y_m);
    let weather = weather_sample(l, xy);
    let c = local_coverage(l, weather.w);
    let profile = profile_density(l.kind, h, weather.t);
    // The shape is 0 unless base·profile > 1 − c, and base ≤ 1.
    if (profile <= 1.0 - c) {
        return 0.0;
    }
    let z = p.alt_m - l.bottom_m;
    let uv = xy / l.shape_tile_m + weather.warp;
    let b = noise_sample(clouds.base_at, clouds.base_size, vec3<f32>(uv, z * l.horizontal_stretch / l.shape_tile_m));
    let shape = max(remap(b * profile, 1.0 - c, 1.0, 0.0, 1.0), 0.0);
    if (shape <= 0.0) {
        return 0.0;
    }
    let rain = 1.0 + PRECIPITATION_GAIN * weather.precipitation;
    if (!eroded) {
        return shape * rain;
    }
    let e = profile_erosion(l.kind, h);
    let k = l.shape_tile_m / l.detail_tile_m;
    let d = noise_sample(clouds.detail_at, clouds.detail_size, vec3<f32>(uv * k, z * l.horizontal_stretch / l.detail_tile_m));
    return max(remap(shape, e * d, 1.0, 0.0, 1.0), 0.0) * rain;
}

// CloudLayer::surely_empty: outside the shell, or where the profile is at most 1 − c_loc.
fn layer_surely_empty(i: u32, p: CloudPoint) -> bool {
    let l = clouds.layer[i];
    if (p.alt_m < l.bottom_m || p.alt_m > l.top_m) {
        return true;
    }
    if (l.kind == CLOUD_UNIFORM) {
        return false;
    }
    let xy = cloud_planar(p.up) + vec2<f32>(l.wind_x_m, l.wind_y_m);
    let weather = weather_sample(l, xy);
    let h = (p.alt_m - l.bottom_m) / (l.top_m - l.bottom_m);
    return profile_density(l.kind, h, weather.t) <= 1.0 - local_coverage(l, weather.w);
}

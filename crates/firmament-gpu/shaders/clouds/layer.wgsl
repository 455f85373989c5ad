// The cloud layers (firmament::scene::clouds::layer::CloudLayer): shells between two
// altitudes following the planet, their density from the weather map's coverage and type
// (or the planet's weather map's, planetary.wgsl), the type's height profile and the two
// noise volumes (Hillaire 2016 §5.2, Schneider 2015), filtered over a pixel's footprint
// when the layer has a view (lod.wgsl).
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
    // The phase the δ-scaling keeps, min(p, ts_forward_cap) (TwoStream::forward_phase_cap).
    ts_forward_cap: f32,
    // The planet's weather (weather_wrap = "planet"; planetary.wgsl): the observer's east,
    // north and up in the planet-fixed frame, the map's offset (NONE: the tiled map's weather)
    // and size.
    planet_east: vec3<f32>,
    planet_at: u32,
    planet_north: vec3<f32>,
    planet_width: u32,
    planet_up: vec3<f32>,
    planet_height: u32,
    // The view whose pixels' footprint the density is filtered over (CloudLayer::filter):
    // the camera (planet-centred, m) and a pixel's angle (rad).
    eye: vec3<f32>,
    pixel_angle_rad: f32,
    // The planet's fine detail: two tiled maps of w alone (PlanetaryWeather::detail).
    planet_detail_at: vec2<u32>,
    planet_detail_width: vec2<u32>,
    planet_detail_height: vec2<u32>,
    planet_detail_tile_m: vec2<f32>,
    // The filter's mean density (lod.wgsl; NONE: no filter, the noise's density everywhere)
    // and the noise's cell (CloudLayer::cell_m).
    mean_at: u32,
    cell_m: f32,
    pad2: u32,
    pad3: u32,
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
    // The tables' ground above the clouds' planet (m: the ground lifted to a terrain's
    // floor; 0 without a terrain).
    lift_m: f32,
    shadow_at: vec4<u32>,
    // The thinnest layer's thickness (m): far steps cross it in at least VERTICAL_STEPS.
    thinnest_m: f32,
    // Whether the coarse shadow map's edge stands for the clouds beyond it (1; 0 over a
    // planet's weather: CloudShadow's `extends`).
    shadow_extends: u32,
    pad4: u32,
    pad5: u32,
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

// The weather at a point of a layer (CloudLayer::local's Local): normalised height, local
// coverage c_loc, type, precipitation, the planar coordinates with the wind (m) and the
// noise's warp (tiles).
struct CloudLocal {
    h: f32,
    c: f32,
    t: f32,
    precipitation: f32,
    xy: vec2<f32>,
    warp: vec2<f32>,
}

// CloudLayer::local at `p` inside the shell of layer `l`, which has weather (not uniform):
// c_loc = clamp(c + k·(w − ½), 0, 1) with the tiled map's w and k = WEATHER_CONTRAST, or the
// planet's w plus PLANET_DETAIL times its fine detail and k = PLANET_CONTRAST (t and p from
// the planet's map too; the tiled map still warps the noise).
fn cloud_local(l: CloudLayerParams, p: CloudPoint) -> CloudLocal {
    var out: CloudLocal;
    out.h = (p.alt_m - l.bottom_m) / (l.top_m - l.bottom_m);
    out.xy = cloud_planar(p.up) + vec2<f32>(l.wind_x_m, l.wind_y_m);
    let weather = weather_sample(l, out.xy);
    out.warp = weather.warp;
    var w = weather.w;
    var contrast = WEATHER_CONTRAST;
    out.t = weather.t;
    out.precipitation = weather.precipitation;
    if (l.planet_at != NONE) {
        let planet = planet_sample(l, p.up);
        w = clamp(planet.x + PLANET_DETAIL * planet_detail(l, out.xy), 0.0, 1.0);
        out.t = planet.y;
        out.precipitation = planet.z;
        contrast = PLANET_CONTRAST;
    }
    out.c = clamp(l.coverage + contrast * (w - 0.5), 0.0, 1.0);
    return out;
}

// CloudLayer::noise_density: the noise's density (before precipitation's gain) at the
// weather `local` of layer `l` with the type's `profile` there.
fn noise_density(l: CloudLayerParams, local: CloudLocal, profile: f32, eroded: bool) -> f32 {
    let z = local.h * (l.top_m - l.bottom_m);
    let uv = local.xy / l.shape_tile_m + local.warp;
    let b = noise_sample(clouds.base_at, clouds.base_size, vec3<f32>(uv, z * l.horizontal_stretch / l.shape_tile_m));
    let shape = max(remap(b * profile, 1.0 - local.c, 1.0, 0.0, 1.0), 0.0);
    if (shape <= 0.0 || !eroded) {
        return shape;
    }
    let e = profile_erosion(l.kind, local.h);
    let k = l.shape_tile_m / l.detail_tile_m;
    let d = noise_sample(clouds.detail_at, clouds.detail_size, vec3<f32>(uv * k, z * l.horizontal_stretch / l.detail_tile_m));
    return max(remap(shape, e * d, 1.0, 0.0, 1.0), 0.0);
}

// CloudLayer::density_with (dimensionless: the extinction over extinction_per_m); with a
// view, the noise's density blended towards the mean given the weather as the pixel's
// footprint there grows past the noise's cells (lod.wgsl).
fn cloud_layer_density(i: u32, p: CloudPoint, eroded: bool) -> f32 {
    let l = clouds.layer[i];
    if (p.alt_m < l.bottom_m || p.alt_m > l.top_m) {
        return 0.0;
    }
    if (l.kind == CLOUD_UNIFORM) {
        return 1.0;
    }
    let local = cloud_local(l, p);
    let profile = profile_density(l.kind, local.h, local.t);
    // The shape is 0 unless base·profile > 1 − c, and base ≤ 1.
    if (profile <= 1.0 - local.c) {
        return 0.0;
    }
    let gain = 1.0 + PRECIPITATION_GAIN * local.precipitation;
    // The pixel's footprint at the point (the point planet-centred, as the eye).
    var weight = 0.0;
    if (l.mean_at != NONE) {
        let centred = p.up * (clouds.planet_radius_m + p.alt_m);
        weight = filter_weight(length(centred - l.eye) * l.pixel_angle_rad, l.cell_m);
    }
    var density = 0.0;
    if (weight < 1.0) {
        density = noise_density(l, local, profile, eroded);
    }
    if (weight > 0.0) {
        density += weight * (mean_effective(l.mean_at, local.h, local.c, local.t) - density);
    }
    return gain * density;
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
    let local = cloud_local(l, p);
    return profile_density(l.kind, local.h, local.t) <= 1.0 - local.c;
}

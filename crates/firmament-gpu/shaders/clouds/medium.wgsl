// A cloud layer as a volume (firmament::scene::clouds::medium::CloudMedium): where a ray
// crosses its shell, the progressive march towards a light (Hillaire 2016, "Sun shadow
// sampling"), the vertical optical depths of the ambient light, and the two-stream's diffuse
// light at a point (Volume::diffuse_radiance). Grey: one value for every channel.

// The distances (t0, t1) at which the ray from local `q` along `dir` meets the sphere at
// altitude `alt_m` (t0 > t1: it misses), without cancellation:
// c = |q − C|² − (R + a)² = x² + y² + (z − a)(2R + z + a).
fn shell_sphere(q: vec3<f32>, dir: vec3<f32>, alt_m: f32) -> vec2<f32> {
    let r0 = clouds.planet_radius_m;
    let b = dot(dir.xy, q.xy) + dir.z * (r0 + q.z);
    let c = dot(q.xy, q.xy) + (q.z - alt_m) * (2.0 * r0 + q.z + alt_m);
    let disc = b * b - c;
    if (disc < 0.0) {
        return vec2<f32>(1.0, -1.0);
    }
    let root = sqrt(disc);
    let s = -(b + select(-root, root, b >= 0.0));
    if (s == 0.0) {
        return vec2<f32>(0.0, 0.0);
    }
    let t_a = s;
    let t_b = c / s;
    return vec2<f32>(min(t_a, t_b), max(t_a, t_b));
}

// CloudMedium::segments: up to two stretches of the ray inside layer i, t ≥ 0 (n = 0, 1, 2).
struct Segments {
    n: u32,
    s: array<vec2<f32>, 2>,
}

fn layer_segments(i: u32, q: vec3<f32>, dir: vec3<f32>) -> Segments {
    var out: Segments;
    out.n = 0u;
    let l = clouds.layer[i];
    let top = shell_sphere(q, dir, l.top_m);
    if (top.x > top.y || top.y <= 0.0) {
        return out;
    }
    let start = max(top.x, 0.0);
    let base = shell_sphere(q, dir, l.bottom_m);
    if (base.x <= base.y && base.y > start && base.x < top.y) {
        let a = max(base.x, start);
        if (a > start) {
            out.s[out.n] = vec2<f32>(start, a);
            out.n += 1u;
        }
        let b = max(base.y, start);
        if (top.y > b) {
            out.s[out.n] = vec2<f32>(b, top.y);
            out.n += 1u;
        }
    } else if (top.y > start) {
        out.s[0] = vec2<f32>(start, top.y);
        out.n = 1u;
    }
    return out;
}

// CloudMedium::light_optical_depth of layer i from local `q` along `dir`: LIGHT_SAMPLES
// midpoints over steps growing by LIGHT_STEP_GROWTH to the first stretch's end (at most
// LIGHT_MARCH_MAX_M), the first DETAILED_LIGHT_SAMPLES with the erosion; the uniform layer's
// depth in closed form.
fn layer_light_optical_depth(i: u32, q: vec3<f32>, dir: vec3<f32>) -> f32 {
    let segs = layer_segments(i, q, dir);
    if (segs.n == 0u) {
        return 0.0;
    }
    let l = clouds.layer[i];
    if (l.kind == CLOUD_UNIFORM) {
        var length = segs.s[0].y - segs.s[0].x;
        if (segs.n == 2u) {
            length += segs.s[1].y - segs.s[1].x;
        }
        return l.extinction_per_m * length;
    }
    let a = segs.s[0].x;
    let end = min(segs.s[0].y, a + LIGHT_MARCH_MAX_M);
    var total = 0.0;
    var g = 1.0;
    for (var k = 0u; k < LIGHT_SAMPLES; k++) {
        total += g;
        g *= LIGHT_STEP_GROWTH;
    }
    var step = (end - a) / total;
    var t = a;
    var tau = 0.0;
    for (var k = 0u; k < LIGHT_SAMPLES; k++) {
        let x = q + (t + 0.5 * step) * dir;
        tau += l.extinction_per_m * cloud_layer_density(i, cloud_point(x), k < DETAILED_LIGHT_SAMPLES) * step;
        t += step;
        step *= LIGHT_STEP_GROWTH;
    }
    return tau;
}

// Every layer's optical depth from `q` towards a light in `dir` (render::volumes::
// light_optical_depth; grey).
fn light_optical_depth(q: vec3<f32>, dir: vec3<f32>) -> f32 {
    var tau = 0.0;
    for (var i = 0u; i < clouds.layers; i++) {
        tau += layer_light_optical_depth(i, q, dir);
    }
    return tau;
}

// CloudMedium::vertical_optical_depths: (up to the top, down to the base) of layer i from
// the point, AMBIENT_SAMPLES midpoints each without the erosion.
fn vertical_optical_depths(i: u32, p: CloudPoint) -> vec2<f32> {
    let l = clouds.layer[i];
    if (p.alt_m < l.bottom_m || p.alt_m > l.top_m) {
        return vec2<f32>(0.0);
    }
    if (l.kind == CLOUD_UNIFORM) {
        return l.extinction_per_m * vec2<f32>(l.top_m - p.alt_m, p.alt_m - l.bottom_m);
    }
    var out = vec2<f32>(0.0);
    for (var side = 0u; side < 2u; side++) {
        let to = select(l.bottom_m, l.top_m, side == 0u);
        let dt = (to - p.alt_m) / f32(AMBIENT_SAMPLES);
        var tau = 0.0;
        for (var k = 0u; k < AMBIENT_SAMPLES; k++) {
            var x: CloudPoint;
            x.up = p.up;
            x.alt_m = p.alt_m + (f32(k) + 0.5) * dt;
            tau += l.extinction_per_m * cloud_layer_density(i, x, false) * abs(dt);
        }
        out[side] = tau;
    }
    return out;
}

// scene::volume::DiffuseLight (the moments per unit irradiance, grey).
struct DiffuseLight {
    from_light: vec2<f32>,
    from_above: vec2<f32>,
    from_below: vec2<f32>,
    asymmetry: f32,
    base_direct: f32,
    base_from_light: f32,
    base_from_above: f32,
    base_reflectance: f32,
    scattering_scale: f32,
}

// DiffuseLight::forward_peak: the share of the light's beam, after optical depth `tau`
// towards it, that the δ-scaling (optical depth per true one `scale`) moved into the
// forward peak.
fn forward_peak(scale: f32, tau: f32) -> f32 {
    return exp(-scale * tau) - exp(-tau);
}

// CloudMedium::diffuse_radiance of layer i (which has two-stream tables) above its top: the
// light comes down unscattered.
fn diffuse_above(i: u32) -> DiffuseLight {
    let l = clouds.layer[i];
    var f: DiffuseLight;
    f.asymmetry = l.ts_asymmetry;
    f.scattering_scale = l.ts_scattering_scale;
    f.base_direct = 1.0;
    return f;
}

// CloudMedium::diffuse_radiance of layer i (which has two-stream tables) at a point in or
// under it whose vertical optical depths (above, below) in the layer are `depths` (inside:
// vertical_optical_depths; under it: the march up its whole column and 0; the callers
// march them, each call site of a march inlining the layer's density), a light at cosine
// `mu_light` from the local vertical seen through optical depth `tau_light`.
fn diffuse_radiance(i: u32, depths: vec2<f32>, mu_light: f32, tau_light: f32) -> DiffuseLight {
    let l = clouds.layer[i];
    let at = l.two_stream_at;
    var f: DiffuseLight;
    f.asymmetry = l.ts_asymmetry;
    f.scattering_scale = l.ts_scattering_scale;
    let above = depths.x;
    let thickness = depths.x + depths.y;
    // A cloud's sides face a low light: the equivalent slab is never lit more grazingly than
    // MIN_LIGHT_COSINE.
    var mu_slab = mu_light;
    if (tau_light < 3.0e38 && mu_light > -0.1) {
        mu_slab = max(mu_light, MIN_LIGHT_COSINE);
    }
    var sun_depth = thickness;
    if (mu_slab > 0.0) {
        sun_depth = min(tau_light * mu_slab, thickness);
    }
    let two_pi = 2.0 * PI;
    f.from_light = ts_sun(at, thickness, sun_depth, mu_slab);
    f.from_above = ts_diffuse(at, thickness, above, true);
    f.from_below = ts_diffuse(at, thickness, above, false);
    if (mu_light > 0.0) {
        f.base_direct = exp(-thickness / mu_light);
    }
    f.base_from_light = two_pi * ts_sun(at, thickness, thickness, mu_light).x;
    // The beam's light in the forward peak reaches the base as a beam too.
    if (mu_light > 0.0) {
        f.base_from_light += mu_light * forward_peak(l.ts_extinction_scale, thickness / mu_light);
    }
    f.base_from_above = two_pi * ts_diffuse(at, thickness, thickness, true).x;
    f.base_reflectance = clamp(two_pi * ts_diffuse(at, thickness, 0.0, true).x - 1.0, 0.0, 1.0);
    return f;
}

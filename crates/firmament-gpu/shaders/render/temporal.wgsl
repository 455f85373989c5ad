// The temporal resolve of an interleaved frame (firmament_gpu::render::temporal): the frame
// drew one pixel of each k×k block (render.wgsl's `pixel`, its depth in alpha); every other
// pixel takes the previous frames' value where the same surface was seen (reprojected
// through the pinhole cameras by the fresh pixels' depths, Schneider 2015; Hillaire 2016
// §4.4), or else this frame's pixels around it, interpolated. With the camera and the scene
// still, the k² phases fill every pixel with its own value in k² frames: the full frame.

struct Temporal {
    // The frame's step k and the pixel (x, y) of each k×k block it drew.
    step: u32,
    phase_x: u32,
    phase_y: u32,
    // HISTORY_VALID | SAME_CAMERA | PINHOLES, and the count of `windows` in bits 8–15.
    flags: u32,
    // The previous frame's pinhole camera: its basis, and tan(fov/2) in before_forward.w.
    before_forward: vec4<f32>,
    before_right: vec4<f32>,
    before_up: vec4<f32>,
    // The eye's move since the previous frame (m; x east, y north, z up).
    moved_m: vec4<f32>,
    // Windows drawn whole this frame, around the lights' disks: x0, y0, x1, y1 (ends
    // excluded).
    windows: array<vec4<u32>, MAX_LIGHTS>,
}

// The history holds the same scene (else it is not read).
const HISTORY_VALID: u32 = 1u;
// The camera has not moved: the history is read in place.
const SAME_CAMERA: u32 = 2u;
// Both cameras are pinholes (perspective or orbit): the history is reprojected.
const PINHOLES: u32 = 4u;
// How far two depths of one surface may differ (relative): a cloud's depth is the mean of
// its layer's along the ray, which moves with the view and differs from pixel to pixel by
// tens of percent in a cumulus field; a ridge against the slope behind it differs by
// several times.
const DEPTH_TOLERANCE: f32 = 0.3;
// The least bilinear weight of the history's matching pixels for it to be used.
const MIN_HISTORY_WEIGHT: f32 = 0.25;

@group(0) @binding(0) var<uniform> temporal: Temporal;
// This frame's pixels (those of its phase): linear sRGB and the depth (m; 0 outside the
// projection).
@group(0) @binding(1) var<storage, read> fresh: array<vec4<f32>>;
// The previous frame's resolve, depths from its eye.
@group(0) @binding(2) var<storage, read> history: array<vec4<f32>>;
// The frame: linear sRGB and the mask (GpuRenderer's frame buffer layout).
@group(0) @binding(3) var<storage, read_write> resolved: array<vec4<f32>>;
// This frame's resolve with its depths, the next frame's history.
@group(0) @binding(4) var<storage, read_write> history_out: array<vec4<f32>>;

fn is_sky(depth_m: f32) -> bool {
    return depth_m >= 0.5 * SKY_DEPTH_M;
}

// Whether two depths (m, from their eyes) can be one surface's.
fn same_depth(a: f32, b: f32) -> bool {
    if (is_sky(a) || is_sky(b)) {
        return is_sky(a) && is_sky(b);
    }
    return abs(a - b) <= DEPTH_TOLERANCE * max(a, b);
}

// Where direction d was in the previous pinhole camera's frame (pixels, centres at +0.5;
// camera.wgsl's camera_ray inverted); x < 0 behind it.
fn before_pixel(d: vec3<f32>) -> vec2<f32> {
    let w = f32(frame.width);
    let h = f32(frame.height);
    let z = dot(d, temporal.before_forward.xyz);
    if (z <= 1e-6) {
        return vec2<f32>(-1.0);
    }
    let t = temporal.before_forward.w;
    let u = dot(d, temporal.before_right.xyz) / (z * t * w / h);
    let v = dot(d, temporal.before_up.xyz) / (z * t);
    return vec2<f32>((u + 1.0) * 0.5 * w, (1.0 - v) * 0.5 * h);
}

// The history's bilinear value at `pos` (pixels) over the pixels whose depth matches
// `expected_m` (value × weight, and the weight).
fn history_at(pos: vec2<f32>, expected_m: f32) -> vec4<f32> {
    let c = pos - vec2<f32>(0.5);
    let base = vec2<i32>(floor(c));
    let f = c - floor(c);
    var sum = vec4<f32>(0.0);
    for (var j = 0; j < 4; j++) {
        let o = vec2<i32>(j & 1, j >> 1u);
        let q = base + o;
        if (q.x < 0 || q.y < 0 || q.x >= i32(frame.width) || q.y >= i32(frame.height)) {
            continue;
        }
        let w = select(1.0 - f.x, f.x, o.x == 1) * select(1.0 - f.y, f.y, o.y == 1);
        let s = history[u32(q.y) * frame.width + u32(q.x)];
        if (w > 0.0 && s.w > 0.0 && same_depth(s.w, expected_m)) {
            sum += vec4<f32>(w * s.xyz, w);
        }
    }
    return sum;
}

// Along one axis: this frame's two drawn coordinates around x (of `size`, every k from
// `phase`) and the second's bilinear weight.
fn drawn_around(x: u32, phase: u32, k: u32, size: u32) -> vec3<f32> {
    let count = (size - phase + k - 1u) / k;
    let rel = (f32(x) - f32(phase)) / f32(k);
    let j0 = clamp(i32(floor(rel)), 0, i32(count) - 1);
    let j1 = min(j0 + 1, i32(count) - 1);
    var w1 = clamp(rel - f32(j0), 0.0, 1.0);
    if (j1 == j0) {
        w1 = 0.0;
    }
    return vec3<f32>(f32(u32(j0) * k + phase), f32(u32(j1) * k + phase), w1);
}

@compute @workgroup_size(64)
fn resolve(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = gid.x + gid.y * nwg.x * 64u;
    if (i >= frame.width * frame.height) {
        return;
    }
    let x = i % frame.width;
    let y = i / frame.width;
    let k = temporal.step;
    // Drawn this frame (its phase, or a window around a light's disk): its own value.
    var drawn = x % k == temporal.phase_x && y % k == temporal.phase_y;
    for (var w = 0u; w < ((temporal.flags >> 8u) & 0xffu); w++) {
        let r = temporal.windows[w];
        drawn = drawn || (x >= r.x && y >= r.y && x < r.z && y < r.w);
    }
    if (drawn) {
        let s = fresh[i];
        resolved[i] = vec4<f32>(s.xyz, select(0.0, 1.0, s.w > 0.0));
        history_out[i] = s;
        return;
    }
    let ray = camera_ray(f32(x) + 0.5, f32(y) + 0.5);
    if (!ray.valid) {
        resolved[i] = vec4<f32>(0.0);
        history_out[i] = vec4<f32>(0.0);
        return;
    }
    // This frame's four drawn pixels around (x, y) and their bilinear weights.
    let ax = drawn_around(x, temporal.phase_x, k, frame.width);
    let ay = drawn_around(y, temporal.phase_y, k, frame.height);
    var taps: array<vec4<f32>, 4>;
    var weights: array<f32, 4>;
    for (var j = 0u; j < 4u; j++) {
        let tx = u32(select(ax.x, ax.y, (j & 1u) == 1u));
        let ty = u32(select(ay.x, ay.y, (j >> 1u) == 1u));
        taps[j] = fresh[ty * frame.width + tx];
        weights[j] = select(1.0 - ax.z, ax.z, (j & 1u) == 1u) * select(1.0 - ay.z, ay.z, (j >> 1u) == 1u);
    }
    var value = vec3<f32>(0.0);
    var depth_m = 0.0;
    var found = false;
    if ((temporal.flags & HISTORY_VALID) != 0u) {
        if ((temporal.flags & SAME_CAMERA) != 0u) {
            let s = history[i];
            if (s.w > 0.0) {
                value = s.xyz;
                depth_m = s.w;
                found = true;
            }
        } else if ((temporal.flags & PINHOLES) != 0u) {
            // The surface this pixel sees now, where the previous frame saw it: at the depth
            // the history holds in the pixel's direction (for a turn of the camera, exact),
            // then at each drawn neighbour's depth; the best-matched of the five.
            var best = 0.0;
            let guess = before_pixel(ray.dir);
            var guessed = 0.0;
            if (guess.x >= 0.0 && guess.x < f32(frame.width) && guess.y >= 0.0 && guess.y < f32(frame.height)) {
                guessed = history[u32(guess.y) * frame.width + u32(guess.x)].w;
            }
            for (var j = 0u; j < 5u; j++) {
                var d = guessed;
                if (j > 0u) {
                    d = taps[j - 1u].w;
                }
                if (d <= 0.0) {
                    continue;
                }
                var dir_before = ray.dir;
                var expected_m = SKY_DEPTH_M;
                if (!is_sky(d)) {
                    let from_before = d * ray.dir + temporal.moved_m.xyz;
                    expected_m = length(from_before);
                    dir_before = from_before / expected_m;
                }
                let pos = before_pixel(dir_before);
                if (pos.x < 0.0) {
                    continue;
                }
                let taken = history_at(pos, expected_m);
                if (taken.w > best) {
                    best = taken.w;
                    value = taken.xyz / taken.w;
                    depth_m = d;
                }
            }
            found = best >= MIN_HISTORY_WEIGHT;
        }
    }
    if (!found) {
        // This frame's drawn pixels around it, inside the projection; the depth of the
        // nearest.
        var sum = vec4<f32>(0.0);
        var nearest = -1.0;
        depth_m = 0.0;
        for (var j = 0u; j < 4u; j++) {
            if (taps[j].w > 0.0) {
                sum += vec4<f32>(weights[j] * taps[j].xyz, weights[j]);
                if (weights[j] > nearest) {
                    nearest = weights[j];
                    depth_m = taps[j].w;
                }
            }
        }
        // (None inside: a fisheye's rim; black, and depth 0 keeps it out of the history.)
        value = sum.xyz / max(sum.w, 1e-12);
    }
    resolved[i] = vec4<f32>(value, 1.0);
    history_out[i] = vec4<f32>(value, depth_m);
}

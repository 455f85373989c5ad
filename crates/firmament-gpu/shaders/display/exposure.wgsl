// Automatic exposure of a frame on the GPU, the twin of firmament's
// `render::Frame::log_average_luminance` and `render::tonemap::auto_ev100`: the log-average
// luminance over the pixels inside the projection (leaving out black space, below 1e-6 of
// the brightest pixel), metered as a reflected-light meter reads it (ISO 2720), then
// adapted over time as an eye or a camera's auto-exposure does (an exponential approach,
// time constant `tau_s`). One workgroup walks the whole frame: cheap next to the frame.

struct ExposureParams {
    size: vec2<u32>,
    // Seconds since the last frame.
    dt_s: f32,
    // Adaptation time constant (s); 0 jumps to the metered value.
    tau_s: f32,
    // EV100 used when `manual` is 1.
    manual_ev100: f32,
    manual: u32,
    // The meter's calibration constant K (cd·s/m², ISO 2720), from the Rust constant.
    meter_k: f32,
    // 1: forget the adapted value (first frame, or after a jump).
    reset: u32,
}

// The frame as the render pass writes it (`RenderTarget::Buffer`): rows from the top.
@group(0) @binding(0) var<storage, read> frame_pixels: array<vec4<f32>>;
@group(0) @binding(1) var<uniform> params: ExposureParams;
// [EV100 in use, metered log-average luminance (cd/m²), pixels metered, brightest luminance]
@group(0) @binding(2) var<storage, read_write> exposure_state: array<f32, 4>;

const EXPOSURE_THREADS: u32 = 256u;
var<workgroup> partial_a: array<f32, 256>;
var<workgroup> partial_b: array<f32, 256>;

// Rec. 709 luminance weights (ITU-R BT.709), as the CPU's meter.
fn frame_luminance(c: vec3<f32>) -> f32 {
    return 0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b;
}

fn reduce_max(i: u32) {
    for (var s = EXPOSURE_THREADS / 2u; s > 0u; s = s / 2u) {
        workgroupBarrier();
        if (i < s) {
            partial_a[i] = max(partial_a[i], partial_a[i + s]);
        }
    }
    workgroupBarrier();
}

fn reduce_sums(i: u32) {
    for (var s = EXPOSURE_THREADS / 2u; s > 0u; s = s / 2u) {
        workgroupBarrier();
        if (i < s) {
            partial_a[i] = partial_a[i] + partial_a[i + s];
            partial_b[i] = partial_b[i] + partial_b[i + s];
        }
    }
    workgroupBarrier();
}

// EV100 = log2(L·100/K) (`tonemap::auto_ev100`).
fn auto_ev100(mean_luminance: f32) -> f32 {
    return log2(max(mean_luminance, 1e-6) * 100.0 / params.meter_k);
}

@compute @workgroup_size(256)
fn log_average_luminance(@builtin(local_invocation_index) i: u32) {
    let n = params.size.x * params.size.y;
    var brightest = 0.0;
    for (var p = i; p < n; p = p + EXPOSURE_THREADS) {
        let y = frame_luminance(frame_pixels[p].rgb);
        // NaN and negative values never win.
        if (y > brightest) {
            brightest = y;
        }
    }
    partial_a[i] = brightest;
    reduce_max(i);
    let top = partial_a[0];
    workgroupBarrier();
    let floor_y = max(top * 1e-6, 1e-6);
    var sum = 0.0;
    var count = 0.0;
    for (var p = i; p < n; p = p + EXPOSURE_THREADS) {
        let px = frame_pixels[p];
        let y = frame_luminance(px.rgb);
        if (px.a > 0.5 && y > floor_y) {
            sum = sum + log(y);
            count = count + 1.0;
        }
    }
    partial_a[i] = sum;
    partial_b[i] = count;
    reduce_sums(i);
    if (i == 0u) {
        var metered = 1.0;
        if (partial_b[0] > 0.0) {
            metered = exp(partial_a[0] / partial_b[0]);
        }
        let target_ev = auto_ev100(metered);
        var ev = target_ev;
        if (params.manual == 1u) {
            ev = params.manual_ev100;
        } else if (params.reset == 0u && params.tau_s > 0.0) {
            let previous = exposure_state[0];
            ev = previous + (target_ev - previous) * (1.0 - exp(-params.dt_s / params.tau_s));
        }
        exposure_state[0] = ev;
        exposure_state[1] = metered;
        exposure_state[2] = partial_b[0];
        exposure_state[3] = top;
    }
}

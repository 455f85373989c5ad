// A linear HDR frame (linear sRGB, Y in cd/m²) shown on a display: the twin of firmament's
// `render::tonemap` (the curves, `exposure_from_ev100`) and `spectrum::gamut::map_into_gamut`
// as `Frame::to_srgb8` applies them: into Rec. 709's gamut at the same luminance, the
// exposure of the EV100 in use (`exposure.wgsl`), the curve per channel, then the sRGB
// transfer function (IEC 61966-2-1) unless the target format encodes it. A frame smaller
// than the target is resampled bilinearly after the curve, so a bright disk does not bleed.

struct DisplayParams {
    source_size: vec2<u32>,
    target_size: vec2<u32>,
    // 0 ACES (Narkowicz 2015), 1 filmic (Hable 2010), 2 clamp.
    curve: u32,
    // 1 when the target stores codes (a UNORM format), 0 when it encodes sRGB itself.
    encode_srgb: u32,
    // The exposed value the curve maps to display mid-grey (`ToneCurve::inverse(0.18)`).
    mid_grey_input: f32,
    // The meter's calibration constant K (cd·s/m², ISO 2720).
    meter_k: f32,
}

// The frame as the render pass writes it (`RenderTarget::Buffer`): rows from the top.
@group(0) @binding(0) var<storage, read> frame_pixels: array<vec4<f32>>;
@group(0) @binding(1) var<uniform> display: DisplayParams;
@group(0) @binding(2) var<storage, read> exposure_state: array<f32, 4>;

// `ToneCurve::apply`.
fn apply(curve: u32, x_in: f32) -> f32 {
    let x = max(x_in, 0.0);
    if (curve == 0u) {
        // ACES filmic fit, Narkowicz 2015.
        return clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
    }
    if (curve == 1u) {
        // Hable 2010 with white point 11.2.
        return clamp(hable(2.0 * x) / hable(11.2), 0.0, 1.0);
    }
    return min(x, 1.0);
}

fn hable(x: f32) -> f32 {
    let a = 0.15;
    let b = 0.50;
    let c = 0.10;
    let d = 0.20;
    let e = 0.02;
    let f = 0.30;
    return ((x * (a * x + c * b) + d * e) / (x * (a * x + b) + d * f)) - e / f;
}

// `tonemap::exposure_from_ev100`: the metered luminance 2^EV·K/100 lands on mid-grey.
fn exposure_from_ev100(ev100: f32) -> f32 {
    return display.mid_grey_input / (exp2(ev100) * display.meter_k / 100.0);
}

// `gamut::map_into_gamut` with Rec. 709's luminance row.
fn map_into_gamut(rgb: vec3<f32>) -> vec3<f32> {
    let lowest = min(rgb.r, min(rgb.g, rgb.b));
    if (lowest >= 0.0) {
        return rgb;
    }
    let y = 0.2126 * rgb.r + 0.7152 * rgb.g + 0.0722 * rgb.b;
    if (y <= 0.0) {
        return vec3<f32>(0.0);
    }
    let s = y / (y - lowest);
    return max(vec3<f32>(y) + s * (rgb - vec3<f32>(y)), vec3<f32>(0.0));
}

fn linear_to_srgb(c: f32) -> f32 {
    if (c <= 0.0031308) {
        return 12.92 * c;
    }
    return 1.055 * pow(c, 1.0 / 2.4) - 0.055;
}

// One source pixel shown: gamut, exposure, curve (display-linear).
fn shown(p: vec2<i32>, exposure: f32) -> vec3<f32> {
    let q = clamp(p, vec2<i32>(0), vec2<i32>(display.source_size) - vec2<i32>(1));
    var c = frame_pixels[u32(q.y) * display.source_size.x + u32(q.x)].rgb;
    // A NaN shows as black, as `encode_srgb` on the CPU.
    c = select(c, vec3<f32>(0.0), c != c);
    c = map_into_gamut(c) * exposure;
    return vec3<f32>(apply(display.curve, c.r), apply(display.curve, c.g), apply(display.curve, c.b));
}

@vertex
fn fullscreen(@builtin(vertex_index) v: u32) -> @builtin(position) vec4<f32> {
    // One triangle over the whole target.
    let x = f32((v << 1u) & 2u);
    let y = f32(v & 2u);
    return vec4<f32>(2.0 * x - 1.0, 1.0 - 2.0 * y, 0.0, 1.0);
}

@fragment
fn present(@builtin(position) position: vec4<f32>) -> @location(0) vec4<f32> {
    let exposure = exposure_from_ev100(exposure_state[0]);
    var c: vec3<f32>;
    if (all(display.source_size == display.target_size)) {
        c = shown(vec2<i32>(position.xy), exposure);
    } else {
        // Pixel centres of the source under this target pixel's centre.
        let scale = vec2<f32>(display.source_size) / vec2<f32>(display.target_size);
        let s = position.xy * scale - vec2<f32>(0.5);
        let base = vec2<i32>(floor(s));
        let t = s - floor(s);
        let c00 = shown(base, exposure);
        let c10 = shown(base + vec2<i32>(1, 0), exposure);
        let c01 = shown(base + vec2<i32>(0, 1), exposure);
        let c11 = shown(base + vec2<i32>(1, 1), exposure);
        c = mix(mix(c00, c10, t.x), mix(c01, c11, t.x), t.y);
    }
    if (display.encode_srgb == 1u) {
        c = vec3<f32>(linear_to_srgb(c.r), linear_to_srgb(c.g), linear_to_srgb(c.b));
    }
    return vec4<f32>(c, 1.0);
}

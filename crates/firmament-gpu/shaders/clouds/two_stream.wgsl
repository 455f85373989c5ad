// A layer's δ-Eddington two-stream tables (firmament::scene::clouds::two_stream::TwoStream):
// in cloud_data from the layer's `two_stream_at`, the sun's (I₀, I₁) per unit beam
// irradiance over [TS_COSINES][TS_THICKNESSES][TS_DEPTHS], then diffuse light entering the
// top over [TS_THICKNESSES][TS_DEPTHS], each entry two f32.

// TwoStream::axes: fractional indices along the thickness (τ* = MAX·s²) and relative depth.
fn ts_axes(thickness: f32, depth: f32) -> vec2<f32> {
    let tau = clamp(thickness, 0.0, TS_MAX_THICKNESS);
    let s = sqrt(tau / TS_MAX_THICKNESS) * f32(TS_THICKNESSES - 1u);
    var u = 0.0;
    if (tau > 0.0) {
        u = clamp(depth / tau, 0.0, 1.0);
    }
    return vec2<f32>(s, u * f32(TS_DEPTHS - 1u));
}

fn ts_entry(at: u32, j: u32, i: u32) -> vec2<f32> {
    let e = at + 2u * (j * TS_DEPTHS + i);
    return vec2<f32>(cloud_data[e], cloud_data[e + 1u]);
}

// TwoStream::plane: a bilinear read of the [thickness][depth] plane at `at`.
fn ts_plane(at: u32, a: vec2<f32>) -> vec2<f32> {
    let j0 = u32(a.x);
    let i0 = u32(a.y);
    let j1 = min(j0 + 1u, TS_THICKNESSES - 1u);
    let i1 = min(i0 + 1u, TS_DEPTHS - 1u);
    let fs = a.x - f32(j0);
    let fu = a.y - f32(i0);
    let lo = mix(ts_entry(at, j0, i0), ts_entry(at, j0, i1), fu);
    let hi = mix(ts_entry(at, j1, i0), ts_entry(at, j1, i1), fu);
    return mix(lo, hi, fs);
}

// TwoStream::sun: (I₀, I₁) per unit beam irradiance at `depth` below the top of a slab of
// `thickness` (both true optical depths) under a light at cosine mu0.
fn ts_sun(at: u32, thickness: f32, depth: f32, mu0: f32) -> vec2<f32> {
    if (mu0 <= 0.0) {
        return vec2<f32>(0.0);
    }
    let a = ts_axes(thickness, depth);
    let c = clamp(mu0 * f32(TS_COSINES) - 0.5, 0.0, f32(TS_COSINES - 1u));
    let c0 = u32(c);
    let c1 = min(c0 + 1u, TS_COSINES - 1u);
    let size = 2u * TS_THICKNESSES * TS_DEPTHS;
    return mix(ts_plane(at + c0 * size, a), ts_plane(at + c1 * size, a), c - f32(c0));
}

// TwoStream::diffuse: per unit hemispheric irradiance entering the top (`from_above`) or
// the base.
fn ts_diffuse(at: u32, thickness: f32, depth_in: f32, from_above: bool) -> vec2<f32> {
    var depth = depth_in;
    if (!from_above) {
        depth = max(thickness - depth_in, 0.0);
    }
    let m = ts_plane(at + 2u * TS_COSINES * TS_THICKNESSES * TS_DEPTHS, ts_axes(thickness, depth));
    return vec2<f32>(m.x, select(-m.y, m.y, from_above));
}

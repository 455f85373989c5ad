// Interpolation of the scattering tables along r (firmament::sky::bruneton4d::r_blend):
// per (μ, ν) texel, after the blend along μ_s, geometric with the fraction of the altitude
// where the radiance falls with altitude (0 < b < a), Bruneton's linear blend in ρ where it
// rises. Channel groups as vec4, per component.

// The filter along r (RFilter): the two rows, the fraction of the way in ρ (t) and in r (w).
struct RFilter {
    z0: u32,
    z1: u32,
    t: f32,
    w: f32,
    // The geometric blend applies (not into the top row: RFilter::log).
    log: bool,
}

fn r_filter(u_r: f32, n: u32) -> RFilter {
    var f = r_filter_snapped(u_r, n);
    f.w = altitude_fraction(f.z0, f.z1, f.t, n, atm.bottom_radius_km / atm.h_km);
    return f;
}

// RFilter::altitude_rows: rows even in altitude (the irradiance table's), w = t.
fn r_filter_altitude_rows(v: f32, n: u32) -> RFilter {
    var f = r_filter_snapped(v, n);
    f.w = f.t;
    return f;
}

// The linear filter with t snapped to a row within MU_S_SAMPLE_SNAP of it (w unset).
fn r_filter_snapped(u: f32, n: u32) -> RFilter {
    var f = r_filter_linear(u, n);
    if (f.t < MU_S_SAMPLE_SNAP) {
        f.z1 = f.z0;
        f.t = 0.0;
    } else if (f.t > 1.0 - MU_S_SAMPLE_SNAP) {
        f.z0 = f.z1;
        f.t = 0.0;
    }
    f.log = f.z1 + 1u < n;
    return f;
}

// Bruneton's linear filter along r alone (w = t, no snap), for the precomputation's ΔJ
// lookups, which the CPU filters linearly in (μ, r) (compute_multiple_scattering).
fn r_filter_linear(u_r: f32, n: u32) -> RFilter {
    let l = lerp_weights(u_r, n);
    var f: RFilter;
    f.z0 = l.i0;
    f.z1 = l.i1;
    f.t = l.t;
    f.w = l.t;
    f.log = false;
    return f;
}

// The fraction of the way in r from row z0 to row z1 at the fraction t in ρ
// (r_blend::altitude_fraction): x = ρ/H, q = r/H = √(x² + k²), k = R_g/H, and
// (q − q0)/(q1 − q0) = t·(x + x0)/(x1 + x0)·(q1 + q0)/(q + q0), without the cancellation of
// r − r0 in f32.
fn altitude_fraction(z0: u32, z1: u32, t: f32, n: u32, bottom_over_h: f32) -> f32 {
    if (z1 == z0 || t == 0.0) {
        return t;
    }
    let step = 1.0 / f32(n - 1u);
    let x0 = f32(z0) * step;
    let x1 = f32(z1) * step;
    let x = x0 + t * (x1 - x0);
    let k2 = bottom_over_h * bottom_over_h;
    let q0 = sqrt(x0 * x0 + k2);
    let q1 = sqrt(x1 * x1 + k2);
    let q = sqrt(x * x + k2);
    return t * (x + x0) / (x1 + x0) * (q1 + q0) / (q + q0);
}

// r_blend::blend of the rows' values a (z0) and b (z1).
fn r_blend(a: vec4<f32>, b: vec4<f32>, f: RFilter) -> vec4<f32> {
    let zero = vec4<f32>(0.0);
    let falls = (b < a) & (b > zero) & vec4<bool>(f.log);
    let tiny = vec4<f32>(1e-37);
    let geometric = a * exp(f.w * log(max(b, tiny) / max(a, tiny)));
    return select(a + f.t * (b - a), geometric, falls);
}

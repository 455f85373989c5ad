// The twilight blend of the scattering and irradiance tables along μ_s
// (firmament::sky::bruneton4d::mu_s_blend): in the first atm.mu_s_twilight_cells cells
// (atm.irradiance_twilight_cells for the irradiance table), a cubic Hermite in ln L through
// the cell's two samples with PCHIP tangents from their outer neighbours; linear where an
// end of the cell is unlit (≤ 0). Channel groups as vec4, per component.

// How close to a sample (in the fraction of a cell) a twilight lookup reads the sample
// (mu_s_blend::SAMPLE_SNAP).
const MU_S_SAMPLE_SNAP: f32 = 1e-5;

// The μ_s filter of MuSFilter::new: (s0, s1, t) of lerp_weights, the snap at a sample in a
// twilight cell, and the outer neighbours.
struct MuSFilter {
    below: u32,
    s0: u32,
    s1: u32,
    above: u32,
    t: f32,
    // The cell takes the twilight blend.
    twilight: bool,
}

fn mu_s_filter(u: f32, n: u32, twilight_cells: u32) -> MuSFilter {
    let l = lerp_weights(u, n);
    var f: MuSFilter;
    f.s0 = l.i0;
    f.s1 = l.i1;
    f.t = l.t;
    let in_twilight = l.i0 < twilight_cells;
    if (in_twilight && l.t < MU_S_SAMPLE_SNAP) {
        f.s1 = l.i0;
        f.t = 0.0;
    } else if (in_twilight && l.t > 1.0 - MU_S_SAMPLE_SNAP) {
        f.s0 = l.i1;
        f.t = 0.0;
    }
    f.below = select(f.s0, f.s0 - 1u, f.s0 > 0u);
    f.above = min(f.s1 + 1u, n - 1u);
    f.twilight = in_twilight && f.t > 0.0;
    return f;
}

// The tangent of ln L at the cell's lower (upper) end from the cell's chord and the outer
// secant (mu_s_blend::tangent, for lit cell ends): their harmonic mean where they agree in
// sign, 0 where they do not, the chord where the outer sample is missing or unlit.
fn mu_s_end_tangent(outer: vec4<f32>, chord: vec4<f32>, outer_ok: vec4<bool>) -> vec4<f32> {
    let same = outer * chord > vec4<f32>(0.0);
    let harmonic = 2.0 * outer * chord / select(vec4<f32>(1.0), outer + chord, same);
    return select(chord, select(vec4<f32>(0.0), harmonic, same), outer_ok);
}

// e^h(t) of the cubic Hermite with h(0) = l0, h(1) = l1, h′(0) = m0, h′(1) = m1
// (mu_s_blend::hermite_exp).
fn hermite_exp(l0: vec4<f32>, l1: vec4<f32>, m0: vec4<f32>, m1: vec4<f32>, t: f32) -> vec4<f32> {
    let chord = l1 - l0;
    let u = 1.0 - t;
    return exp(l0 + t * (chord + u * ((m0 - chord) * u - (m1 - chord) * t)));
}

// mu_s_blend::blend of the cell's samples a (t = 0) and b (t = 1) with the outer neighbours
// below and above (has_below, has_above: whether the table has them).
fn mu_s_blend(below: vec4<f32>, a: vec4<f32>, b: vec4<f32>, above: vec4<f32>, has_below: bool, has_above: bool, t: f32) -> vec4<f32> {
    let zero = vec4<f32>(0.0);
    let lit = a > zero & b > zero;
    let tiny = vec4<f32>(1e-37);
    let la = log(max(a, tiny));
    let lb = log(max(b, tiny));
    let chord = lb - la;
    let below_ok = vec4<bool>(has_below) & below > zero;
    let above_ok = vec4<bool>(has_above) & above > zero;
    let m0 = mu_s_end_tangent(la - log(max(below, tiny)), chord, below_ok);
    let m1 = mu_s_end_tangent(log(max(above, tiny)) - lb, chord, above_ok);
    let linear = a + t * (b - a);
    return select(linear, hermite_exp(la, lb, m0, m1, t), lit);
}

// mu_s_blend at a filter from the four samples it names.
fn mu_s_blend_at(f: MuSFilter, below: vec4<f32>, a: vec4<f32>, b: vec4<f32>, above: vec4<f32>) -> vec4<f32> {
    return mu_s_blend(below, a, b, above, f.below != f.s0, f.above != f.s1, f.t);
}

// Quadrature along view rays (Rust twin precompute/ray.rs): RAY_INTERVALS intervals in pairs
// of two equal ones, placed per (r, μ) row (ray_pair_end_km), integrated pair by pair with an
// exponentially fitted Simpson rule (a Filon-type product rule):
// ∫ g(d)·T(d) dd with the transmittance T factored out as an exponential over each pair and
// g quadratic, exact for g quadratic and T exponential, Simpson's rule as Δτ → 0. Plain
// Simpson on g·T overestimates optically thick intervals (horizontal rays near the ground
// in the blue). The end weight of a pair with Δτ > 2.9 is slightly negative, so the passes
// clamp their sums at 0 (as the CPU does). Per channel, on the four lanes of a channel group
// at once.

// ∫₀² e^{−a·s} L_j(s) ds for the quadratic Lagrange basis on the nodes 0, 1, 2, per lane
// (precompute/ray.rs, `lagrange_exponential_moments`): a series for a < 1 (no cancellation for
// small a), the closed form above. In f32 the switch at a = 1 is also the most accurate one
// (largest error 8e-7 of ∫₀² e^{−a·s} ds over a ∈ [0, 60], against 6e-6 switching at 2 and
// 2e-6 at 0.5); 16 terms of the series, not the CPU's 30: the 17th is below 2e-9.
struct Moments {
    m0: vec4<f32>,
    m1: vec4<f32>,
    m2: vec4<f32>,
}

// For a < 0 by the reflection s → 2 − s: M_j(a) = e^{−2a}·M_{2−j}(−a).
fn lagrange_exponential_moments(a_signed: vec4<f32>) -> Moments {
    let a = abs(a_signed);
    // I_m = ∫₀² s^m e^{−a·s} ds. Series Σ_k (−a)^k/k! · 2^{m+k+1}/(m+k+1), on lanes a < 1
    // (the others evaluate it at a = 1, unused).
    let a_series = min(a, vec4<f32>(1.0));
    var s0 = vec4<f32>(0.0);
    var s1 = vec4<f32>(0.0);
    var s2 = vec4<f32>(0.0);
    var c = vec4<f32>(1.0); // (−a)^k/k! · 2^k
    for (var k = 0u; k < 16u; k++) {
        let kf = f32(k);
        s0 += c * (2.0 / (kf + 1.0));
        s1 += c * (4.0 / (kf + 2.0));
        s2 += c * (8.0 / (kf + 3.0));
        c *= -2.0 * a_series / (kf + 1.0);
    }
    // Closed form, on lanes a ≥ 1 (the others evaluate it at a = 1, unused).
    let b = max(a, vec4<f32>(1.0));
    let e = exp(-2.0 * b);
    let c0 = (1.0 - e) / b;
    let c1 = (1.0 - e * (1.0 + 2.0 * b)) / (b * b);
    let c2 = (2.0 - e * (2.0 + 4.0 * b + 4.0 * b * b)) / (b * b * b);
    let series = a < vec4<f32>(1.0);
    let i0 = select(c0, s0, series);
    let i1 = select(c1, s1, series);
    let i2 = select(c2, s2, series);
    let p0 = 0.5 * (i2 - 3.0 * i1 + 2.0 * i0);
    let p1 = 2.0 * i1 - i2;
    let p2 = 0.5 * (i2 - i1);
    let negative = a_signed < vec4<f32>(0.0);
    let reflect = exp(select(vec4<f32>(0.0), 2.0 * a, negative));
    var m: Moments;
    m.m0 = select(p0, reflect * p2, negative);
    m.m1 = reflect * p1;
    m.m2 = select(p2, reflect * p0, negative);
    return m;
}

// Weights (in units of the pair's step) on the three samples of one pair of intervals, per lane,
// from their transmittances T and the fitted quantity F = β·T (precompute/ray.rs,
// `exponential_simpson_weights`, one pair): a = ln(F_0/F_2)/2 (ln(F_0/F_1) when F_2 = 0, 0
// when F_1 = 0 too; from T the same way where F_0 = 0) clamped to [−30, 300], weights
// T_0·M_0, T_1·e^a·M_1, T_2·e^{2a}·M_2; all 0 when T_0 ≤ 0. T_j·e^{j·a} is taken as
// exp(ln T_j + j·a): e^{2a} alone leaves f32 when T_2 is below ~1e-38.
struct PairWeights {
    w0: vec4<f32>,
    w1: vec4<f32>,
    w2: vec4<f32>,
}

// The decay rate per step through a pair's samples v (see exponential_simpson_weights).
fn pair_rate(v0: vec4<f32>, v1: vec4<f32>, v2: vec4<f32>) -> vec4<f32> {
    let zero = vec4<f32>(0.0);
    let one = vec4<f32>(1.0);
    let l0 = log(select(one, v0, v0 > zero));
    let l1 = log(select(one, v1, v1 > zero));
    let l2 = log(select(one, v2, v2 > zero));
    return select(select(zero, l0 - l1, v1 > zero), 0.5 * (l0 - l2), v2 > zero);
}

fn exponential_simpson_weights(t0: vec4<f32>, t1: vec4<f32>, t2: vec4<f32>, f0: vec4<f32>, f1: vec4<f32>, f2: vec4<f32>) -> PairWeights {
    let zero = vec4<f32>(0.0);
    let one = vec4<f32>(1.0);
    let p0 = t0 > zero;
    let p1 = t1 > zero;
    let p2 = t2 > zero;
    let l1 = log(select(one, t1, p1));
    let l2 = log(select(one, t2, p2));
    let rate = select(pair_rate(t0, t1, t2), pair_rate(f0, f1, f2), f0 > zero);
    let a = clamp(rate, vec4<f32>(-30.0), vec4<f32>(300.0));
    let m = lagrange_exponential_moments(a);
    var w: PairWeights;
    w.w0 = select(zero, t0 * m.m0, p0);
    // Exponents only where T_j > 0 (no infinities in unused lanes).
    w.w1 = select(zero, exp(select(zero, l1 + a, p1)) * m.m1, p0 & p1);
    w.w2 = select(zero, exp(select(zero, l2 + 2.0 * a, p2)) * m.m2, p0 & p2);
    return w;
}

// The length of a texel's view ray, to the ground or the top (RaySamples::new).
fn ray_length_km(t: ScatteringTexel) -> f32 {
    if (t.ground) {
        return distance_to_bottom(t.r_km, t.rho_km, t.mu);
    }
    return distance_to_top(t.r_km, t.rho_km, t.mu);
}

// The end of pair p (0 to RAY_INTERVALS / 2) of the view ray of (r, μ) row `row`, of length
// `length_km`: placed by the CPU's ray_grading (graded by the ray's optical depth) and read
// from the atmosphere data as fractions of the length (bruneton4d/atmosphere.rs,
// pack_for_precompute); pair p's samples are its two ends and their midpoint.
fn ray_pair_end_km(row: u32, p: u32, length_km: f32) -> f32 {
    let pairs = RAY_INTERVALS / 2u;
    if (p == 0u) {
        return 0.0;
    }
    if (p >= pairs) {
        return length_km;
    }
    let per_row = (pairs - 1u + 3u) / 4u;
    let q = p - 1u;
    return data[atm.ray_fractions_offset + row * per_row + q / 4u][q % 4u] * length_km;
}

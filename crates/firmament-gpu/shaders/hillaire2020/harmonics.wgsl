// Real spherical harmonics symmetric about the light's vertical plane, Y_ℓm ∝ P_ℓ^m(μ)·cos mφ
// with m ≥ 0, orthonormal on the sphere (firmament::sky::hillaire2020::harmonics): the
// basis of the multiple-scattering field (degree 0 alone for the isotropic model). The CPU
// evaluates all of them at once; a shader takes one (ℓ, m) at a time, by the same
// recurrences, with no array in private memory.

// The index of (ℓ, m) among the coefficients (harmonics::index).
fn harmonic_index(l: u32, m: u32) -> u32 {
    return l * (l + 1u) / 2u + m;
}

// The (ℓ, m) of coefficient c (the inverse of harmonic_index).
fn harmonic_degree_order(c: u32) -> vec2<u32> {
    var l = 0u;
    while (harmonic_index(l + 1u, 0u) <= c) {
        l++;
    }
    return vec2<u32>(l, c - harmonic_index(l, 0u));
}

// N_ℓm = sqrt((2ℓ + 1)/4π · (ℓ − m)!/(ℓ + m)!), times √2 for m > 0 (harmonics::normalisation,
// computed on the host in f64: HARMONIC_NORMALISATIONS of the prelude).
fn harmonic_normalisation(l: u32, m: u32) -> f32 {
    return HARMONIC_NORMALISATIONS[harmonic_index(l, m)];
}

// Y_ℓm at zenith cosine `mu` and azimuth cosine `cos_phi` from the light's (harmonics::eval
// for one (ℓ, m)): P_m^m = (2m − 1)!!·sin^m θ, P_{m+1}^m = (2m + 1)μ·P_m^m,
// (ℓ − m)P_ℓ^m = (2ℓ − 1)μ·P_{ℓ−1}^m − (ℓ + m − 1)·P_{ℓ−2}^m, without the Condon–Shortley
// phase; cos mφ by the Chebyshev recurrence.
fn harmonic(l: u32, m: u32, mu_in: f32, cos_phi_in: f32) -> f32 {
    let mu = clamp_cosine(mu_in);
    let sin_theta = safe_sqrt(1.0 - mu * mu);
    let cos_phi = clamp_cosine(cos_phi_in);
    var cos_prev = 1.0;
    var cos_m = 1.0;
    if (m >= 1u) {
        cos_m = cos_phi;
    }
    for (var j = 2u; j <= m; j++) {
        let next = 2.0 * cos_phi * cos_m - cos_prev;
        cos_prev = cos_m;
        cos_m = next;
    }
    var p_mm = 1.0;
    for (var j = 1u; j <= m; j++) {
        p_mm *= f32(2u * j - 1u) * sin_theta;
    }
    var p = p_mm;
    if (l > m) {
        var p_prev = p_mm;
        p = f32(2u * m + 1u) * mu * p_mm;
        for (var j = m + 2u; j <= l; j++) {
            let next = (f32(2u * j - 1u) * mu * p - f32(j + m - 1u) * p_prev) / f32(j - m);
            p_prev = p;
            p = next;
        }
    }
    return harmonic_normalisation(l, m) * p * cos_m;
}

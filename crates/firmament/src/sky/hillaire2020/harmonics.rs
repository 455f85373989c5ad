//! Real spherical harmonics symmetric about a plane (the cosine half: Y_ℓm ∝ P_ℓ^m(μ)·cos mφ,
//! m ≥ 0, orthonormal on the sphere), and the Legendre moments of phase functions, for the
//! multiple-scattering field of [`super::multiple_scattering`]: by the Funk–Hecke theorem
//! a phase function acts on each degree ℓ as a factor, ∫ p(ω·v) Y_ℓm(ω) dω = k_ℓ·Y_ℓm(v)
//! with k_ℓ = 2π ∫₋₁¹ p(μ) P_ℓ(μ) dμ (k₀ = 1; Rayleigh's vanish beyond ℓ = 2).
//!
//! The field about a point in the atmosphere is symmetric about the vertical plane through
//! the light, so the sine terms vanish and φ is the azimuth from the light's.

use crate::math::quadrature::GL8;
use crate::medium::PhaseFunction;
use std::f64::consts::PI;
use std::sync::LazyLock;

/// The largest degree of the multiple-scattering field's harmonics.
pub const MAX_DEGREE: usize = 8;

/// Y₀₀ = 1/√(4π).
pub const Y00: f64 = 0.282_094_791_773_878_14;

/// Coefficients up to degree `degree`: (d + 1)(d + 2)/2.
#[inline]
pub const fn coefficient_count(degree: usize) -> usize {
    (degree + 1) * (degree + 2) / 2
}

/// The index of (ℓ, m) among them.
#[inline]
pub const fn index(l: usize, m: usize) -> usize {
    l * (l + 1) / 2 + m
}

/// Every Y_ℓm (ℓ ≤ `degree`, 0 ≤ m ≤ ℓ) at zenith cosine `mu` and azimuth cosine
/// `cos_phi` (from the light's), into `out` (at least [`coefficient_count`] long).
pub fn eval(degree: usize, mu: f64, cos_phi: f64, out: &mut [f64]) {
    let norm = &*NORMALISATIONS;
    if degree == 0 {
        // The isotropic field's one constant (every gather direction asks for it).
        out[0] = norm[0];
        return;
    }
    let mu = mu.clamp(-1.0, 1.0);
    let sin_theta = (1.0 - mu * mu).max(0.0).sqrt();
    let cos_phi = cos_phi.clamp(-1.0, 1.0);
    // cos mφ by the Chebyshev recurrence.
    let mut cos_m = [0.0; MAX_DEGREE + 1];
    cos_m[0] = 1.0;
    if degree >= 1 {
        cos_m[1] = cos_phi;
    }
    for m in 2..=degree {
        cos_m[m] = 2.0 * cos_phi * cos_m[m - 1] - cos_m[m - 2];
    }
    // Associated Legendre functions without the Condon–Shortley phase (the same on both
    // sides of the projection): P_m^m = (2m − 1)!!·sin^m θ, P_{m+1}^m = (2m + 1)μ·P_m^m,
    // (ℓ − m)P_ℓ^m = (2ℓ − 1)μ·P_{ℓ−1}^m − (ℓ + m − 1)·P_{ℓ−2}^m.
    let mut p_mm = 1.0;
    for m in 0..=degree {
        if m > 0 {
            p_mm *= (2 * m - 1) as f64 * sin_theta;
        }
        out[index(m, m)] = norm[index(m, m)] * p_mm * cos_m[m];
        if m == degree {
            break;
        }
        let (mut p_prev, mut p) = (p_mm, (2 * m + 1) as f64 * mu * p_mm);
        out[index(m + 1, m)] = norm[index(m + 1, m)] * p * cos_m[m];
        for l in (m + 2)..=degree {
            let next = ((2 * l - 1) as f64 * mu * p - (l + m - 1) as f64 * p_prev) / (l - m) as f64;
            (p_prev, p) = (p, next);
            out[index(l, m)] = norm[index(l, m)] * p * cos_m[m];
        }
    }
}

/// [`normalisation`] of every (ℓ, m) up to [`MAX_DEGREE`], at [`index`]: computed once (each
/// march step evaluates the harmonics, and the factorial ratios and square roots were half
/// of that).
static NORMALISATIONS: LazyLock<[f64; coefficient_count(MAX_DEGREE)]> = LazyLock::new(|| {
    let mut n = [0.0; coefficient_count(MAX_DEGREE)];
    for l in 0..=MAX_DEGREE {
        for m in 0..=l {
            n[index(l, m)] = normalisation(l, m);
        }
    }
    n
});

/// N_ℓm (see [`normalisation`]) of every (ℓ, m) up to [`MAX_DEGREE`], at [`index`] (the GPU's
/// shaders take them as a constant array).
pub fn normalisations() -> &'static [f64] {
    &NORMALISATIONS[..]
}

/// N_ℓm with ∫ Y_ℓm² dω = 1 for the cosine harmonics: √((2ℓ+1)/4π · (ℓ−m)!/(ℓ+m)!), times
/// √2 for m > 0.
fn normalisation(l: usize, m: usize) -> f64 {
    let mut ratio = 1.0;
    for j in (l - m + 1)..=(l + m) {
        ratio /= j as f64;
    }
    let n = ((2 * l + 1) as f64 / (4.0 * PI) * ratio).sqrt();
    if m > 0 {
        n * 2f64.sqrt()
    } else {
        n
    }
}

/// Legendre polynomials P_0 … P_degree at `mu`, into `out`.
fn legendre(degree: usize, mu: f64, out: &mut [f64]) {
    out[0] = 1.0;
    if degree >= 1 {
        out[1] = mu;
    }
    for l in 2..=degree {
        out[l] = ((2 * l - 1) as f64 * mu * out[l - 1] - (l - 1) as f64 * out[l - 2]) / l as f64;
    }
}

/// k_ℓ = 2π ∫₋₁¹ p(μ)·P_ℓ(μ) dμ for ℓ ≤ `degree` (composite Gauss–Legendre, panels
/// denser towards the forward peak at μ = 1).
pub fn phase_moments(phase: &PhaseFunction, degree: usize) -> Vec<f64> {
    let mut k = vec![0.0; degree + 1];
    let mut p_l = vec![0.0; degree + 1];
    // Panels in s = 1 − μ on a geometric grid from 2 down to 1e-6.
    let mut edges: Vec<f64> = (0..=60)
        .map(|i| 2.0 * (1e-6f64 / 2.0).powf(i as f64 / 60.0))
        .collect();
    edges.push(0.0);
    for w in edges.windows(2) {
        let (s0, s1) = (w[0], w[1]);
        for (s, weight) in GL8.composite(s1, s0, 1) {
            let mu = 1.0 - s;
            legendre(degree, mu, &mut p_l);
            let p = phase.eval(mu);
            for l in 0..=degree {
                k[l] += 2.0 * PI * weight * p * p_l[l];
            }
        }
    }
    k
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::lattice::sphere_directions;

    #[test]
    fn the_harmonics_are_orthonormal() {
        let degree = 4;
        let c = coefficient_count(degree);
        let dirs = sphere_directions(20_000);
        let mut gram = vec![0.0; c * c];
        let mut y = vec![0.0; c];
        for d in &dirs {
            let s = (1.0 - d.z * d.z).max(0.0).sqrt();
            let cos_phi = if s > 0.0 { d.x / s } else { 1.0 };
            eval(degree, d.z, cos_phi, &mut y);
            for i in 0..c {
                for j in 0..c {
                    gram[i * c + j] += y[i] * y[j] * 4.0 * PI / dirs.len() as f64;
                }
            }
        }
        for i in 0..c {
            for j in 0..c {
                let want = if i == j { 1.0 } else { 0.0 };
                assert!(
                    (gram[i * c + j] - want).abs() < 2e-3,
                    "{i} {j}: {}",
                    gram[i * c + j]
                );
            }
        }
    }

    #[test]
    fn phase_moments_match_closed_forms() {
        // Henyey–Greenstein: k_ℓ = g^ℓ; Rayleigh 3/(16π)(1 + μ²): k₀ = 1, k₂ = 1/10, others 0.
        let hg = phase_moments(&PhaseFunction::HenyeyGreenstein { g: 0.76 }, 6);
        for (l, k) in hg.iter().enumerate() {
            assert!((k - 0.76f64.powi(l as i32)).abs() < 1e-6, "HG ℓ {l}: {k}");
        }
        let r = phase_moments(
            &PhaseFunction::Rayleigh {
                depolarization: 0.0,
            },
            4,
        );
        let want = [1.0, 0.0, 0.1, 0.0, 0.0];
        for l in 0..=4 {
            assert!((r[l] - want[l]).abs() < 1e-9, "Rayleigh ℓ {l}: {}", r[l]);
        }
    }

    #[test]
    fn funk_hecke_holds_for_a_phase_function_on_a_harmonic() {
        // ∫ p(ω·v) Y_ℓm(ω) dω = k_ℓ Y_ℓm(v), by direct quadrature.
        let degree = 3;
        let phase = PhaseFunction::HenyeyGreenstein { g: 0.5 };
        let k = phase_moments(&phase, degree);
        let dirs = sphere_directions(200_000);
        let v = crate::math::Vec3::new(0.6, 0.0, 0.8);
        let mut y = vec![0.0; coefficient_count(degree)];
        let mut integral = vec![0.0; y.len()];
        for d in &dirs {
            let s = (1.0 - d.z * d.z).max(0.0).sqrt();
            eval(degree, d.z, if s > 0.0 { d.x / s } else { 1.0 }, &mut y);
            let p = phase.eval(d.dot(v));
            for (i, yi) in y.iter().enumerate() {
                integral[i] += p * yi * 4.0 * PI / dirs.len() as f64;
            }
        }
        eval(degree, 0.8, 1.0, &mut y);
        for l in 0..=degree {
            for m in 0..=l {
                let i = index(l, m);
                assert!(
                    (integral[i] - k[l] * y[i]).abs() < 2e-3,
                    "ℓ {l} m {m}: {} vs {}",
                    integral[i],
                    k[l] * y[i]
                );
            }
        }
    }
}

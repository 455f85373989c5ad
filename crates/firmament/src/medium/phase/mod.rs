//! Phase functions of atmospheric media.
//!
//! Conventions: `cos_theta` is the cosine of the scattering angle between the incident
//! propagation direction and the scattered direction (μ = 1 is forward scattering, so a
//! positive asymmetry `g` means forward-peaked). Values are in 1/sr and every phase function
//! is normalised so that ∫ p dΩ = 1 over the sphere.
//!
//! Sampling (`sample`) inverts the cumulative distribution in μ exactly (closed form, or a
//! safeguarded Newton iteration on a closed-form CDF), so the density of the sampled
//! directions equals `eval` and the result is a deterministic function of `(u1, u2)`.

mod analytic;
mod tabulated;
#[cfg(test)]
mod tests;

use std::f64::consts::PI;
use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::math::quadrature::GL8;
use crate::{Error, Result};
pub use analytic::SCHLICK_G_MAX;
use analytic::{
    cornette_shanks, cs_sample, hg, hg_sample, legendre_into, rayleigh_ab, schlick_k,
    schlick_mean_cosine, INV_4PI,
};
pub use tabulated::TabulatedPhase;

/// A phase function, as written in TOML (`{ type = "henyey-greenstein", g = 0.76 }`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "kebab-case", deny_unknown_fields)]
pub enum PhaseFunction {
    /// p = 1/(4π).
    Isotropic,
    /// Rayleigh scattering with depolarisation factor ρ (Chandrasekhar 1960, §I.18; Bodhaine
    /// et al. 1999 use ρ ≈ 0.0279 for air): with γ = ρ/(2−ρ),
    /// p = 3/(16π(1+2γ))·((1+3γ) + (1−γ)μ²). ρ = 0 gives 3/(16π)(1+μ²).
    Rayleigh {
        /// Depolarisation factor ρ in [0, 0.5).
        #[serde(default)]
        depolarization: f64,
    },
    /// Henyey & Greenstein (1941): p = (1−g²)/(4π(1+g²−2gμ)^{3/2}).
    HenyeyGreenstein {
        /// Asymmetry parameter in (−1, 1).
        g: f64,
    },
    /// Cornette & Shanks (1992), as in Bruneton & Neyret (2008) eq. 4:
    /// p = 3/(8π)·(1−g²)/(2+g²)·(1+μ²)/(1+g²−2gμ)^{3/2}.
    CornetteShanks {
        /// Shape parameter in (−1, 1) (not the mean cosine; see [`PhaseFunction::mean_cosine`]).
        g: f64,
    },
    /// Schlick's approximation of Henyey–Greenstein (Blasi, Le Saëc & Schlick 1993):
    /// p = (1−k²)/(4π(1−kμ)²), k = 1.55g − 0.55g³.
    Schlick {
        /// HG-equivalent asymmetry in (−1, 1).
        g: f64,
    },
    /// Two Henyey–Greenstein lobes, w·HG(g1) + (1−w)·HG(g2) (Hillaire 2016, clouds).
    DualLobeHg {
        /// First lobe asymmetry in (−1, 1).
        g1: f64,
        /// Second lobe asymmetry in (−1, 1).
        g2: f64,
        /// Weight of the first lobe in [0, 1].
        weight: f64,
    },
    /// Read from a text file of `angle_deg value` lines, normalised on load.
    Tabulated(TabulatedPhase),
}

impl PhaseFunction {
    /// A tabulated phase function read from `path` now (relative to the working directory).
    pub fn load_tabulated(path: impl AsRef<Path>) -> Result<Self> {
        Ok(PhaseFunction::Tabulated(TabulatedPhase::load(path)?))
    }

    /// Loads external data (the tabulated file, relative to `base_dir`, normally the TOML
    /// file's directory). A no-op for analytic phase functions or already loaded tables.
    pub fn prepare(&mut self, base_dir: &Path) -> Result<()> {
        match self {
            PhaseFunction::Tabulated(t) => t.prepare(base_dir),
            _ => Ok(()),
        }
    }

    /// Whether `eval`/`sample` can be called (false only for an unloaded table).
    pub fn is_prepared(&self) -> bool {
        match self {
            PhaseFunction::Tabulated(t) => t.is_loaded(),
            _ => true,
        }
    }

    /// Checks parameter ranges; `field` is the dotted path of this phase function
    /// (e.g. `constituents[1].phase`), to which the parameter name is appended.
    pub fn validate(&self, field: &str) -> Result<()> {
        let check_g = |name: &str, g: f64| {
            if g > -1.0 && g < 1.0 {
                Ok(())
            } else {
                Err(Error::invalid(
                    format!("{field}.{name}"),
                    g,
                    "expected in the open interval (-1, 1)",
                ))
            }
        };
        match self {
            PhaseFunction::Isotropic => Ok(()),
            PhaseFunction::Rayleigh { depolarization } => {
                if (0.0..0.5).contains(depolarization) {
                    Ok(())
                } else {
                    Err(Error::invalid(
                        format!("{field}.depolarization"),
                        depolarization,
                        "expected in [0, 0.5)",
                    ))
                }
            }
            PhaseFunction::HenyeyGreenstein { g } | PhaseFunction::CornetteShanks { g } => {
                check_g("g", *g)
            }
            PhaseFunction::Schlick { g } => {
                // k = 1.55g − 0.55g³ reaches ±1 at |g| = SCHLICK_G_MAX (and exceeds it beyond),
                // where p = (1−k²)/(4π(1−kμ)²) stops being a density.
                if g.abs() < SCHLICK_G_MAX {
                    Ok(())
                } else {
                    Err(Error::invalid(
                        format!("{field}.g"),
                        g,
                        format!(
                            "expected in the open interval (-{SCHLICK_G_MAX:.4}, {SCHLICK_G_MAX:.4}): Schlick's k = 1.55g - 0.55g^3 reaches 1 there"
                        ),
                    ))
                }
            }
            PhaseFunction::DualLobeHg { g1, g2, weight } => {
                check_g("g1", *g1)?;
                check_g("g2", *g2)?;
                if (0.0..=1.0).contains(weight) {
                    Ok(())
                } else {
                    Err(Error::invalid(
                        format!("{field}.weight"),
                        weight,
                        "expected in [0, 1]",
                    ))
                }
            }
            PhaseFunction::Tabulated(t) => {
                if t.file.as_os_str().is_empty() {
                    Err(Error::invalid(
                        format!("{field}.file"),
                        "\"\"",
                        "expected a file path",
                    ))
                } else {
                    Ok(())
                }
            }
        }
    }

    /// Phase function value (1/sr) for the cosine of the scattering angle.
    ///
    /// # Panics
    /// For a tabulated phase function that has not been [`prepare`](Self::prepare)d.
    #[inline]
    pub fn eval(&self, cos_theta: f64) -> f64 {
        let mu = cos_theta.clamp(-1.0, 1.0);
        match self {
            PhaseFunction::Isotropic => INV_4PI,
            PhaseFunction::Rayleigh { depolarization } => {
                // Chandrasekhar (1960): 3/(16π(1+2γ))·(a + bμ²), and 4(1+2γ) = 3a + b.
                let (a, b) = rayleigh_ab(*depolarization);
                3.0 / (4.0 * PI * (3.0 * a + b)) * (a + b * mu * mu)
            }
            PhaseFunction::HenyeyGreenstein { g } => hg(*g, mu),
            PhaseFunction::CornetteShanks { g } => cornette_shanks(*g, mu),
            PhaseFunction::Schlick { g } => {
                // Blasi, Le Saëc & Schlick (1993).
                let k = schlick_k(*g);
                let d = 1.0 - k * mu;
                (1.0 - k * k) * INV_4PI / (d * d)
            }
            PhaseFunction::DualLobeHg { g1, g2, weight } => {
                weight * hg(*g1, mu) + (1.0 - weight) * hg(*g2, mu)
            }
            PhaseFunction::Tabulated(t) => t.data().eval(mu),
        }
    }

    /// [`PhaseFunction::eval`] with the asymmetry parameters scaled by `scale` ∈ [0, 1]
    /// (Henyey–Greenstein, its dual lobe, Schlick, Cornette–Shanks; the others unchanged):
    /// the phase of a higher octave of multiple scattering (Wrenninge 2015), g·cⁿ.
    #[inline]
    pub fn eval_scaled(&self, cos_theta: f64, scale: f64) -> f64 {
        if scale == 1.0 {
            return self.eval(cos_theta);
        }
        let mu = cos_theta.clamp(-1.0, 1.0);
        match self {
            PhaseFunction::HenyeyGreenstein { g } => hg(g * scale, mu),
            PhaseFunction::CornetteShanks { g } => cornette_shanks(g * scale, mu),
            PhaseFunction::Schlick { g } => PhaseFunction::Schlick { g: g * scale }.eval(mu),
            PhaseFunction::DualLobeHg { g1, g2, weight } => {
                weight * hg(g1 * scale, mu) + (1.0 - weight) * hg(g2 * scale, mu)
            }
            other => other.eval(mu),
        }
    }

    /// Samples a scattering direction from two uniform numbers in [0, 1]: returns
    /// (cos θ, φ) with φ = 2π·u2, distributed with density `eval` over the sphere.
    ///
    /// # Panics
    /// For a tabulated phase function that has not been [`prepare`](Self::prepare)d.
    pub fn sample(&self, u1: f64, u2: f64) -> (f64, f64) {
        let u = u1.clamp(0.0, 1.0);
        let cos_theta = match self {
            PhaseFunction::Isotropic => 2.0 * u - 1.0,
            PhaseFunction::Rayleigh { depolarization } => {
                // CDF (a(μ+1) + b(μ³+1)/3)/(2a + 2b/3) = u ⇔ μ³ + pμ + q = 0 with p = 3a/b,
                // q = −(p+1)(2u−1); one real root (p > 0), Cardano in a cancellation-free form.
                let (a, b) = rayleigh_ab(*depolarization);
                let p = 3.0 * a / b;
                let q = -(p + 1.0) * (2.0 * u - 1.0);
                let disc = (0.25 * q * q + p * p * p / 27.0).sqrt();
                let big_a = -q.signum() * (0.5 * q.abs() + disc).cbrt();
                let mut mu = big_a - p / (3.0 * big_a);
                mu -= (mu * mu * mu + p * mu + q) / (3.0 * mu * mu + p); // one Newton polish
                mu.clamp(-1.0, 1.0)
            }
            PhaseFunction::HenyeyGreenstein { g } => hg_sample(*g, u),
            PhaseFunction::CornetteShanks { g } => cs_sample(*g, u),
            PhaseFunction::Schlick { g } => {
                // CDF (1−k)(1+μ)/(2(1−kμ)) = u ⇔ μ = (v+k)/(1+kv), v = 2u−1.
                let k = schlick_k(*g);
                let v = 2.0 * u - 1.0;
                ((v + k) / (1.0 + k * v)).clamp(-1.0, 1.0)
            }
            PhaseFunction::DualLobeHg { g1, g2, weight } => {
                let w = *weight;
                if u < w {
                    hg_sample(*g1, u / w)
                } else if w < 1.0 {
                    hg_sample(*g2, ((u - w) / (1.0 - w)).min(1.0))
                } else {
                    hg_sample(*g1, 1.0)
                }
            }
            // The table's CDF runs in θ (from μ = 1); 1 − u keeps μ increasing with u1.
            PhaseFunction::Tabulated(t) => t.data().sample_cos(1.0 - u),
        };
        (cos_theta, 2.0 * PI * u2)
    }

    /// Mean cosine of the scattering angle (asymmetry parameter), ∫ p μ dΩ.
    pub fn mean_cosine(&self) -> f64 {
        match self {
            PhaseFunction::Isotropic | PhaseFunction::Rayleigh { .. } => 0.0,
            PhaseFunction::HenyeyGreenstein { g } => *g,
            // E_HG[μ+μ³]/E_HG[1+μ²] with E_HG[P_l] = g^l: 3g(4+g²)/(5(2+g²)).
            PhaseFunction::CornetteShanks { g } => 3.0 * g * (4.0 + g * g) / (5.0 * (2.0 + g * g)),
            PhaseFunction::Schlick { g } => schlick_mean_cosine(schlick_k(*g)),
            PhaseFunction::DualLobeHg { g1, g2, weight } => weight * g1 + (1.0 - weight) * g2,
            PhaseFunction::Tabulated(t) => t.data().mean_cosine,
        }
    }

    /// The forward peak cut off (Potter 1970, "The delta function approximation in
    /// radiative transfer theory", J. Atmos. Sci. 27): the phase's value p(θ_c) at the cone
    /// θ < θ_c inside which p − p(θ_c) holds the fraction `fraction` of the scattering, so
    /// that min(p, p(θ_c)) is the phase of what a δ-scaling with f = `fraction` keeps
    /// (integrating to 1 − f). `fraction` ≤ 0: p's forward value (nothing cut).
    pub fn truncated_forward_value(&self, fraction: f64) -> f64 {
        if fraction <= 0.0 {
            return self.eval(1.0);
        }
        // 2π ∫_c^1 (p(μ) − p(c)) dμ, with 1 − μ = e^s so the peak is resolved.
        let cut = |c: f64| {
            let (lo, hi) = ((1e-9f64).ln(), (1.0 - c).max(1e-9).ln());
            let n = 512;
            let ds = (hi - lo) / n as f64;
            let pc = self.eval(c);
            (0..n)
                .map(|i| {
                    let e = (lo + (i as f64 + 0.5) * ds).exp();
                    (self.eval(1.0 - e) - pc) * e * ds
                })
                .sum::<f64>()
                * 2.0
                * PI
        };
        // The cut grows as the cone widens (c falls) while p falls towards its minimum.
        let (mut lo, mut hi) = (-1.0, 1.0);
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if cut(mid) > fraction {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        self.eval(lo)
    }

    /// Legendre moments χ_l = 2π ∫ p(μ) P_l(μ) dμ for l = 0 … n−1 (χ_0 = 1, χ_1 = mean
    /// cosine); p = Σ (2l+1) χ_l P_l / (4π). Exact for HG (χ_l = g^l) and its mixture,
    /// numerical (composite Gauss–Legendre in θ) otherwise.
    pub fn legendre_coefficients(&self, n: usize) -> Vec<f64> {
        match self {
            PhaseFunction::Isotropic => (0..n).map(|l| if l == 0 { 1.0 } else { 0.0 }).collect(),
            PhaseFunction::HenyeyGreenstein { g } => (0..n).map(|l| g.powi(l as i32)).collect(),
            PhaseFunction::DualLobeHg { g1, g2, weight } => (0..n)
                .map(|l| weight * g1.powi(l as i32) + (1.0 - weight) * g2.powi(l as i32))
                .collect(),
            _ => {
                let mut out = vec![0.0; n];
                let mut pl = vec![0.0; n];
                for (t, w) in GL8.composite(0.0, PI, 2048) {
                    let mu = t.cos();
                    let w = w * 2.0 * PI * self.eval(mu) * t.sin();
                    legendre_into(mu, &mut pl);
                    out.iter_mut().zip(&pl).for_each(|(o, p)| *o += w * p);
                }
                out
            }
        }
    }
}

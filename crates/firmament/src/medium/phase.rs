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

use std::f64::consts::PI;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use serde::{Deserialize, Serialize};

use crate::{Error, Result};

const INV_4PI: f64 = 1.0 / (4.0 * PI);

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

/// A phase function tabulated against the scattering angle, read from a text file.
///
/// In TOML: `{ type = "tabulated", file = "path" }`; the path is kept as written and is
/// resolved against the TOML file's directory by [`PhaseFunction::prepare`]. The file holds
/// one `angle_deg value` pair per line (whitespace or comma separated, `#` starts a comment),
/// angles strictly increasing in [0, 180]. Values are interpolated linearly in θ; if the
/// table does not start at 0° or end at 180° the end values are extended as constants.
#[derive(Clone, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TabulatedPhase {
    /// The file, as written.
    pub file: PathBuf,
    #[serde(skip)]
    data: Option<Arc<TabulatedData>>,
}

impl std::fmt::Debug for TabulatedPhase {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("TabulatedPhase")
            .field("file", &self.file)
            .field("points", &self.data.as_ref().map(|d| d.theta.len()))
            .finish()
    }
}

impl PartialEq for TabulatedPhase {
    fn eq(&self, other: &Self) -> bool {
        self.file == other.file && self.data.as_deref() == other.data.as_deref()
    }
}

/// Loaded, normalised table.
#[derive(Clone, Debug, PartialEq)]
struct TabulatedData {
    /// Scattering angles in radians, strictly increasing from 0 to π.
    theta: Vec<f64>,
    /// Normalised values (1/sr).
    value: Vec<f64>,
    /// Cumulative probability at each knot (0 … 1).
    cdf: Vec<f64>,
    /// ∫ p μ dΩ.
    mean_cosine: f64,
}

impl TabulatedPhase {
    /// An unloaded table referring to `file`; call [`TabulatedPhase::prepare`] before use.
    pub fn new(file: impl Into<PathBuf>) -> Self {
        Self {
            file: file.into(),
            data: None,
        }
    }

    /// Read and normalise `path` (relative paths are relative to the working directory).
    pub fn load(path: impl AsRef<Path>) -> Result<Self> {
        let mut t = Self::new(path.as_ref());
        t.prepare(Path::new(""))?;
        Ok(t)
    }

    /// Load the file, relative to `base_dir` unless absolute. Does nothing if already loaded.
    pub fn prepare(&mut self, base_dir: &Path) -> Result<()> {
        if self.data.is_some() {
            return Ok(());
        }
        let path = if self.file.is_absolute() {
            self.file.clone()
        } else {
            base_dir.join(&self.file)
        };
        let file_err = |reason: String| Error::File {
            path: path.display().to_string(),
            reason,
        };
        if self.file.as_os_str().is_empty() {
            return Err(file_err(
                "no file given for the tabulated phase function".into(),
            ));
        }
        let text = std::fs::read_to_string(&path).map_err(|e| file_err(e.to_string()))?;
        let (angles, values) = parse_table(&text).map_err(file_err)?;
        let data = TabulatedData::build(&angles, &values).map_err(file_err)?;
        self.data = Some(Arc::new(data));
        Ok(())
    }

    /// Whether the table has been loaded.
    pub fn is_loaded(&self) -> bool {
        self.data.is_some()
    }

    /// Knot angles in radians (0 … π), empty if not loaded.
    pub fn angles(&self) -> &[f64] {
        self.data.as_deref().map_or(&[], |d| &d.theta)
    }

    /// Normalised knot values in 1/sr, empty if not loaded.
    pub fn values(&self) -> &[f64] {
        self.data.as_deref().map_or(&[], |d| &d.value)
    }

    fn data(&self) -> &TabulatedData {
        self.data.as_deref().unwrap_or_else(|| {
            panic!(
                "tabulated phase function {} used before prepare()",
                self.file.display()
            )
        })
    }
}

/// Parse `angle_deg value` lines; returns the reason on failure.
fn parse_table(text: &str) -> std::result::Result<(Vec<f64>, Vec<f64>), String> {
    let mut angles = Vec::new();
    let mut values = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let fields: Vec<&str> = line
            .split(|c: char| c.is_whitespace() || c == ',')
            .filter(|s| !s.is_empty())
            .collect();
        if fields.len() != 2 {
            return Err(format!(
                "line {}: expected `angle_deg value`, found `{line}`",
                n + 1
            ));
        }
        let num = |s: &str| -> std::result::Result<f64, String> {
            let v: f64 = s
                .parse()
                .map_err(|_| format!("line {}: `{s}` is not a number", n + 1))?;
            if v.is_finite() {
                Ok(v)
            } else {
                Err(format!("line {}: `{s}` is not finite", n + 1))
            }
        };
        let (a, v) = (num(fields[0])?, num(fields[1])?);
        if !(0.0..=180.0).contains(&a) {
            return Err(format!(
                "line {}: angle {a} outside [0, 180] degrees",
                n + 1
            ));
        }
        if let Some(&prev) = angles.last() {
            if a <= prev {
                return Err(format!(
                    "line {}: angle {a} not greater than the previous angle {prev}",
                    n + 1
                ));
            }
        }
        if v < 0.0 {
            return Err(format!("line {}: negative phase function value {v}", n + 1));
        }
        angles.push(a);
        values.push(v);
    }
    if angles.len() < 2 {
        return Err(format!(
            "need at least 2 `angle_deg value` points, found {}",
            angles.len()
        ));
    }
    Ok((angles, values))
}

/// 2π ∫_{θa}^{θ} (pa + m(t−θa)) sin t dt, exact for a piecewise-linear p(θ).
fn segment_integral(ta: f64, pa: f64, m: f64, t: f64) -> f64 {
    // cos ta − cos t = 2 sin((t+ta)/2) sin((t−ta)/2), stable for t ≈ ta.
    let dcos = 2.0 * (0.5 * (t + ta)).sin() * (0.5 * (t - ta)).sin();
    2.0 * PI * (pa * dcos + m * (t.sin() - ta.sin() - (t - ta) * t.cos()))
}

/// 2π ∫_{θa}^{θb} (pa + m(t−θa)) cos t sin t dt, exact.
fn segment_moment(ta: f64, tb: f64, pa: f64, m: f64) -> f64 {
    let h = tb - ta;
    let c = -0.25 * ((2.0 * tb).cos() - (2.0 * ta).cos());
    let l = -0.25 * h * (2.0 * tb).cos() + 0.125 * ((2.0 * tb).sin() - (2.0 * ta).sin());
    2.0 * PI * (pa * c + m * l)
}

impl TabulatedData {
    fn build(angles_deg: &[f64], values: &[f64]) -> std::result::Result<Self, String> {
        let mut theta: Vec<f64> = angles_deg.iter().map(|a| a.to_radians()).collect();
        let mut value = values.to_vec();
        if theta[0] > 0.0 {
            theta.insert(0, 0.0);
            value.insert(0, value[0]);
        }
        if *theta.last().unwrap() < PI {
            theta.push(PI);
            value.push(*value.last().unwrap());
        }
        *theta.last_mut().unwrap() = PI; // 180° exactly, whatever the rounding
        let n = theta.len();
        let mut cdf = vec![0.0; n];
        let mut moment = 0.0;
        for i in 0..n - 1 {
            let (ta, tb) = (theta[i], theta[i + 1]);
            let m = (value[i + 1] - value[i]) / (tb - ta);
            cdf[i + 1] = cdf[i] + segment_integral(ta, value[i], m, tb);
            moment += segment_moment(ta, tb, value[i], m);
        }
        let total = cdf[n - 1];
        if !(total > 0.0 && total.is_finite()) {
            return Err("phase function values are all zero".into());
        }
        value.iter_mut().for_each(|v| *v /= total);
        cdf.iter_mut().for_each(|c| *c /= total);
        cdf[n - 1] = 1.0;
        Ok(Self {
            theta,
            value,
            cdf,
            mean_cosine: moment / total,
        })
    }

    #[inline]
    fn eval(&self, cos_theta: f64) -> f64 {
        let t = cos_theta.clamp(-1.0, 1.0).acos();
        let n = self.theta.len();
        let i = self.theta.partition_point(|&x| x <= t).clamp(1, n - 1) - 1;
        let (ta, tb) = (self.theta[i], self.theta[i + 1]);
        let f = ((t - ta) / (tb - ta)).clamp(0.0, 1.0);
        self.value[i] + f * (self.value[i + 1] - self.value[i])
    }

    fn sample_cos(&self, u: f64) -> f64 {
        let n = self.theta.len();
        let i = self.cdf.partition_point(|&c| c <= u).clamp(1, n - 1) - 1;
        let (ta, tb) = (self.theta[i], self.theta[i + 1]);
        let (pa, pb) = (self.value[i], self.value[i + 1]);
        let m = (pb - pa) / (tb - ta);
        let target = u - self.cdf[i];
        let mass = self.cdf[i + 1] - self.cdf[i];
        let guess = if mass > 0.0 {
            ta + (tb - ta) * (target / mass)
        } else {
            ta
        };
        let t = solve_increasing(ta, tb, guess, |t| {
            (
                segment_integral(ta, pa, m, t) - target,
                2.0 * PI * (pa + m * (t - ta)) * t.sin(),
            )
        });
        t.cos()
    }
}

/// Solves F(x) = 0 for a non-decreasing F on [lo, hi] (F(lo) ≤ 0 ≤ F(hi)) by Newton's
/// method safeguarded with bisection; `fdf` returns (F(x), F′(x)).
fn solve_increasing(mut lo: f64, mut hi: f64, x0: f64, fdf: impl Fn(f64) -> (f64, f64)) -> f64 {
    let mut x = x0.clamp(lo, hi);
    for _ in 0..200 {
        let (f, df) = fdf(x);
        if f == 0.0 {
            return x;
        }
        if f < 0.0 {
            lo = x;
        } else {
            hi = x;
        }
        let mut next = x - f / df;
        if !(next > lo && next < hi) {
            next = 0.5 * (lo + hi);
        }
        if (next - x).abs() <= 4.0 * f64::EPSILON * (1.0 + x.abs()) || hi - lo <= 4.0 * f64::EPSILON
        {
            return next;
        }
        x = next;
    }
    x
}

/// Henyey & Greenstein (1941).
#[inline]
fn hg(g: f64, mu: f64) -> f64 {
    let d = 1.0 + g * g - 2.0 * g * mu;
    (1.0 - g * g) * INV_4PI / (d * d.sqrt())
}

/// Exact inverse CDF of HG in μ. The usual form μ = (1+g²−((1−g²)/(1−g+2gu))²)/(2g)
/// (e.g. Pharr, Jakob & Humphreys, PBRT 4th ed. §11.3.1) expanded with v = 2u−1 so that it
/// stays accurate for g → 0 (no division by g).
#[inline]
fn hg_sample(g: f64, u: f64) -> f64 {
    let v = 2.0 * u - 1.0;
    let d = 1.0 + g * v;
    let num = v + 0.5 * g * (v * v + 3.0) + g * g * v + 0.5 * g * g * g * (v * v - 1.0);
    (num / (d * d)).clamp(-1.0, 1.0)
}

/// Largest |g| for which Schlick's k = 1.55g − 0.55g³ stays below 1 in magnitude: the root
/// of 0.55g² + 0.55g − 1 = 0, (√2.5025 − 0.55)/1.1 ≈ 0.93812.
pub const SCHLICK_G_MAX: f64 = 0.938_117_456_323_306_7;

/// Schlick's k from the HG asymmetry (Blasi, Le Saëc & Schlick 1993).
#[inline]
fn schlick_k(g: f64) -> f64 {
    1.55 * g - 0.55 * g * g * g
}

/// Rayleigh coefficients (a, b) of p ∝ a + bμ², with γ = ρ/(2−ρ) (Chandrasekhar 1960).
#[inline]
fn rayleigh_ab(rho: f64) -> (f64, f64) {
    let gamma = rho / (2.0 - rho);
    (1.0 + 3.0 * gamma, 1.0 - gamma)
}

/// Cornette & Shanks (1992); Bruneton & Neyret (2008) eq. 4.
#[inline]
fn cornette_shanks(g: f64, mu: f64) -> f64 {
    let g2 = g * g;
    let d = 1.0 + g2 - 2.0 * g * mu;
    3.0 / (8.0 * PI) * (1.0 - g2) / (2.0 + g2) * (1.0 + mu * mu) / (d * d.sqrt())
}

/// 8-point Gauss–Legendre nodes and weights on [−1, 1] (positive half).
const GL8_X: [f64; 4] = [
    0.183_434_642_495_649_8,
    0.525_532_409_916_329,
    0.796_666_477_413_626_7,
    0.960_289_856_497_536_3,
];
const GL8_W: [f64; 4] = [
    0.362_683_783_378_362,
    0.313_706_645_877_887_3,
    0.222_381_034_453_374_5,
    0.101_228_536_290_376_3,
];

/// ∫_a^b f by `panels` panels of 8-point Gauss–Legendre.
fn gauss_legendre(a: f64, b: f64, panels: usize, f: impl Fn(f64) -> f64) -> f64 {
    let h = (b - a) / panels as f64;
    let mut sum = 0.0;
    for k in 0..panels {
        let c = a + (k as f64 + 0.5) * h;
        for j in 0..4 {
            let dx = 0.5 * h * GL8_X[j];
            sum += GL8_W[j] * (f(c - dx) + f(c + dx));
        }
    }
    0.5 * h * sum
}

/// Cumulative distribution in μ of Cornette–Shanks for g ≥ 0: P(cos θ ≤ μ).
fn cs_cdf(g: f64, mu: f64) -> f64 {
    if g < 0.05 {
        // Smooth integrand (pole of (1+g²−2gμ)^{-3/2} at μ ≥ 9.5): Gauss–Legendre is exact
        // to rounding, and avoids the cancellation of the closed form below.
        return gauss_legendre(-1.0, mu, 2, |t| 2.0 * PI * cornette_shanks(g, t));
    }
    // With s = 1+g²−2gμ, (1+μ²) = (B − 2As + s²)/(4g²), A = 1+g², B = 4g²+A², dμ = −ds/(2g):
    // ∫(1+μ²)s^{-3/2}dμ = −1/(8g³) G(s), G(s) = −2B s^{-1/2} − 4A s^{1/2} + (2/3) s^{3/2}.
    let a = 1.0 + g * g;
    let b = 4.0 * g * g + a * a;
    let big_g = |s: f64| {
        let r = s.sqrt();
        -2.0 * b / r - 4.0 * a * r + 2.0 / 3.0 * s * r
    };
    let s_lo = (1.0 + g) * (1.0 + g);
    let s_hi = (1.0 - g) * (1.0 - g);
    let s = (a - 2.0 * g * mu).max(s_hi);
    let g_lo = big_g(s_lo);
    (g_lo - big_g(s)) / (g_lo - big_g(s_hi))
}

/// Exact inverse CDF of Cornette–Shanks (Newton on the closed-form CDF, started from HG).
fn cs_sample(g: f64, u: f64) -> f64 {
    if g < 0.0 {
        // p_{−g}(μ) = p_g(−μ).
        return -cs_sample(-g, 1.0 - u);
    }
    solve_increasing(-1.0, 1.0, hg_sample(g, u), |mu| {
        (cs_cdf(g, mu) - u, 2.0 * PI * cornette_shanks(g, mu))
    })
}

/// Schlick mean cosine: 1/k − (1−k²)·atanh(k)/k², by its series Σ 2k^{2m+1}/((2m+1)(2m+3))
/// for small k to avoid cancellation.
fn schlick_mean_cosine(k: f64) -> f64 {
    if k.abs() < 0.1 {
        let k2 = k * k;
        let mut term = k;
        let mut sum = 0.0;
        for m in 0..12 {
            let m = m as f64;
            sum += 2.0 * term / ((2.0 * m + 1.0) * (2.0 * m + 3.0));
            term *= k2;
        }
        sum
    } else {
        1.0 / k - (1.0 - k * k) * k.atanh() / (k * k)
    }
}

/// Legendre polynomials P_0 … P_{n−1} at x into `out`.
fn legendre_into(x: f64, out: &mut [f64]) {
    for l in 0..out.len() {
        out[l] = match l {
            0 => 1.0,
            1 => x,
            _ => ((2 * l - 1) as f64 * x * out[l - 1] - (l - 1) as f64 * out[l - 2]) / l as f64,
        };
    }
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
                let panels = 2048;
                let h = PI / panels as f64;
                for k in 0..panels {
                    let c = (k as f64 + 0.5) * h;
                    for j in 0..4 {
                        for t in [c - 0.5 * h * GL8_X[j], c + 0.5 * h * GL8_X[j]] {
                            let mu = t.cos();
                            let w = 0.5 * h * GL8_W[j] * 2.0 * PI * self.eval(mu) * t.sin();
                            legendre_into(mu, &mut pl);
                            out.iter_mut().zip(&pl).for_each(|(o, p)| *o += w * p);
                        }
                    }
                }
                out
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicUsize, Ordering};

    /// ∫ f dΩ: composite 8-point Gauss–Legendre in θ (μ = cos θ), fine enough for g = 0.95.
    fn sphere_integral(f: impl Fn(f64) -> f64) -> f64 {
        gauss_legendre(0.0, PI, 4096, |t| 2.0 * PI * f(t.cos()) * t.sin())
    }

    /// Probability that μ ∈ [a, b].
    fn bin_probability(p: &PhaseFunction, a: f64, b: f64) -> f64 {
        gauss_legendre(b.acos(), a.acos(), 256, |t| {
            2.0 * PI * p.eval(t.cos()) * t.sin()
        })
    }

    fn analytic_cases() -> Vec<PhaseFunction> {
        let mut v = vec![
            PhaseFunction::Isotropic,
            PhaseFunction::Rayleigh {
                depolarization: 0.0,
            },
            PhaseFunction::Rayleigh {
                depolarization: 0.0279,
            },
            PhaseFunction::Rayleigh {
                depolarization: 0.45,
            },
        ];
        for g in [-0.95, -0.5, -0.01, 0.0, 1e-7, 0.03, 0.3, 0.76, 0.9, 0.95] {
            v.push(PhaseFunction::HenyeyGreenstein { g });
            v.push(PhaseFunction::CornetteShanks { g });
            v.push(PhaseFunction::Schlick {
                g: g.clamp(-0.93, 0.93),
            });
        }
        v.push(PhaseFunction::DualLobeHg {
            g1: 0.8,
            g2: -0.5,
            weight: 0.5,
        });
        v.push(PhaseFunction::DualLobeHg {
            g1: 0.95,
            g2: 0.2,
            weight: 0.9,
        });
        v.push(PhaseFunction::DualLobeHg {
            g1: 0.5,
            g2: -0.3,
            weight: 1.0,
        });
        v.push(PhaseFunction::DualLobeHg {
            g1: 0.5,
            g2: -0.3,
            weight: 0.0,
        });
        v
    }

    static COUNTER: AtomicUsize = AtomicUsize::new(0);

    fn temp_file(name: &str, contents: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!(
            "firmament-phase-{}-{}",
            std::process::id(),
            COUNTER.fetch_add(1, Ordering::Relaxed)
        ));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join(name);
        std::fs::write(&path, contents).unwrap();
        path
    }

    /// An HG(g) table every 0.5°, scaled by an arbitrary factor (normalised on load).
    fn hg_table(g: f64) -> String {
        let mut s = String::from("# angle_deg value\n\n");
        for i in 0..=360 {
            let a = i as f64 * 0.5;
            s.push_str(&format!(
                "{a} {}  # comment\n",
                3.7 * hg(g, a.to_radians().cos())
            ));
        }
        s
    }

    fn all_cases() -> Vec<PhaseFunction> {
        let mut v = analytic_cases();
        v.push(PhaseFunction::load_tabulated(temp_file("hg.txt", &hg_table(0.7))).unwrap());
        // Coarse, partial table: flat extension to 0° and 180°, a zero-valued segment.
        v.push(
            PhaseFunction::load_tabulated(temp_file(
                "coarse.txt",
                "10, 5\n40 1\n90 0\n100 0\n150 2.5\n",
            ))
            .unwrap(),
        );
        v
    }

    #[test]
    fn phase_every_variant_integrates_to_one() {
        for p in all_cases() {
            p.validate("phase").unwrap();
            let total = sphere_integral(|mu| p.eval(mu));
            assert!((total - 1.0).abs() < 1e-4, "{p:?}: ∫p dΩ = {total}");
        }
    }

    #[test]
    fn phase_mean_cosine_matches_numeric() {
        for p in all_cases() {
            let numeric = sphere_integral(|mu| mu * p.eval(mu));
            assert!(
                (numeric - p.mean_cosine()).abs() < 1e-4,
                "{p:?}: numeric {numeric} vs {}",
                p.mean_cosine()
            );
        }
        for g in [-0.9, 0.0, 0.5, 0.95] {
            let p = PhaseFunction::HenyeyGreenstein { g };
            assert_eq!(p.mean_cosine(), g);
            assert!((sphere_integral(|mu| mu * p.eval(mu)) - g).abs() < 1e-5);
        }
    }

    #[test]
    fn phase_legendre_coefficients() {
        for p in all_cases() {
            let chi = p.legendre_coefficients(4);
            assert!((chi[0] - 1.0).abs() < 1e-4, "{p:?}: {chi:?}");
            assert!((chi[1] - p.mean_cosine()).abs() < 1e-4, "{p:?}: {chi:?}");
        }
        // Rayleigh, ρ = 0: 1 + μ² = (4/3)P_0 + (2/3)P_2 → χ_2 = 1/10.
        let chi = PhaseFunction::Rayleigh {
            depolarization: 0.0,
        }
        .legendre_coefficients(3);
        assert!((chi[2] - 0.1).abs() < 1e-9, "{chi:?}");
    }

    #[test]
    fn phase_rayleigh_and_cornette_shanks_limits() {
        let r = PhaseFunction::Rayleigh {
            depolarization: 0.0,
        };
        let cs = PhaseFunction::CornetteShanks { g: 0.0 };
        for i in 0..=100 {
            let mu = -1.0 + i as f64 * 0.02;
            let expected = 3.0 / (16.0 * PI) * (1.0 + mu * mu);
            assert!((r.eval(mu) - expected).abs() < 1e-15);
            assert!((cs.eval(mu) - expected).abs() < 1e-15);
        }
        // Depolarised Rayleigh: forward/side ratio (1+3γ+1−γ)/(1+3γ) = 2(1+γ)/(1+3γ).
        let rho: f64 = 0.0279;
        let gamma = rho / (2.0 - rho);
        let p = PhaseFunction::Rayleigh {
            depolarization: rho,
        };
        assert!(
            (p.eval(1.0) / p.eval(0.0) - 2.0 * (1.0 + gamma) / (1.0 + 3.0 * gamma)).abs() < 1e-12
        );
        // HG at g = 0 is isotropic; CS and HG agree on the forward/backward symmetry.
        assert!((PhaseFunction::HenyeyGreenstein { g: 0.0 }.eval(0.3) - INV_4PI).abs() < 1e-16);
        let (a, b) = (
            PhaseFunction::CornetteShanks { g: 0.6 },
            PhaseFunction::CornetteShanks { g: -0.6 },
        );
        assert!((a.eval(0.4) - b.eval(-0.4)).abs() < 1e-15);
    }

    /// Radical inverse in base 2 (van der Corput) for the second random number.
    fn van_der_corput(mut i: u32) -> f64 {
        i = i.reverse_bits();
        i as f64 / 4_294_967_296.0
    }

    #[test]
    fn phase_sampling_histograms_match_eval() {
        const N: usize = 200_000;
        const BINS: usize = 20;
        for p in all_cases() {
            let mut hist = [0usize; BINS];
            for i in 0..N {
                // Stratified u1 (low discrepancy), van der Corput u2.
                let (mu, phi) = p.sample((i as f64 + 0.5) / N as f64, van_der_corput(i as u32));
                assert!(
                    (-1.0..=1.0).contains(&mu) && (0.0..2.0 * PI).contains(&phi),
                    "{p:?}: {mu} {phi}"
                );
                hist[(((mu + 1.0) * 0.5 * BINS as f64) as usize).min(BINS - 1)] += 1;
            }
            for (k, &count) in hist.iter().enumerate() {
                let a = -1.0 + 2.0 * k as f64 / BINS as f64;
                let expected = N as f64 * bin_probability(&p, a, a + 2.0 / BINS as f64);
                if expected < 1.0 {
                    assert!(count <= 2, "{p:?} bin {k}: {count} vs {expected}");
                    continue;
                }
                // Inverse-CDF with stratified u1 puts each bin within ±1 of its expectation.
                let tolerance = (0.02 * expected).max(1.5);
                assert!(
                    (count as f64 - expected).abs() <= tolerance,
                    "{p:?} bin {k}: {count} samples, expected {expected:.1}"
                );
            }
        }
    }

    #[test]
    fn phase_sampling_is_exact_inverse_of_cdf() {
        // P(μ ≤ sample(u)) = u for each single-lobe sampler, to near rounding (the dual-lobe
        // sampler picks a lobe with u1, so it is not monotone in u1; the histograms cover it).
        for p in all_cases()
            .into_iter()
            .filter(|p| !matches!(p, PhaseFunction::DualLobeHg { .. }))
        {
            for i in 1..40 {
                let u = i as f64 / 40.0;
                let (mu, _) = p.sample(u, 0.5);
                let cdf = bin_probability(&p, -1.0, mu);
                assert!(
                    (cdf - u).abs() < 2e-6,
                    "{p:?}: u = {u}, cdf(sample) = {cdf}"
                );
            }
            assert_eq!(p.sample(0.0, 0.0).0.clamp(-1.0, 1.0), p.sample(0.0, 0.0).0);
        }
    }

    #[test]
    fn phase_tabulated_reproduces_henyey_greenstein() {
        let g = 0.7;
        let p = PhaseFunction::load_tabulated(temp_file("hg.txt", &hg_table(g))).unwrap();
        let PhaseFunction::Tabulated(t) = &p else {
            unreachable!()
        };
        assert_eq!(t.angles().len(), 361);
        assert_eq!(*t.angles().last().unwrap(), PI);
        for i in 0..=1000 {
            let mu = -1.0 + i as f64 * 0.002;
            let (tab, exact) = (p.eval(mu), hg(g, mu));
            assert!(
                (tab / exact - 1.0).abs() < 0.01,
                "μ = {mu}: {tab} vs {exact}"
            );
        }
        assert!((p.mean_cosine() - g).abs() < 1e-3, "{}", p.mean_cosine());
    }

    #[test]
    fn phase_tabulated_toml_prepare_relative_to_base_dir() {
        let path = temp_file("table.dat", &hg_table(0.5));
        let dir = path.parent().unwrap();
        #[derive(Deserialize, Serialize)]
        struct Doc {
            phase: PhaseFunction,
        }
        let mut doc: Doc =
            toml::from_str("phase = { type = \"tabulated\", file = \"table.dat\" }").unwrap();
        assert!(!doc.phase.is_prepared());
        doc.phase.validate("phase").unwrap();
        doc.phase.prepare(dir).unwrap();
        assert!(doc.phase.is_prepared());
        assert!((doc.phase.eval(0.2) - hg(0.5, 0.2)).abs() / hg(0.5, 0.2) < 0.01);
        // Serialises back to the path as written.
        let text = toml::to_string(&doc).unwrap();
        assert!(
            text.contains("type = \"tabulated\"") && text.contains("file = \"table.dat\""),
            "{text}"
        );
        // Unresolved relative to the wrong directory → File error naming the path.
        let mut bad: Doc =
            toml::from_str("phase = { type = \"tabulated\", file = \"table.dat\" }").unwrap();
        match bad.phase.prepare(Path::new("/nonexistent-firmament-dir")) {
            Err(Error::File { path, .. }) => assert!(path.contains("table.dat"), "{path}"),
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn phase_toml_analytic_forms() {
        let p: PhaseFunction = toml::from_str("type = \"rayleigh\"").unwrap();
        assert_eq!(
            p,
            PhaseFunction::Rayleigh {
                depolarization: 0.0
            }
        );
        let p: PhaseFunction = toml::from_str("type = \"henyey-greenstein\"\ng = 0.76").unwrap();
        assert_eq!(p, PhaseFunction::HenyeyGreenstein { g: 0.76 });
        let p: PhaseFunction =
            toml::from_str("type = \"dual-lobe-hg\"\ng1 = 0.8\ng2 = -0.3\nweight = 0.6").unwrap();
        assert_eq!(
            p,
            PhaseFunction::DualLobeHg {
                g1: 0.8,
                g2: -0.3,
                weight: 0.6
            }
        );
        for p in analytic_cases() {
            let back: PhaseFunction = toml::from_str(&toml::to_string(&p).unwrap()).unwrap();
            assert_eq!(back, p);
        }
        assert!(
            toml::from_str::<PhaseFunction>("type = \"cornette-shanks\"\ng = 0.8\nk = 1").is_err()
        );
        assert!(
            toml::from_str::<PhaseFunction>("type = \"tabulated\"\nfile = \"x\"\nextra = 1")
                .is_err()
        );
        assert!(toml::from_str::<PhaseFunction>("type = \"mie\"").is_err());
    }

    fn invalid_field(r: Result<()>) -> String {
        match r {
            Err(e @ Error::InvalidParameter { .. }) => e.to_string(),
            other => panic!("expected InvalidParameter, got {other:?}"),
        }
    }

    #[test]
    fn phase_validate_names_field_value_and_range() {
        let f = "constituents[1].phase";
        let msg = invalid_field(PhaseFunction::HenyeyGreenstein { g: 1.0 }.validate(f));
        assert!(
            msg.contains("constituents[1].phase.g") && msg.contains('1') && msg.contains("(-1, 1)"),
            "{msg}"
        );
        let msg = invalid_field(PhaseFunction::CornetteShanks { g: f64::NAN }.validate(f));
        assert!(msg.contains("phase.g") && msg.contains("NaN"), "{msg}");
        let msg = invalid_field(PhaseFunction::Schlick { g: -1.5 }.validate(f));
        assert!(msg.contains("phase.g") && msg.contains("-1.5"), "{msg}");
        let msg = invalid_field(PhaseFunction::Schlick { g: 0.95 }.validate(f));
        assert!(msg.contains("phase.g") && msg.contains("0.9381"), "{msg}");
        PhaseFunction::Schlick { g: 0.938 }.validate(f).unwrap();
        assert!((schlick_k(SCHLICK_G_MAX) - 1.0).abs() < 1e-15);
        let msg = invalid_field(
            PhaseFunction::DualLobeHg {
                g1: 0.5,
                g2: -1.0,
                weight: 0.5,
            }
            .validate(f),
        );
        assert!(msg.contains("phase.g2"), "{msg}");
        let msg = invalid_field(
            PhaseFunction::DualLobeHg {
                g1: 0.5,
                g2: 0.1,
                weight: 1.2,
            }
            .validate(f),
        );
        assert!(
            msg.contains("phase.weight") && msg.contains("1.2") && msg.contains("[0, 1]"),
            "{msg}"
        );
        let msg = invalid_field(
            PhaseFunction::Rayleigh {
                depolarization: 0.5,
            }
            .validate(f),
        );
        assert!(
            msg.contains("phase.depolarization") && msg.contains("[0, 0.5)"),
            "{msg}"
        );
        let msg = invalid_field(
            PhaseFunction::Rayleigh {
                depolarization: -0.01,
            }
            .validate(f),
        );
        assert!(msg.contains("-0.01"), "{msg}");
        let msg = invalid_field(PhaseFunction::Tabulated(TabulatedPhase::new("")).validate(f));
        assert!(msg.contains("phase.file"), "{msg}");
    }

    #[test]
    fn phase_tabulated_refuses_bad_files() {
        let cases = [
            ("one.txt", "0 1\n", "at least 2"),
            ("empty.txt", "# nothing\n", "at least 2"),
            ("neg.txt", "0 1\n90 -0.5\n180 1\n", "negative"),
            ("nan.txt", "0 1\n90 NaN\n180 1\n", "not finite"),
            ("inf.txt", "0 1\n90 inf\n180 1\n", "not finite"),
            ("order.txt", "0 1\n90 1\n45 1\n", "not greater"),
            ("dup.txt", "0 1\n90 1\n90 1\n", "not greater"),
            ("range.txt", "0 1\n190 1\n", "outside [0, 180]"),
            ("negangle.txt", "-5 1\n90 1\n", "outside [0, 180]"),
            ("zero.txt", "0 0\n180 0\n", "all zero"),
            ("junk.txt", "0 1\n90 abc\n", "not a number"),
            ("three.txt", "0 1 2\n180 1\n", "expected `angle_deg value`"),
        ];
        for (name, text, reason_part) in cases {
            let path = temp_file(name, text);
            match PhaseFunction::load_tabulated(&path) {
                Err(Error::File { path: p, reason }) => {
                    assert!(p.contains(name), "{p}");
                    assert!(reason.contains(reason_part), "{name}: {reason}");
                }
                other => panic!("{name}: expected File error, got {other:?}"),
            }
        }
        match PhaseFunction::load_tabulated("/nonexistent-firmament-dir/phase.txt") {
            Err(Error::File { path, .. }) => assert!(path.contains("phase.txt")),
            other => panic!("{other:?}"),
        }
    }
}

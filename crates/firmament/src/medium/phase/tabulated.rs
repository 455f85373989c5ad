//! Phase functions tabulated against the scattering angle, read from a text file (e.g.
//! written by MiePlot), normalised on load, sampled by inverting their exact CDF.

use std::f64::consts::PI;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use serde::{Deserialize, Serialize};

use crate::{Error, Result};

/// A phase function tabulated against the scattering angle, read from a text file.
///
/// In TOML: `{ type = "tabulated", file = "path" }`; the path is kept as written and is
/// resolved against the TOML file's directory by [`PhaseFunction::prepare`]. The file holds
/// one `angle_deg value` pair per line (whitespace or comma separated, `#` starts a comment),
/// angles strictly increasing in [0, 180]. Values are interpolated linearly in θ; if the
/// table does not start at 0° or end at 180° the end values are extended as constants.
///
/// [`PhaseFunction::prepare`]: super::PhaseFunction::prepare
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
pub(super) struct TabulatedData {
    /// Scattering angles in radians, strictly increasing from 0 to π.
    theta: Vec<f64>,
    /// Normalised values (1/sr).
    value: Vec<f64>,
    /// Cumulative probability at each knot (0 … 1).
    cdf: Vec<f64>,
    /// ∫ p μ dΩ.
    pub(super) mean_cosine: f64,
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

    pub(super) fn data(&self) -> &TabulatedData {
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
    pub(super) fn eval(&self, cos_theta: f64) -> f64 {
        let t = cos_theta.clamp(-1.0, 1.0).acos();
        let n = self.theta.len();
        let i = self.theta.partition_point(|&x| x <= t).clamp(1, n - 1) - 1;
        let (ta, tb) = (self.theta[i], self.theta[i + 1]);
        let f = ((t - ta) / (tb - ta)).clamp(0.0, 1.0);
        self.value[i] + f * (self.value[i + 1] - self.value[i])
    }

    pub(super) fn sample_cos(&self, u: f64) -> f64 {
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
pub(super) fn solve_increasing(
    mut lo: f64,
    mut hi: f64,
    x0: f64,
    fdf: impl Fn(f64) -> (f64, f64),
) -> f64 {
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

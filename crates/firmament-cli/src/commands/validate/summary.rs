//! The per-view relative errors of one table configuration and their summaries: median,
//! nearest-rank 95th percentile, maximum, bias, root mean square with and without the
//! reference's noise; as JSON and as the lines `validate` prints.

use serde::Serialize;

use crate::common::median_of_sorted;

/// Per-view relative errors (table / reference − 1) of one table configuration, with the
/// reference's relative standard error of each view.
pub struct RelativeErrors {
    pub luminance: Vec<f64>,
    pub luminance_stderr: Vec<f64>,
    /// Per wavelength: (errors, reference relative standard errors).
    pub channels: Vec<(Vec<f64>, Vec<f64>)>,
}

/// Summary statistics of the absolute relative errors of a set of views.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Summary {
    pub median: f64,
    /// Nearest-rank 95th percentile.
    pub p95: f64,
    pub max: f64,
    /// Median of the signed relative errors (bias).
    pub signed_median: f64,
    /// Median relative standard error of the reference.
    pub reference_median_relative_stderr: f64,
    /// Root mean square of the relative errors.
    pub rms: f64,
    /// The RMS with the reference's noise removed, √max(⟨e²⟩ − ⟨σ²⟩, 0): the error e of a
    /// view is the table's own error plus the reference's relative noise σ (independent,
    /// mean 0), so ⟨e²⟩ − ⟨σ²⟩ estimates the mean square of the table's own error.
    pub rms_noise_removed: f64,
    /// Views.
    pub count: usize,
}

/// The summary of one wavelength.
#[derive(Debug, Serialize)]
pub struct ChannelSummary {
    #[serde(flatten)]
    pub summary: Summary,
    pub wavelength_nm: f64,
}

/// The summaries of luminance and of each wavelength.
#[derive(Debug, Serialize)]
pub struct Summaries {
    pub luminance: Summary,
    pub wavelengths: Vec<ChannelSummary>,
}

impl RelativeErrors {
    /// No views yet, for `channels` wavelengths.
    pub fn new(channels: usize) -> RelativeErrors {
        RelativeErrors {
            luminance: Vec::new(),
            luminance_stderr: Vec::new(),
            channels: vec![(Vec::new(), Vec::new()); channels],
        }
    }

    /// Add the views of `other`.
    pub fn extend(&mut self, other: &RelativeErrors) {
        self.luminance.extend(&other.luminance);
        self.luminance_stderr.extend(&other.luminance_stderr);
        for (a, b) in self.channels.iter_mut().zip(&other.channels) {
            a.0.extend(&b.0);
            a.1.extend(&b.1);
        }
    }

    /// The summaries, the wavelengths being `wavelengths_nm`.
    pub fn summaries(&self, wavelengths_nm: &[f64]) -> Summaries {
        Summaries {
            luminance: summarise(&self.luminance, &self.luminance_stderr),
            wavelengths: self
                .channels
                .iter()
                .zip(wavelengths_nm)
                .map(|((errors, stderr), &wavelength_nm)| ChannelSummary {
                    summary: summarise(errors, stderr),
                    wavelength_nm,
                })
                .collect(),
        }
    }
}

fn summarise(errors: &[f64], reference_stderr: &[f64]) -> Summary {
    let mut abs: Vec<f64> = errors.iter().map(|e| e.abs()).collect();
    abs.sort_by(f64::total_cmp);
    let mut signed = errors.to_vec();
    signed.sort_by(f64::total_cmp);
    let mut stderr = reference_stderr.to_vec();
    stderr.sort_by(f64::total_cmp);
    let n = abs.len();
    let mean_square = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>() / v.len().max(1) as f64;
    let (e2, s2) = (mean_square(errors), mean_square(reference_stderr));
    Summary {
        rms: e2.sqrt(),
        rms_noise_removed: (e2 - s2).max(0.0).sqrt(),
        median: median_of_sorted(&abs),
        p95: if n == 0 {
            f64::NAN
        } else {
            abs[((0.95 * n as f64).ceil() as usize).clamp(1, n) - 1]
        },
        max: abs.last().copied().unwrap_or(f64::NAN),
        signed_median: median_of_sorted(&signed),
        reference_median_relative_stderr: median_of_sorted(&stderr),
        count: n,
    }
}

impl Summary {
    /// One printed line: `label`, then the figures in percent.
    fn line(&self, label: &str) -> String {
        let pct = |v: f64| format!("{:6.2}%", 100.0 * v);
        format!(
            "  {label:>8}  med {} p95 {} max {}  (ref se {})  bias {:+.2}%  rms {} (noise removed {})",
            pct(self.median),
            pct(self.p95),
            pct(self.max),
            pct(self.reference_median_relative_stderr),
            100.0 * self.signed_median,
            pct(self.rms).trim_start(),
            pct(self.rms_noise_removed).trim_start()
        )
    }
}

impl Summaries {
    /// The printed lines: luminance (`Y`), then each wavelength.
    pub fn print(&self) {
        println!("{}", self.luminance.line("Y"));
        for c in &self.wavelengths {
            println!("{}", c.summary.line(&format!("{:.0} nm", c.wavelength_nm)));
        }
    }
}

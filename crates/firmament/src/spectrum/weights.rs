//! The weights that turn a few wavelength samples into CIE XYZ: fitted, by least squares, to
//! a family of sky-like spectra whose colour is known exactly, instead of reading the samples
//! as a piecewise-linear spectrum.
//!
//! A sky's spectral radiance is the sun's spectrum times a smooth factor: `L(λ) = E☉(λ)·f(λ)`,
//! with `f` made of scattering coefficients (λ⁻⁴ for molecules, flatter for aerosols) and
//! transmittances (`exp(−m·τ(λ))`, ozone's Chappuis band included). Bruneton (2016, §14.3 of
//! the documentation of "precomputed_atmospheric_scattering") turns three samples into
//! luminance by interpolating `f` and integrating it against the full solar spectrum; we go
//! one step further and choose, for the given sample wavelengths, the linear map `w` (one
//! column per X, Y, Z) that best reproduces the exact XYZ `683·∫ x̄ E☉ f dλ` of a family of
//! such `f` from their samples `E☉(λₖ)·f(λₖ)`, in relative terms, with the sun itself (`f = 1`)
//! reproduced exactly, so the solar illuminance is the full embedded spectrum's.
//!
//! The generic family ([`generic_family`]) is `(λ/550)^−p · exp(−a·(λ/550)^−4) ·
//! exp(−b·σ_O₃(λ)/σ_O₃(600))`: a power law from red (p = −3, a dusty sky) to bluer than Rayleigh
//! (p = 4.5), reddened by up to 1.2 vertical Rayleigh optical depths at 550 nm and by up to
//! 0.3 of ozone's Chappuis band (4 and 2 for eight samples or more, which can serve the
//! sun's beam at the horizon and twilight too); a model adds its own single-scattering skies
//! (`atmosphere::sky_spectra`). What that achieves against 48-wavelength computations is in
//! docs/accuracy.md ("Luminance from a few wavelengths").

use super::table;
use super::LUMINOUS_EFFICACY_LM_W;

/// First wavelength of the 1-nm grid the targets are integrated on (the CIE 1931 table's).
pub const GRID_START_NM: f64 = 360.0;
/// Number of 1-nm steps of that grid (360–830 nm).
pub const GRID_LEN: usize = 471;

/// The wavelengths of the 1-nm grid (360, 361, …, 830 nm).
pub fn grid_nm() -> impl Iterator<Item = f64> {
    (0..GRID_LEN).map(|i| GRID_START_NM + i as f64)
}

/// The sun's spectrum as the samples see it and as the eye would: `at_samples[k]` is the
/// value the model uses at sample k (a band mean, or a user table's value), `on_grid` the
/// spectrum on the 1-nm grid of [`grid_nm`] (W·m⁻²·nm⁻¹ both).
#[derive(Clone, Debug)]
pub struct SolarShape {
    /// At the sample wavelengths.
    pub at_samples: Vec<f64>,
    /// On the 1-nm grid, 360–830 nm.
    pub on_grid: Vec<f64>,
}

impl SolarShape {
    /// ASTM G173-03, as [`super::Wavelengths::solar_irradiance_w_m2_nm`] samples it
    /// (10-nm band means), and at full resolution on the grid (the table is 1 nm there).
    pub fn astm_g173(nm: &[f64]) -> SolarShape {
        SolarShape {
            at_samples: nm
                .iter()
                .map(|&l| super::solar_irradiance_band_mean(l, super::SOLAR_SMOOTHING_BANDWIDTH_NM))
                .collect(),
            on_grid: grid_nm().map(super::solar_irradiance_astm_g173).collect(),
        }
    }
}

/// One training spectrum: the smooth factor `f` relative to the sun, at the samples and on
/// the 1-nm grid.
#[derive(Clone, Debug)]
pub struct TrainingSpectrum {
    /// `f(λₖ)` at the sample wavelengths.
    pub at_samples: Vec<f64>,
    /// `f` on the 1-nm grid of [`grid_nm`].
    pub on_grid: Vec<f64>,
    /// Its weight in the fit (1 for the generic family).
    pub weight: f64,
}

impl TrainingSpectrum {
    /// From a function of the wavelength (nm).
    pub fn from_fn(nm: &[f64], f: impl Fn(f64) -> f64) -> TrainingSpectrum {
        TrainingSpectrum {
            at_samples: nm.iter().map(|&l| f(l)).collect(),
            on_grid: grid_nm().map(&f).collect(),
            weight: 1.0,
        }
    }
}

/// The generic family (module documentation): 16 slopes × 7 or 10 Rayleigh reddenings ×
/// 4 or 6 ozone amounts.
pub fn generic_family(nm: &[f64]) -> Vec<TrainingSpectrum> {
    let ozone = table::ozone();
    let s600 = ozone.interp(0, 600.0);
    let mut out = Vec::new();
    for ip in 0..16 {
        let p = -3.0 + 0.5 * ip as f64;
        for &a in reddenings(nm.len()) {
            for &b in ozone_amounts(nm.len()) {
                out.push(TrainingSpectrum::from_fn(nm, |l| {
                    let x = l / 550.0;
                    x.powf(-p) * (-a * x.powi(-4) - b * ozone.interp(0, l) / s600).exp()
                }));
            }
        }
    }
    out
}

/// Rayleigh reddenings of the generic family, in vertical optical depths at 550 nm: up to
/// 1.2 (a daylight sky's paths) for fewer than [`TWILIGHT_SAMPLES`] samples; up to 4 (the
/// sun's own beam at the horizon, ~40 air masses of τ ≈ 0.1) for more.
fn reddenings(samples: usize) -> &'static [f64] {
    if samples < TWILIGHT_SAMPLES {
        &[0.0, 0.05, 0.1, 0.2, 0.4, 0.8, 1.2]
    } else {
        &[0.0, 0.05, 0.1, 0.2, 0.4, 0.8, 1.2, 2.0, 3.0, 4.0]
    }
}

/// Ozone amounts of the generic family, relative to the Chappuis band's cross-section at
/// 600 nm: daylight's (up to 0.3: ~8 vertical columns of 300 DU) for fewer than
/// [`TWILIGHT_SAMPLES`] samples, which cannot serve daylight and twilight at once; up to 2
/// (twilight's long paths through the ozone layer) for more.
fn ozone_amounts(samples: usize) -> &'static [f64] {
    if samples < TWILIGHT_SAMPLES {
        &[0.0, 0.03, 0.1, 0.3]
    } else {
        &[0.0, 0.03, 0.1, 0.3, 1.0, 2.0]
    }
}

/// The fewest samples whose weights are fitted to twilight's spectra as well as daylight's.
pub const TWILIGHT_SAMPLES: usize = 8;

/// Relative weight of the sun's own spectrum among the training rows: enough that the solar
/// illuminance is reproduced to a few 10⁻⁶.
const SUN_ROW_WEIGHT: f64 = 1000.0;
/// Ridge regularisation, relative to the mean diagonal of the normal matrix: keeps the
/// weights of a dense sample list from oscillating where the samples are redundant.
const RIDGE: f64 = 1e-7;

/// The XYZ weights per sample (`xyz[k]` multiplies sample k's value), fitted to `family`
/// under `sun` (module documentation). Sample values are radiances (or irradiances) and
/// XYZ comes out with Y in cd/m² (or lux), 683 lm/W.
pub fn fit_xyz_weights(sun: &SolarShape, family: &[TrainingSpectrum]) -> Vec<[f64; 3]> {
    let n = sun.at_samples.len();
    let cmf = table::cie_1931();
    let target = |f: &[f64]| -> [f64; 3] {
        let mut t = [0.0; 3];
        for (i, (fv, e)) in f.iter().zip(&sun.on_grid).enumerate() {
            for (c, tc) in t.iter_mut().enumerate() {
                *tc += cmf.cols[c][i] * e * fv * LUMINOUS_EFFICACY_LM_W;
            }
        }
        t
    };
    // Rows, per component c: the samples of each member over a scale, against its exact
    // component over the same scale. The scale is the component itself, but at least
    // `FLOOR`·Y: a relative error per component keeps the small Z of a red sunset (and X of a
    // deep blue) from changing sign, and the floor keeps a component near 0 from weighing
    // a member without end.
    const FLOOR: f64 = 0.05;
    let sun_member = TrainingSpectrum {
        at_samples: vec![1.0; n],
        on_grid: vec![1.0; GRID_LEN],
        weight: 1.0,
    };
    let mut ata = vec![vec![vec![0.0; n]; n]; 3];
    let mut atb = vec![vec![0.0; n]; 3];
    let mut add_row = |m: &TrainingSpectrum, weight: f64| {
        let t = target(&m.on_grid);
        if t[1].is_nan() || t[1] <= 0.0 {
            return;
        }
        for c in 0..3 {
            let scale = weight / t[c].max(FLOOR * t[1]);
            let row: Vec<f64> = (0..n)
                .map(|k| scale * sun.at_samples[k] * m.at_samples[k])
                .collect();
            for i in 0..n {
                for j in 0..n {
                    ata[c][i][j] += row[i] * row[j];
                }
                atb[c][i] += row[i] * scale * t[c];
            }
        }
    };
    add_row(&sun_member, SUN_ROW_WEIGHT);
    for m in family {
        add_row(m, m.weight);
    }
    let mut out = vec![[0.0; 3]; n];
    for (c, (mut a, b)) in ata.into_iter().zip(atb).enumerate() {
        let mean_diag = (0..n).map(|i| a[i][i]).sum::<f64>() / n as f64;
        for (i, r) in a.iter_mut().enumerate() {
            r[i] += RIDGE * mean_diag;
        }
        for (o, x) in out.iter_mut().zip(solve(a, b)) {
            o[c] = x;
        }
    }
    out
}

/// Solves the symmetric positive definite system `a·x = b` by Gaussian elimination with
/// partial pivoting.
fn solve(mut a: Vec<Vec<f64>>, mut b: Vec<f64>) -> Vec<f64> {
    let n = b.len();
    for col in 0..n {
        let pivot = (col..n)
            .max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))
            .unwrap_or(col);
        a.swap(col, pivot);
        b.swap(col, pivot);
        let p = a[col][col];
        if p == 0.0 {
            continue;
        }
        for row in col + 1..n {
            let f = a[row][col] / p;
            if f != 0.0 {
                for k in col..n {
                    a[row][k] -= f * a[col][k];
                }
                b[row] -= f * b[col];
            }
        }
    }
    let mut x = vec![0.0; n];
    for row in (0..n).rev() {
        let s: f64 = (row + 1..n).map(|k| a[row][k] * x[k]).sum();
        x[row] = if a[row][row] != 0.0 {
            (b[row] - s) / a[row][row]
        } else {
            0.0
        };
    }
    x
}

//! Atmospheric constituents: a density profile, per-wavelength scattering and absorption
//! coefficients at density 1, and a phase function.

use serde::{Deserialize, Serialize};

use super::phase::PhaseFunction;
use super::profile::DensityProfile;
use crate::spectrum;
use crate::{Error, Result};

/// What a constituent is, which decides how the precomputed tables group its single
/// scattering (Bruneton & Neyret 2008 §4: Rayleigh and Mie single scattering are stored
/// apart so their phase functions are applied at render time).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ConstituentKind {
    /// Air molecules: Rayleigh scattering.
    Molecules,
    /// Aerosols: Mie scattering and absorption.
    Aerosols,
    /// Pure absorbers such as ozone: no scattering.
    Absorber,
}

/// Dobson unit: 2.6867e20 molecules per m² (1 DU = 0.01 mm of gas at STP; WMO).
pub const DOBSON_UNIT_M2: f64 = 2.686_7e20;

/// A spectral coefficient (m⁻¹ at density 1 unless stated).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "kebab-case", deny_unknown_fields)]
pub enum Coefficient {
    /// Zero at every wavelength.
    None,
    /// The same value at every wavelength (m⁻¹).
    Constant {
        /// Coefficient (m⁻¹).
        value_per_m: f64,
    },
    /// A table over wavelength, interpolated as a power law between samples (linear in
    /// log–log, extrapolated with the end segments' slope; linear where a value is 0).
    Table {
        /// Wavelengths (nm), increasing.
        wavelengths_nm: Vec<f64>,
        /// Coefficients (m⁻¹).
        values_per_m: Vec<f64>,
    },
    /// β(λ) = value·(λ/reference)^(−exponent); exponent 4 for Rayleigh (paper §2.1).
    PowerLaw {
        /// Reference wavelength (nm).
        reference_nm: f64,
        /// Coefficient at the reference wavelength (m⁻¹).
        value_per_m: f64,
        /// Power-law exponent.
        exponent: f64,
    },
    /// Rayleigh scattering from the Bodhaine et al. (1999) cross-section σ(λ), scaled so the
    /// vertical column of the profile holds `column_m2` molecules per m².
    RayleighCrossSection {
        /// Molecules per m² in the vertical column from the ground to the top.
        column_m2: f64,
    },
    /// Ozone absorption from the embedded cross-sections σ(λ), scaled so the column holds
    /// `column_du` Dobson units.
    OzoneColumn {
        /// Total ozone column (DU).
        column_du: f64,
    },
    /// Ångström's law for aerosols: vertical optical depth τ(λ) = β·(λ/1 µm)^(−α) (Ångström
    /// 1929), times `fraction` (single-scattering albedo for scattering, 1 − it for
    /// absorption), spread over the profile.
    Angstrom {
        /// Ångström exponent α.
        alpha: f64,
        /// Ångström turbidity β (optical depth at 1 µm).
        beta: f64,
        /// Share of the extinction this coefficient carries, in [0, 1].
        fraction: f64,
    },
}

impl Coefficient {
    /// Check the numbers; `field` is the coefficient's path.
    pub fn validate(&self, field: &str) -> Result<()> {
        let nonneg = |name: &str, v: f64| -> Result<()> {
            if v.is_finite() && v >= 0.0 {
                Ok(())
            } else {
                Err(Error::invalid(
                    format!("{field}.{name}"),
                    v,
                    "a finite number ≥ 0",
                ))
            }
        };
        match self {
            Coefficient::None => Ok(()),
            Coefficient::Constant { value_per_m } => nonneg("value_per_m", *value_per_m),
            Coefficient::Table {
                wavelengths_nm,
                values_per_m,
            } => {
                check_wavelength_table(field, "values_per_m", wavelengths_nm, values_per_m.len())?;
                for (i, v) in values_per_m.iter().enumerate() {
                    nonneg(&format!("values_per_m[{i}]"), *v)?;
                }
                Ok(())
            }
            Coefficient::PowerLaw {
                reference_nm,
                value_per_m,
                exponent,
            } => {
                if !(reference_nm.is_finite() && *reference_nm > 0.0) {
                    return Err(Error::invalid(
                        format!("{field}.reference_nm"),
                        reference_nm,
                        "a wavelength > 0 nm",
                    ));
                }
                nonneg("value_per_m", *value_per_m)?;
                if !exponent.is_finite() {
                    return Err(Error::invalid(
                        format!("{field}.exponent"),
                        exponent,
                        "a finite number",
                    ));
                }
                Ok(())
            }
            Coefficient::RayleighCrossSection { column_m2 } => nonneg("column_m2", *column_m2),
            Coefficient::OzoneColumn { column_du } => nonneg("column_du", *column_du),
            Coefficient::Angstrom {
                alpha,
                beta,
                fraction,
            } => {
                if !alpha.is_finite() {
                    return Err(Error::invalid(
                        format!("{field}.alpha"),
                        alpha,
                        "a finite number",
                    ));
                }
                nonneg("beta", *beta)?;
                if !(0.0..=1.0).contains(fraction) {
                    return Err(Error::invalid(
                        format!("{field}.fraction"),
                        fraction,
                        "a number in [0, 1]",
                    ));
                }
                Ok(())
            }
        }
    }

    /// The coefficient at density 1 (m⁻¹) at each wavelength; `column_m` is the profile's
    /// vertical integral ∫ρ dh (m), needed by column-normalised forms.
    pub fn resolve(&self, wavelengths_nm: &[f64], column_m: f64) -> Vec<f64> {
        let per_column = |v: f64| if column_m > 0.0 { v / column_m } else { 0.0 };
        wavelengths_nm
            .iter()
            .map(|&l| match self {
                Coefficient::None => 0.0,
                Coefficient::Constant { value_per_m } => *value_per_m,
                Coefficient::Table {
                    wavelengths_nm,
                    values_per_m,
                } => interpolate_power_law(wavelengths_nm, values_per_m, l),
                Coefficient::PowerLaw {
                    reference_nm,
                    value_per_m,
                    exponent,
                } => value_per_m * (l / reference_nm).powf(-exponent),
                Coefficient::RayleighCrossSection { column_m2 } => {
                    per_column(spectrum::rayleigh_cross_section_m2(l) * column_m2)
                }
                Coefficient::OzoneColumn { column_du } => {
                    per_column(spectrum::ozone_cross_section_m2(l) * column_du * DOBSON_UNIT_M2)
                }
                Coefficient::Angstrom {
                    alpha,
                    beta,
                    fraction,
                } => per_column(fraction * beta * (l / 1000.0).powf(-alpha)),
            })
            .collect()
    }
}

/// Check a table over wavelength: non-empty, as many values (field `values_name`) as
/// wavelengths, wavelengths positive and increasing. `field` is the table's path.
pub(crate) fn check_wavelength_table(
    field: &str,
    values_name: &str,
    wavelengths_nm: &[f64],
    values: usize,
) -> Result<()> {
    if wavelengths_nm.is_empty() {
        return Err(Error::invalid(
            format!("{field}.wavelengths_nm"),
            "[]",
            "at least one wavelength",
        ));
    }
    if wavelengths_nm.len() != values {
        return Err(Error::invalid(
            format!("{field}.{values_name}"),
            format!("{values} values"),
            format!("as many values as wavelengths ({})", wavelengths_nm.len()),
        ));
    }
    for (i, w) in wavelengths_nm.iter().enumerate() {
        if !(w.is_finite() && *w > 0.0) || (i > 0 && *w <= wavelengths_nm[i - 1]) {
            return Err(Error::invalid(
                format!("{field}.wavelengths_nm[{i}]"),
                w,
                "positive wavelengths in increasing order",
            ));
        }
    }
    Ok(())
}

/// Interpolate a table as a power law between samples (linear in log–log), extrapolating
/// with the end segments; falls back to linear interpolation with held ends where a value
/// is not positive.
pub fn interpolate_power_law(xs: &[f64], ys: &[f64], x: f64) -> f64 {
    let n = xs.len();
    if n == 1 {
        return ys[0];
    }
    let i = match xs.iter().position(|&v| v > x) {
        Some(0) => 0,
        Some(i) => i - 1,
        None => n - 2,
    };
    let (x0, x1, y0, y1) = (xs[i], xs[i + 1], ys[i], ys[i + 1]);
    if y0 > 0.0 && y1 > 0.0 {
        let slope = (y1 / y0).ln() / (x1 / x0).ln();
        y0 * (x / x0).powf(slope)
    } else {
        let t = ((x - x0) / (x1 - x0)).clamp(0.0, 1.0);
        y0 + t * (y1 - y0)
    }
}

/// One constituent as written in an atmosphere file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Constituent {
    /// A name for messages and query output.
    pub name: String,
    /// Molecules, aerosols or absorber.
    pub kind: ConstituentKind,
    /// Density profile (layers from the ground up).
    pub density: DensityProfile,
    /// Scattering coefficient at density 1.
    pub scattering: Coefficient,
    /// Absorption coefficient at density 1.
    pub absorption: Coefficient,
    /// Phase function of its scattering.
    pub phase: PhaseFunction,
}

impl Constituent {
    /// Check every field; `field` is this constituent's path, e.g. `constituents[1]`.
    pub fn validate(&self, field: &str) -> Result<()> {
        self.density.validate(&format!("{field}.density"))?;
        self.scattering.validate(&format!("{field}.scattering"))?;
        self.absorption.validate(&format!("{field}.absorption"))?;
        self.phase.validate(&format!("{field}.phase"))?;
        if self.kind == ConstituentKind::Absorber && self.scattering != Coefficient::None {
            return Err(Error::invalid(
                format!("{field}.scattering"),
                "a scattering coefficient",
                "type = \"none\" for an absorber",
            ));
        }
        Ok(())
    }
}

/// A constituent resolved for a wavelength grid.
#[derive(Clone, Debug)]
pub struct ResolvedConstituent {
    /// Name.
    pub name: String,
    /// Kind.
    pub kind: ConstituentKind,
    /// Density profile.
    pub density: DensityProfile,
    /// Scattering coefficient at density 1 (m⁻¹), per wavelength.
    pub scattering: Vec<f64>,
    /// Absorption coefficient at density 1 (m⁻¹), per wavelength.
    pub absorption: Vec<f64>,
    /// Extinction = scattering + absorption (m⁻¹), per wavelength.
    pub extinction: Vec<f64>,
    /// Phase function.
    pub phase: PhaseFunction,
}

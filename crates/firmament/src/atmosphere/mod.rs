//! The atmosphere: planet, constituents, sun. Written as TOML (`deny_unknown_fields`),
//! shipped as embedded presets, validated field by field, and resolved for a wavelength
//! grid into a [`Model`] that the tables, the renderer and the reference path tracer share.

pub mod adjust;
pub mod density_table;
pub mod groups;
mod lift;
pub mod limits;
pub mod model;
pub mod presets;
mod sky_spectra;

use std::path::Path;

use serde::{Deserialize, Serialize};

pub use adjust::Adjustments;
pub use groups::ScatteringGroups;
pub use model::{Model, OpticalDepths};

use crate::medium::{Constituent, ConstituentKind};
use crate::spectrum::Wavelengths;
use crate::{Error, Result};

/// Ground albedo: one number for every wavelength, or a table.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged, deny_unknown_fields)]
pub enum Albedo {
    /// Grey albedo in [0, 1].
    Grey(f64),
    /// Per wavelength, linearly interpolated, ends held.
    Table {
        /// Wavelengths (nm), increasing.
        wavelengths_nm: Vec<f64>,
        /// Albedo values in [0, 1].
        values: Vec<f64>,
    },
}

/// The sun's spectral irradiance at the top of the atmosphere.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "kebab-case", deny_unknown_fields)]
pub enum SolarSpectrum {
    /// ASTM G173-03 extraterrestrial spectrum (1366.1 W/m²), 10-nm band means per sample.
    AstmG173,
    /// A table (W·m⁻²·nm⁻¹), linearly interpolated, ends held.
    Table {
        /// Wavelengths (nm), increasing.
        wavelengths_nm: Vec<f64>,
        /// Spectral irradiance (W·m⁻²·nm⁻¹).
        values: Vec<f64>,
    },
    /// Artist terms (Hillaire 2016 §4.1): the ASTM G173 spectral shape scaled so that the
    /// illuminance of the sun at the zenith, seen from the ground through this atmosphere,
    /// is `lux`.
    ZenithIlluminance {
        /// Illuminance at the ground with the sun at the zenith (lx).
        lux: f64,
    },
}

/// Limb-darkening law of the solar disk.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum LimbDarkening {
    /// Uniform disk.
    None,
    /// Neckel (1996), Solar Physics 167, 223–248, polynomial in μ per wavelength.
    Neckel1996,
}

/// The sun.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Sun {
    /// Angular radius (degrees). Mean 0.2666° (959.63″, IAU); 0.2615–0.2725° over the year.
    pub angular_radius_deg: f64,
    /// Spectral irradiance at the top of the atmosphere.
    pub spectrum: SolarSpectrum,
    /// Limb darkening of the disk.
    pub limb_darkening: LimbDarkening,
}

/// Every parameter of an atmosphere.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Atmosphere {
    /// Short name.
    pub name: String,
    /// One line saying what this is.
    #[serde(default)]
    pub description: String,
    /// Planet (ground) radius R_g (m).
    pub bottom_radius_m: f64,
    /// Radius of the top of the atmosphere R_t (m), above `bottom_radius_m`.
    pub top_radius_m: f64,
    /// Lambertian ground albedo in [0, 1].
    pub ground_albedo: Albedo,
    /// Lowest sun elevation (degrees) the scattering tables cover (Bruneton 2017's
    /// `mu_s_min`); below it the sky the sun lights is extrapolated from the tables' last
    /// rows (`Bruneton4dView`'s twilight fade).
    pub min_sun_elevation_deg: f64,
    /// The sun.
    pub sun: Sun,
    /// Molecules, aerosols and absorbers, any number of each.
    pub constituents: Vec<Constituent>,
}

impl Atmosphere {
    /// Parse and validate a TOML document. `base_dir` resolves relative file paths
    /// (tabulated phase functions).
    pub fn from_toml_str(text: &str, base_dir: Option<&Path>) -> Result<Self> {
        let mut atmosphere: Atmosphere =
            toml::from_str(text).map_err(|e| Error::Toml(format!("atmosphere TOML: {e}")))?;
        atmosphere.prepare(base_dir.unwrap_or(Path::new(".")))?;
        atmosphere.validate()?;
        Ok(atmosphere)
    }

    /// Read, parse and validate a TOML file.
    pub fn from_file(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::File {
            path: path.display().to_string(),
            reason: e.to_string(),
        })?;
        Self::from_toml_str(&text, path.parent()).map_err(|e| match e {
            Error::Toml(m) => Error::Toml(format!("{}: {m}", path.display())),
            other => other,
        })
    }

    /// A preset by name (see [`presets::NAMES`]).
    pub fn preset(name: &str) -> Result<Self> {
        let text = presets::toml_text(name)?;
        Self::from_toml_str(text, None)
    }

    /// The default atmosphere (`earth`).
    pub fn earth() -> Self {
        Self::preset("earth").expect("embedded preset is valid")
    }

    /// Load data files the parameters refer to.
    fn prepare(&mut self, base_dir: &Path) -> Result<()> {
        for c in &mut self.constituents {
            c.phase.prepare(base_dir)?;
        }
        Ok(())
    }

    /// Complete TOML for this atmosphere (no comments; presets keep theirs in
    /// [`presets::toml_text`]).
    pub fn to_toml(&self) -> String {
        toml::to_string_pretty(self).expect("atmosphere serialises")
    }

    /// Check every field; the error names the field, the value and the accepted range.
    pub fn validate(&self) -> Result<()> {
        let finite_positive = |field: &str, v: f64| -> Result<()> {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(Error::invalid(field, v, "a finite number > 0"))
            }
        };
        finite_positive("bottom_radius_m", self.bottom_radius_m)?;
        finite_positive("top_radius_m", self.top_radius_m)?;
        if self.top_radius_m <= self.bottom_radius_m {
            return Err(Error::invalid(
                "top_radius_m",
                self.top_radius_m,
                format!("greater than bottom_radius_m ({})", self.bottom_radius_m),
            ));
        }
        match &self.ground_albedo {
            Albedo::Grey(a) => check_unit("ground_albedo", *a)?,
            Albedo::Table {
                wavelengths_nm,
                values,
            } => {
                check_table("ground_albedo", wavelengths_nm, values)?;
                for (i, v) in values.iter().enumerate() {
                    check_unit(&format!("ground_albedo.values[{i}]"), *v)?;
                }
            }
        }
        if !(self.min_sun_elevation_deg.is_finite()
            && (-90.0..=0.0).contains(&self.min_sun_elevation_deg))
        {
            return Err(Error::invalid(
                "min_sun_elevation_deg",
                self.min_sun_elevation_deg,
                "a number in [-90, 0] degrees",
            ));
        }
        let r = self.sun.angular_radius_deg;
        if !(r.is_finite() && r > 0.0 && r < 10.0) {
            return Err(Error::invalid(
                "sun.angular_radius_deg",
                r,
                "a number in (0, 10) degrees",
            ));
        }
        match &self.sun.spectrum {
            SolarSpectrum::AstmG173 => {}
            SolarSpectrum::Table {
                wavelengths_nm,
                values,
            } => {
                check_table("sun.spectrum", wavelengths_nm, values)?;
                for (i, v) in values.iter().enumerate() {
                    if !(v.is_finite() && *v >= 0.0) {
                        return Err(Error::invalid(
                            format!("sun.spectrum.values[{i}]"),
                            v,
                            "a finite irradiance ≥ 0 W/m²/nm",
                        ));
                    }
                }
            }
            SolarSpectrum::ZenithIlluminance { lux } => finite_positive("sun.spectrum.lux", *lux)?,
        }
        if self.constituents.is_empty() {
            return Err(Error::invalid(
                "constituents",
                "[]",
                "at least one constituent",
            ));
        }
        for (i, c) in self.constituents.iter().enumerate() {
            c.validate(&format!("constituents[{i}]"))?;
        }
        limits::check_shell(self)
    }

    /// Resolve for a wavelength grid.
    pub fn resolve(&self, wavelengths: &Wavelengths) -> Result<Model> {
        self.validate()?;
        Ok(Model::new(self, wavelengths))
    }

    /// Whether any constituent of this kind is present.
    pub fn has_kind(&self, kind: ConstituentKind) -> bool {
        self.constituents.iter().any(|c| c.kind == kind)
    }
}

fn check_unit(field: &str, v: f64) -> Result<()> {
    if v.is_finite() && (0.0..=1.0).contains(&v) {
        Ok(())
    } else {
        Err(Error::invalid(field, v, "a number in [0, 1]"))
    }
}

fn check_table(field: &str, wavelengths_nm: &[f64], values: &[f64]) -> Result<()> {
    crate::medium::constituent::check_wavelength_table(
        field,
        "values",
        wavelengths_nm,
        values.len(),
    )
}

/// Linear interpolation in a table with held ends.
pub(crate) fn interpolate_linear(xs: &[f64], ys: &[f64], x: f64) -> f64 {
    if x <= xs[0] {
        return ys[0];
    }
    let n = xs.len();
    if x >= xs[n - 1] {
        return ys[n - 1];
    }
    let i = xs.partition_point(|&v| v <= x) - 1;
    let t = (x - xs[i]) / (xs[i + 1] - xs[i]);
    ys[i] + t * (ys[i + 1] - ys[i])
}

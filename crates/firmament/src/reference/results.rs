//! What the reference path tracer returns: Monte Carlo estimates with their standard errors.

use serde::Serialize;

/// A Monte Carlo estimate of a spectral radiance.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RadianceEstimate {
    /// Mean radiance per wavelength (W·m⁻²·sr⁻¹·nm⁻¹).
    pub radiance: Vec<f64>,
    /// Standard error of each mean (same unit).
    pub stderr: Vec<f64>,
    /// Paths per wavelength.
    pub samples: usize,
}

/// A Monte Carlo estimate of a spectral irradiance (diffuse: the direct sun beam excluded).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct IrradianceEstimate {
    /// Mean irradiance per wavelength (W·m⁻²·nm⁻¹).
    pub irradiance: Vec<f64>,
    /// Standard error of each mean.
    pub stderr: Vec<f64>,
    /// Paths per wavelength.
    pub samples: usize,
}

/// A value per wavelength with its standard error.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Tally {
    /// Mean per wavelength.
    pub value: Vec<f64>,
    /// Standard error per wavelength.
    pub stderr: Vec<f64>,
}

/// Where the power of a collimated beam entering the top of the atmosphere goes, as
/// fractions of that power, per wavelength (photons traced from the sun side).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FluxBudget {
    /// Leaves through the top of the atmosphere.
    pub reflected: Tally,
    /// Absorbed by the ground.
    pub ground_absorbed: Tally,
    /// Absorbed in the air.
    pub medium_absorbed: Tally,
    /// Arrives at the ground without any scattering or reflection (direct beam).
    pub ground_direct: Tally,
    /// Arrives at the ground after at least one scattering or reflection.
    pub ground_diffuse: Tally,
    /// Carried by paths cut at `max_bounces` (bias).
    pub truncated: Tally,
    /// Photons per wavelength.
    pub samples: usize,
}

impl RadianceEstimate {
    /// Luminance (cd/m²) and its standard error (channels are independent).
    pub fn luminance(&self, wavelengths_nm: &[f64]) -> (f64, f64) {
        crate::spectrum::ColourMatrix::new(wavelengths_nm)
            .luminance_and_stderr(&self.radiance, &self.stderr)
    }
}

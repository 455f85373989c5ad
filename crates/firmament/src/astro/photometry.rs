//! Astronomical photometry: magnitudes to illuminance, colour indices to spectra.

use crate::spectrum::ColourMatrix;

/// The visual magnitude of a source giving 1 lx outside the atmosphere:
/// m_V = −13.98 − 2.5 log₁₀(E / lx) (Allen's Astrophysical Quantities, 4th ed., Cox 2000;
/// it gives the sun's 1.27·10⁵ lx at V = −26.74 and the full moon's 0.32 lx at −12.73).
pub const MAGNITUDE_OF_ONE_LUX: f64 = -13.98;

/// Illuminance (lx) outside the atmosphere of a source of visual magnitude `v`.
pub fn illuminance_from_magnitude_lx(v: f64) -> f64 {
    10f64.powf(-0.4 * (v - MAGNITUDE_OF_ONE_LUX))
}

/// Luminance (cd/m²) of a surface brightness of `mag_per_arcsec2` V mag/arcsec².
pub fn luminance_from_surface_brightness(mag_per_arcsec2: f64) -> f64 {
    // One steradian is (180·3600/π)² arcsec².
    let arcsec2_per_sr = (180.0 * 3600.0 / std::f64::consts::PI).powi(2);
    illuminance_from_magnitude_lx(mag_per_arcsec2) * arcsec2_per_sr
}

/// Effective temperature (K) of a star of colour index B−V: Ballesteros (2012), EPL 97,
/// 34008, eq. 14 (black bodies fitted to main-sequence stars).
pub fn temperature_from_b_v(b_v: f64) -> f64 {
    4600.0 * (1.0 / (0.92 * b_v + 1.7) + 1.0 / (0.92 * b_v + 0.62))
}

/// Planck's spectral radiance at `lambda_nm` and `temperature_k`, up to a constant factor
/// (the shape of a star's spectrum): λ⁻⁵ / (exp(hc/λkT) − 1).
pub fn planck_shape(lambda_nm: f64, temperature_k: f64) -> f64 {
    // hc/k = 1.438777·10⁷ nm·K (CODATA 2018 second radiation constant).
    let c2 = 1.438_777e7;
    let l = lambda_nm * 1e-3; // µm, to keep the numbers moderate
    1.0 / (l.powi(5) * ((c2 / (lambda_nm * temperature_k)).exp_m1()))
}

/// `shape` (per channel) scaled so that its illuminance, as the renderer computes
/// luminance from channels (`ColourMatrix`'s Y), is `illuminance_lx`. Zero when the shape
/// has no luminance.
pub fn scale_to_illuminance(shape: &[f64], colour: &ColourMatrix, illuminance_lx: f64) -> Vec<f64> {
    let y = colour.to_xyz(shape)[1];
    let s = if y > 0.0 { illuminance_lx / y } else { 0.0 };
    shape.iter().map(|v| v * s).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zero_point_and_sky_brightness() {
        // The sun, V = −26.74 (Willmer 2018), gives about 1.27·10⁵ lx outside the air.
        let sun = illuminance_from_magnitude_lx(-26.74);
        assert!((sun / 1.27e5 - 1.0).abs() < 0.05, "{sun}");
        // 22 mag/arcsec² is 1.7·10⁻⁴ cd/m² (the usual conversion 10.8·10⁴·10^(−0.4 m)).
        let l = luminance_from_surface_brightness(22.0);
        assert!((l / 1.71e-4 - 1.0).abs() < 0.03, "{l}");
    }

    #[test]
    fn colours_of_stars() {
        // The sun (B−V = 0.65) comes out near 5800 K; Vega (0.0) near 10 000 K.
        assert!((temperature_from_b_v(0.65) - 5800.0).abs() < 150.0);
        assert!((temperature_from_b_v(0.0) - 10_000.0).abs() < 600.0);
        // A hot star is bluer: more at 440 nm than at 680 nm.
        let t = temperature_from_b_v(-0.2);
        assert!(planck_shape(440.0, t) > planck_shape(680.0, t));
        let t = temperature_from_b_v(1.5);
        assert!(planck_shape(440.0, t) < planck_shape(680.0, t));
    }
}

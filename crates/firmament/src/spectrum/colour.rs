//! Colour: spectra to CIE XYZ to linear sRGB ([`ColourMatrix`]), the sRGB transfer function
//! (exact, and a table for whole frames), and white balance to a light's colour.

use std::collections::HashMap;
use std::sync::{Arc, Mutex, OnceLock};

use super::spectrum_to_xyz;
use super::weights::{fit_xyz_weights, generic_family, SolarShape, TrainingSpectrum};

/// The generic weights of a wavelength list, fitted once per list and kept (a fit takes a
/// few milliseconds; luminances are asked for per view).
pub(crate) fn generic_weights(nm: &[f64]) -> Arc<Vec<[f64; 3]>> {
    type Cache = Mutex<HashMap<Vec<u64>, Arc<Vec<[f64; 3]>>>>;
    static CACHE: OnceLock<Cache> = OnceLock::new();
    let key: Vec<u64> = nm.iter().map(|l| l.to_bits()).collect();
    let cache = CACHE.get_or_init(Default::default);
    if let Some(w) = cache.lock().ok().and_then(|c| c.get(&key).cloned()) {
        return w;
    }
    let w = Arc::new(fit_xyz_weights(
        &SolarShape::astm_g173(nm),
        &generic_family(nm),
    ));
    if let Ok(mut c) = cache.lock() {
        c.insert(key, w.clone());
    }
    w
}

/// CIE XYZ → linear sRGB (D65 white), with the matrix of IEC 61966-2-1:1999 (sRGB), §5.2.
/// Units are kept (XYZ in cd/m² → RGB in cd/m² scale); no clamping, no transfer function.
pub fn xyz_to_linear_srgb(xyz: [f64; 3]) -> [f64; 3] {
    const M: [[f64; 3]; 3] = [
        [3.2406, -1.5372, -0.4986],
        [-0.9689, 1.8758, 0.0415],
        [0.0557, -0.2040, 1.0570],
    ];
    let [x, y, z] = xyz;
    M.map(|r| r[0] * x + r[1] * y + r[2] * z)
}

/// Spectral → colour: XYZ = M·L for a set of wavelength samples, then linear sRGB. Rows:
/// X, Y, Z. The weights M are fitted to sky-like spectra under the sun's spectrum
/// ([`super::weights`]), so that three or sixteen samples give the luminance and colour a
/// dense spectrum would; [`ColourMatrix::piecewise_linear`] keeps the plain reading of the
/// samples as a piecewise-linear spectrum.
#[derive(Clone, Debug)]
pub struct ColourMatrix {
    xyz: Vec<[f64; 3]>,
}

impl ColourMatrix {
    /// For these wavelengths under the ASTM G173 sun, fitted to the generic family of sky
    /// spectra ([`super::weights::generic_family`]); cached per wavelength list. An
    /// atmosphere's own matrix (its sun, its constituents' skies) is
    /// `Model::colour_matrix`.
    pub fn new(wavelengths_nm: &[f64]) -> ColourMatrix {
        ColourMatrix {
            xyz: generic_weights(wavelengths_nm).as_ref().clone(),
        }
    }

    /// Fitted to `family` under `sun` ([`super::weights::fit_xyz_weights`]).
    pub fn fitted(sun: &SolarShape, family: &[TrainingSpectrum]) -> ColourMatrix {
        ColourMatrix {
            xyz: fit_xyz_weights(sun, family),
        }
    }

    /// The samples read as a spectrum linearly interpolated between them and held beyond the
    /// ends ([`spectrum_to_xyz`]): exact for such spectra, a few % off for a sky from three
    /// samples (docs/accuracy.md).
    pub fn piecewise_linear(wavelengths_nm: &[f64]) -> ColourMatrix {
        let n = wavelengths_nm.len();
        let xyz = (0..n)
            .map(|k| {
                let mut e = vec![0.0; n];
                e[k] = 1.0;
                spectrum_to_xyz(wavelengths_nm, &e)
            })
            .collect();
        ColourMatrix { xyz }
    }

    /// The weights: `xyz()[k]` multiplies sample k.
    pub fn xyz(&self) -> &[[f64; 3]] {
        &self.xyz
    }

    /// CIE XYZ (Y in cd/m² for radiance in W·m⁻²·sr⁻¹·nm⁻¹): linear in the samples (the
    /// GPU applies the same weights per channel), so a spectrum lit only where fitted
    /// weights dip below zero, at a grid's ends, could read a slightly negative component.
    #[inline]
    pub fn to_xyz(&self, l: &[f64]) -> [f64; 3] {
        let mut o = [0.0; 3];
        for (v, m) in l.iter().zip(&self.xyz) {
            o[0] += v * m[0];
            o[1] += v * m[1];
            o[2] += v * m[2];
        }
        o
    }

    /// Linear sRGB with Y in cd/m².
    #[inline]
    pub fn to_srgb(&self, l: &[f64]) -> [f64; 3] {
        xyz_to_linear_srgb(self.to_xyz(l))
    }

    /// Luminance (cd/m²) and its standard error for a spectrum with independent per-channel
    /// standard errors (the map is linear).
    pub fn luminance_and_stderr(&self, l: &[f64], stderr: &[f64]) -> (f64, f64) {
        let var: f64 = self
            .xyz
            .iter()
            .zip(stderr)
            .map(|(m, e)| (m[1] * e).powi(2))
            .sum();
        (self.to_xyz(l)[1], var.sqrt())
    }

    /// Per-channel factors applied to linear sRGB: with `enabled`, those that make a light of
    /// spectral irradiance `light` white at its own luminance; `[1, 1, 1]` otherwise.
    pub fn white_balance(&self, light: &[f64], enabled: bool) -> [f64; 3] {
        if !enabled {
            return [1.0; 3];
        }
        let rgb = self.to_srgb(light);
        let y = self.to_xyz(light)[1];
        rgb.map(|c| if c > 0.0 { y / c } else { 1.0 })
    }
}

/// Linear [0, 1] to 8-bit sRGB with the IEC 61966-2-1 transfer function
/// (values outside [0, 1] are clamped, NaN gives 0; rounded to nearest).
pub fn encode_srgb(linear: f32) -> u8 {
    let c = if linear.is_nan() {
        0.0
    } else {
        linear.clamp(0.0, 1.0)
    } as f64;
    (linear_to_srgb(c) * 255.0).round().clamp(0.0, 255.0) as u8
}

/// The sRGB transfer function on [0, 1] (IEC 61966-2-1).
pub fn linear_to_srgb(c: f64) -> f64 {
    if c <= 0.0031308 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

/// 8-bit sRGB to linear [0, 1] (inverse of [`encode_srgb`] up to quantisation).
pub fn decode_srgb(srgb: u8) -> f32 {
    srgb_to_linear(srgb as f64 / 255.0) as f32
}

/// [`encode_srgb`] for whole frames: a 2¹⁶-entry table of the 8-bit code of each value in
/// [0, 1] (the code whose interval contains it, by binary search on the 255 decision levels,
/// the decoded mid-points), then one lookup per channel.
pub struct Srgb8Encoder {
    table: Vec<u8>,
}

impl Default for Srgb8Encoder {
    fn default() -> Self {
        Srgb8Encoder::new()
    }
}

impl Srgb8Encoder {
    /// The table.
    pub fn new() -> Srgb8Encoder {
        let levels = srgb_decision_levels();
        let table = (0..=65535u32)
            .map(|i| levels.partition_point(|&l| l <= i as f32 / 65535.0) as u8)
            .collect();
        Srgb8Encoder { table }
    }

    /// The 8-bit code of a linear value (clamped to [0, 1]).
    #[inline]
    pub fn encode(&self, linear: f64) -> u8 {
        self.table[(linear.clamp(0.0, 1.0) * 65535.0 + 0.5) as usize]
    }
}

/// The linear values halfway (in code space) between successive 8-bit sRGB codes.
fn srgb_decision_levels() -> Vec<f32> {
    (0..255)
        .map(|i| srgb_to_linear((i as f64 + 0.5) / 255.0) as f32)
        .collect()
}

/// The sRGB transfer function's inverse on [0, 1] (IEC 61966-2-1).
pub fn srgb_to_linear(e: f64) -> f64 {
    if e <= 0.04045 {
        e / 12.92
    } else {
        ((e + 0.055) / 1.055).powf(2.4)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_transfer() {
        assert_eq!(encode_srgb(0.0), 0);
        assert_eq!(encode_srgb(1.0), 255);
        assert_eq!(encode_srgb(-1.0), 0);
        assert_eq!(encode_srgb(7.0), 255);
        assert_eq!(encode_srgb(f32::NAN), 0);
        // Linear segment: 0.0031308 * 12.92 * 255 = 10.3
        assert_eq!(encode_srgb(0.0031308), 10);
        // Mid grey 0.18 -> 0.4614 -> 118.
        assert_eq!(encode_srgb(0.18), 118);
        assert_eq!(encode_srgb(0.5), 188);
        for v in 0..=255u8 {
            assert_eq!(encode_srgb(decode_srgb(v)), v);
        }
    }
}

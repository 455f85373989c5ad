//! A rendered frame: linear colour in physical units, the projection's mask, and what every
//! frame needs after rendering (the log-average luminance for automatic exposure, tone
//! mapping to 8-bit sRGB).

use rayon::prelude::*;

use super::tonemap::ToneCurve;
use crate::io::ImageRgbF32;
use crate::spectrum::colour::Srgb8Encoder;

/// A rendered frame: linear sRGB (Rec. 709 primaries, D65) scaled so that Y is the
/// luminance in cd/m²; pixels outside the projection are NaN-free zeros with `mask` false.
pub struct Frame {
    /// Linear colour, Y in cd/m².
    pub image: ImageRgbF32,
    /// Whether each pixel is inside the projection.
    pub mask: Vec<bool>,
}

impl Frame {
    /// Log-average luminance over the pixels inside the projection (cd/m²), leaving out
    /// black space (below 10⁻⁶ of the brightest pixel) so a planet seen from orbit is
    /// exposed for itself.
    pub fn log_average_luminance(&self) -> f64 {
        let lum = |p: &[f32; 3]| 0.2126 * p[0] as f64 + 0.7152 * p[1] as f64 + 0.0722 * p[2] as f64;
        let max = self.image.data.iter().map(lum).fold(0.0, f64::max);
        let floor = (max * 1e-6).max(1e-6);
        let mut sum = 0.0;
        let mut count = 0usize;
        for (p, &m) in self.image.data.iter().zip(&self.mask) {
            let y = lum(p);
            if m && y > floor {
                sum += y.ln();
                count += 1;
            }
        }
        if count == 0 {
            return 1.0;
        }
        (sum / count as f64).exp()
    }

    /// Tone-mapped 8-bit sRGB: exposure scale × luminance-scaled colour, then the curve, then
    /// the sRGB transfer function.
    pub fn to_srgb8(&self, exposure: f64, curve: ToneCurve) -> Vec<[u8; 3]> {
        let encoder = Srgb8Encoder::new();
        self.image
            .data
            .par_iter()
            .map(|p| p.map(|v| encoder.encode(curve.apply(v as f64 * exposure))))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spectrum::colour::encode_srgb;

    #[test]
    fn fast_srgb_encoding_equals_the_transfer_function() {
        // Every value the frame's 16-bit table distinguishes, through Frame::to_srgb8 with
        // unit exposure and the plain clamp.
        let values: Vec<f32> = (0..=65535).map(|i| i as f32 / 65535.0).collect();
        let mut image = ImageRgbF32::new(values.len(), 1);
        for (p, &v) in image.data.iter_mut().zip(&values) {
            *p = [v; 3];
        }
        let frame = Frame {
            mask: vec![true; values.len()],
            image,
        };
        let codes = frame.to_srgb8(1.0, ToneCurve::Clamp);
        let mut mismatches = 0;
        for (&v, c) in values.iter().zip(&codes) {
            let fast = c[0];
            let exact = encode_srgb(v);
            // Ties at a decision level may round either way in f32.
            if fast != exact {
                mismatches += 1;
                assert!((fast as i32 - exact as i32).abs() <= 1);
            }
        }
        assert!(mismatches < 20, "{mismatches}");
    }
}

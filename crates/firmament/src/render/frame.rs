//! A rendered frame: linear colour in physical units, the projection's mask, and what every
//! frame needs after rendering (the log-average luminance for automatic exposure, tone
//! mapping to 8-bit sRGB).

use rayon::prelude::*;

use super::tonemap::ToneCurve;
use crate::io::ImageRgbF32;
use crate::math::hash;
use crate::spectrum::colour::{linear_to_srgb, Srgb8Encoder};
use crate::spectrum::gamut::{self, Gamut};

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

    /// Tone-mapped 8-bit sRGB: the colour mapped into Rec. 709's gamut at its luminance
    /// ([`gamut::map_into_gamut`]: no channel clipped at 0), the exposure scale, the curve per
    /// channel, then the sRGB transfer function rounded to the nearest code.
    pub fn to_srgb8(&self, exposure: f64, curve: ToneCurve) -> Vec<[u8; 3]> {
        let encoder = Srgb8Encoder::new();
        let weights = Gamut::Rec709.luminance_weights();
        self.image
            .data
            .par_iter()
            .map(|p| {
                let c = gamut::map_into_gamut(p.map(f64::from), weights);
                c.map(|v| encoder.encode(curve.apply(v * exposure)))
            })
            .collect()
    }

    /// [`Frame::to_srgb8`] with triangular-PDF dither of ±1 code before rounding (two
    /// uniform variates per channel from a hash of the pixel: the same image every time), so
    /// slow gradients (a twilight sky) do not band: the quantisation error becomes noise
    /// independent of the signal (Lipshitz, Wannamaker & Vanderkooy 1992, "Quantization and
    /// dither: a theoretical survey", J. Audio Eng. Soc. 40).
    pub fn to_srgb8_dithered(&self, exposure: f64, curve: ToneCurve) -> Vec<[u8; 3]> {
        let codes = Srgb8Codes::new();
        let weights = Gamut::Rec709.luminance_weights();
        let w = self.image.width;
        self.image
            .data
            .par_iter()
            .enumerate()
            .map(|(i, p)| {
                let c = gamut::map_into_gamut(p.map(f64::from), weights);
                let (x, y) = ((i % w) as i32, (i / w) as i32);
                std::array::from_fn(|k| {
                    let code = codes.code(curve.apply(c[k] * exposure));
                    let (a, b) = (
                        hash::unit(hash::hash32(2 * k as u32, x, y)),
                        hash::unit(hash::hash32(2 * k as u32 + 1, x, y)),
                    );
                    (code + a - b).round().clamp(0.0, 255.0) as u8
                })
            })
            .collect()
    }

    /// The frame's colours in `gamut` (converted from Rec. 709 and mapped into it at their
    /// luminance: no negative component), for image files.
    pub fn in_gamut(&self, gamut: Gamut) -> ImageRgbF32 {
        let m = gamut.from_rec709();
        let weights = gamut.luminance_weights();
        let mut out = ImageRgbF32::new(self.image.width, self.image.height);
        out.data
            .par_iter_mut()
            .zip(&self.image.data)
            .for_each(|(o, p)| {
                let c = gamut::apply(&m, p.map(f64::from));
                *o = gamut::map_into_gamut(c, weights).map(|v| v as f32);
            });
        out
    }
}

/// The sRGB code (0 to 255, not rounded) of linear values in [0, 1]: a 2¹⁶-entry table.
struct Srgb8Codes {
    table: Vec<f32>,
}

impl Srgb8Codes {
    fn new() -> Srgb8Codes {
        let table = (0..=65535u32)
            .map(|i| (255.0 * linear_to_srgb(i as f64 / 65535.0)) as f32)
            .collect();
        Srgb8Codes { table }
    }

    #[inline]
    fn code(&self, linear: f64) -> f64 {
        self.table[(linear.clamp(0.0, 1.0) * 65535.0 + 0.5) as usize] as f64
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

    /// Dither is unbiased and takes the bands out of a slow gradient: across a ramp of
    /// 0.4 code over 1 000 columns, the column means of 200 rows follow the exact code, where
    /// rounding gives two flat bands.
    #[test]
    fn dither_follows_a_slow_gradient() {
        let (w, h) = (1000, 200);
        let mut image = ImageRgbF32::new(w, h);
        for y in 0..h {
            for x in 0..w {
                let code = 100.3 + 0.4 * x as f64 / (w - 1) as f64;
                let v = crate::spectrum::colour::srgb_to_linear(code / 255.0) as f32;
                image.data[y * w + x] = [v; 3];
            }
        }
        let frame = Frame {
            mask: vec![true; w * h],
            image,
        };
        let plain = frame.to_srgb8(1.0, ToneCurve::Clamp);
        let dithered = frame.to_srgb8_dithered(1.0, ToneCurve::Clamp);
        let mut worst: f64 = 0.0;
        let mut plain_worst: f64 = 0.0;
        for x in 0..w {
            let exact = 100.3 + 0.4 * x as f64 / (w - 1) as f64;
            let mean = |codes: &[[u8; 3]]| {
                (0..h).map(|y| codes[y * w + x][1] as f64).sum::<f64>() / h as f64
            };
            worst = worst.max((mean(&dithered) - exact).abs());
            plain_worst = plain_worst.max((mean(&plain) - exact).abs());
        }
        // The mean of 200 samples of ±1 triangular noise: standard error 0.03 code.
        assert!(worst < 0.15, "dithered column means off by {worst}");
        assert!(plain_worst > 0.25, "rounding should band: {plain_worst}");
    }

    /// Colours outside Rec. 709 (a sunset sun's blue below zero) reach files and 8-bit
    /// codes mapped at their luminance, never negative; a wider gamut holds them as they are.
    #[test]
    fn out_of_gamut_colours_are_mapped_at_their_luminance() {
        let mut image = ImageRgbF32::new(2, 1);
        image.data[0] = [5.0e4, 1.8e4, -1.0e3];
        image.data[1] = [0.2, 0.3, 0.4];
        let frame = Frame {
            mask: vec![true; 2],
            image,
        };
        let w = Gamut::Rec709.luminance_weights();
        let y = |p: [f32; 3]| w[0] * p[0] as f64 + w[1] * p[1] as f64 + w[2] * p[2] as f64;
        let mapped = frame.in_gamut(Gamut::Rec709);
        assert!(
            mapped.data[0].iter().all(|&v| v >= 0.0),
            "{:?}",
            mapped.data[0]
        );
        assert!((y(mapped.data[0]) / y(frame.image.data[0]) - 1.0).abs() < 1e-6);
        assert_eq!(mapped.data[1], frame.image.data[1]);
        // In Rec. 2020 the same orange is inside: converted, not desaturated (its
        // luminance in Rec. 2020's weights equals the Rec. 709 one).
        let wide = frame.in_gamut(Gamut::Rec2020);
        assert!(wide.data[0].iter().all(|&v| v > 0.0), "{:?}", wide.data[0]);
        let w2 = Gamut::Rec2020.luminance_weights();
        let y2 = w2[0] * wide.data[0][0] as f64
            + w2[1] * wide.data[0][1] as f64
            + w2[2] * wide.data[0][2] as f64;
        assert!((y2 / y(frame.image.data[0]) - 1.0).abs() < 1e-4, "{y2}");
    }
}

//! Compact storage of the 4D scattering tables: half floats with a power-of-two scale per
//! texel, half the bytes of f32 (a spectral table file at the default sizes: 131 MB in place
//! of 253 MB).
//!
//! A plain half float (11 significant bits, normal from 6.1·10⁻⁵ to 65 504) cannot hold the
//! tables' range: radiances in W·m⁻²·sr⁻¹·nm⁻¹ span about 10⁻¹ under a high sun to 10⁻¹⁵
//! and below in deep twilight and from high altitudes. So each texel's channels share a
//! scale 2^k (one signed byte) chosen so that the texel's largest magnitude lands in
//! [2¹⁴, 2¹⁵): every channel within a factor 2⁻²⁹ ≈ 1.9·10⁻⁹ of the texel's largest keeps
//! its 11 significant bits (a relative error ≤ 2⁻¹¹ ≈ 4.9·10⁻⁴ after rounding), fainter ones fade
//! through half's subnormals to 0, where they are 10⁹ times below their neighbours and
//! weigh nothing in any colour. The scale is a power of two, so applying it is exact.
//!
//! The 2D tables stay f32: the optical depth τ (up to [`super::table::MAX_OPTICAL_DEPTH`])
//! would lose up to τ·2⁻¹¹ of transmittance, 1 % at τ = 20 near the horizon, and both 2D
//! tables together are 1 % of a file. `docs/accuracy.md` has the measured errors.

use half::f16;

/// The scale exponent of a texel whose largest magnitude is `max` (finite, ≥ 0): k with
/// max·2^(−k) in [2¹⁴, 2¹⁵), floored at −128 (a texel below 2⁻¹¹³ keeps only subnormals).
fn texel_exponent(max: f32) -> i8 {
    if max <= 0.0 || !max.is_finite() {
        return 0;
    }
    // max = m·2^e with m in [1, 2): e = floor(log2 max), exact from the bits.
    let bits = max.to_bits();
    let biased = ((bits >> 23) & 0xff) as i32;
    let e = if biased == 0 {
        // Subnormal, frac·2⁻¹⁴⁹: the exponent of its leading bit.
        -118 - (bits & 0x7f_ffff).leading_zeros() as i32
    } else {
        biased - 127
    };
    (e - 14).clamp(-128, 127) as i8
}

/// 2^k as f64 for every i8 k, indexed by k + 128.
fn scales() -> [f64; 256] {
    let mut s = [0.0; 256];
    for (i, v) in s.iter_mut().enumerate() {
        *v = 2f64.powi(i as i32 - 128);
    }
    s
}

/// Bytes taken by `texels` texels of `channels` values: one exponent byte per texel, then
/// two bytes per value.
pub fn encoded_len(texels: usize, channels: usize) -> usize {
    texels * (1 + 2 * channels)
}

/// Append `data` (texels of `channels` f32 each, channels innermost) to `out`: first every
/// texel's exponent k (i8), then every value v as the little-endian half float of v·2^(−k).
pub fn encode(data: &[f32], channels: usize, out: &mut Vec<u8>) {
    let texels = data.len() / channels;
    let exponents: Vec<i8> = data
        .chunks_exact(channels)
        .map(|t| texel_exponent(t.iter().fold(0.0f32, |m, v| m.max(v.abs()))))
        .collect();
    out.reserve(encoded_len(texels, channels));
    out.extend(exponents.iter().map(|&k| k as u8));
    for (texel, &k) in data.chunks_exact(channels).zip(&exponents) {
        let inverse = 2f64.powi(-(k as i32));
        for &v in texel {
            out.extend_from_slice(&f16::from_f64(v as f64 * inverse).to_le_bytes());
        }
    }
}

/// The values [`encode`] wrote for `texels` texels of `channels` values; `bytes` holds
/// exactly [`encoded_len`] bytes.
pub fn decode(bytes: &[u8], texels: usize, channels: usize) -> Vec<f32> {
    debug_assert_eq!(bytes.len(), encoded_len(texels, channels));
    let (exponents, halves) = bytes.split_at(texels);
    let scales = scales();
    let mut out = Vec::with_capacity(texels * channels);
    for (&k, texel) in exponents.iter().zip(halves.chunks_exact(2 * channels)) {
        let scale = scales[(k as i8 as i32 + 128) as usize];
        out.extend(
            texel
                .chunks_exact(2)
                .map(|h| (f16::from_le_bytes([h[0], h[1]]).to_f64() * scale) as f32),
        );
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exponent_puts_the_largest_value_in_the_top_octave_below_2_to_15() {
        for v in [
            1.0f32,
            0.7,
            3.0e-12,
            1.0e-40,
            2.5e5,
            f32::MAX,
            f32::MIN_POSITIVE,
            1.0e-34,
        ] {
            let k = texel_exponent(v) as i32;
            let scaled = v as f64 * 2f64.powi(-k);
            assert!(
                (16384.0..32768.0).contains(&scaled) || k == -128,
                "{v}: k {k}, scaled {scaled}"
            );
        }
        assert_eq!(texel_exponent(0.0), 0);
    }

    #[test]
    fn values_within_a_texel_keep_half_precision_over_nine_decades() {
        // One texel of 6 channels spanning 10⁰ to 10⁻⁸, one deep-twilight texel, one zero.
        let data = [
            1.0f32, 0.3, 1.0e-3, 2.0e-5, 7.0e-7, 1.0e-8, //
            3.0e-18, 1.0e-19, 2.0e-20, 5.0e-21, 0.0, 1.0e-22, //
            0.0, 0.0, 0.0, 0.0, 0.0, 0.0,
        ];
        let mut bytes = Vec::new();
        encode(&data, 6, &mut bytes);
        assert_eq!(bytes.len(), encoded_len(3, 6));
        let back = decode(&bytes, 3, 6);
        for (a, b) in data.iter().zip(&back) {
            let err = if *a == 0.0 {
                b.abs() as f64
            } else {
                ((b - a) / a).abs() as f64
            };
            assert!(err <= 2f64.powi(-11), "{a} read back as {b}");
        }
    }

    #[test]
    fn the_faintest_texels_take_the_lowest_scale() {
        let data = [1.0e-36f32, 3.0e-37, 0.0];
        let mut bytes = Vec::new();
        encode(&data, 3, &mut bytes);
        assert_eq!(bytes[0] as i8, -128);
        let back = decode(&bytes, 1, 3);
        assert!((back[0] / data[0] - 1.0).abs() < 1e-3, "{back:?}");
    }

    #[test]
    fn negative_values_keep_their_sign() {
        // Largest magnitude 0.5 = 2⁻¹: scaled by 2¹⁵.
        let data = [-0.25f32, 0.5, -1.0e-3];
        let mut bytes = Vec::new();
        encode(&data, 3, &mut bytes);
        let back = decode(&bytes, 1, 3);
        let expected = data.map(|v| (f16::from_f64(v as f64 * 32768.0).to_f64() / 32768.0) as f32);
        assert_eq!(back, expected);
        assert!(back[0] < 0.0 && back[2] < 0.0);
    }
}

//! The method against the reference over a frame: the panel's figures (the mean
//! luminances' relative difference and the mean |ΔL|/L) and the false-colour image of
//! `--reference difference` (red where the method is brighter, blue where darker, white
//! where they agree, fully coloured at ±[`FULL_SCALE`]). Frames are RGBA per pixel (linear
//! sRGB with Y in cd/m², the projection's mask in alpha), as the GPU's HDR frame holds them.

/// The relative difference the false colour saturates at.
pub const FULL_SCALE: f64 = 0.10;

/// Pixels brighter than this (cd/m²) hold a light's disk (the sun's is ~10⁹), which the
/// method splats as a point below four pixels and the tracer draws where a pixel's centre
/// meets it: compared apart from the sky, as `tests/view.rs` does.
const DISK_CD_M2: f64 = 1.0e6;

/// The false colour's ends (linear sRGB): the method darker, brighter.
const DARKER: [f64; 3] = [0.10, 0.30, 1.0];
const BRIGHTER: [f64; 3] = [1.0, 0.15, 0.10];
/// What pixels left out (outside the projection, unlit, on a disk) show: mid grey.
const LEFT_OUT: f64 = 0.2;

/// Luminance (Rec. 709 / sRGB primaries) of a linear sRGB pixel.
pub fn luminance(p: &[f32]) -> f64 {
    0.2126 * p[0] as f64 + 0.7152 * p[1] as f64 + 0.0722 * p[2] as f64
}

/// The luminances (method, reference) of a pixel pair that is compared: inside both frames,
/// lit in the reference, off the lights' disks; None for a pair left out.
fn compared(m: &[f32], r: &[f32]) -> Option<(f64, f64)> {
    let (lm, lr) = (luminance(m), luminance(r));
    (m[3] >= 0.5 && r[3] >= 0.5 && lm <= DISK_CD_M2 && lr <= DISK_CD_M2 && lr > 0.0)
        .then_some((lm, lr))
}

/// `method` against `reference`: the relative difference of their mean luminances and the
/// mean of |ΔL|/L over the compared pixels.
pub fn difference(method: &[f32], reference: &[f32]) -> Option<(f64, f64)> {
    let (mut sm, mut sr, mut rel, mut n) = (0.0, 0.0, 0.0, 0usize);
    let pairs = method.chunks_exact(4).zip(reference.chunks_exact(4));
    for (lm, lr) in pairs.filter_map(|(m, r)| compared(m, r)) {
        sm += lm;
        sr += lr;
        rel += (lm - lr).abs() / lr;
        n += 1;
    }
    (sr > 0.0 && n > 0).then(|| (sm / sr - 1.0, rel / n as f64))
}

/// The false-colour image of `method` against `reference` (RGBA, mask 1 everywhere), at the
/// method's mean luminance over the compared pixels (so that the frame's exposure shows it):
/// white where ΔL/L = 0, towards [`BRIGHTER`] or [`DARKER`] linearly up to ±[`FULL_SCALE`].
pub fn false_colour(method: &[f32], reference: &[f32]) -> Vec<f32> {
    let (mut sum, mut n) = (0.0, 0usize);
    let pairs = method.chunks_exact(4).zip(reference.chunks_exact(4));
    for (lm, _) in pairs.filter_map(|(m, r)| compared(m, r)) {
        sum += lm;
        n += 1;
    }
    let level = if n > 0 { sum / n as f64 } else { 1.0 };
    let mut out = Vec::with_capacity(method.len());
    for (m, r) in method.chunks_exact(4).zip(reference.chunks_exact(4)) {
        let rgb = if let Some((lm, lr)) = compared(m, r) {
            let e = lm / lr - 1.0;
            let t = (e / FULL_SCALE).clamp(-1.0, 1.0);
            let end = if t < 0.0 { DARKER } else { BRIGHTER };
            let a = t.abs();
            end.map(|c| 1.0 + a * (c - 1.0))
        } else {
            [LEFT_OUT; 3]
        };
        out.extend(rgb.map(|c| (c * level) as f32));
        out.push(1.0);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn px(y: f32) -> [f32; 4] {
        [y, y, y, 1.0]
    }

    #[test]
    fn the_false_colour_is_white_where_they_agree_and_saturates_at_full_scale() {
        // Pixels: equal, the method 5 % brighter, 30 % darker, outside the projection.
        let reference: Vec<f32> = [px(100.0), px(100.0), px(100.0), [1.0, 1.0, 1.0, 0.0]].concat();
        let method: Vec<f32> = [px(100.0), px(105.0), px(70.0), px(1.0)].concat();
        let c = false_colour(&method, &reference);
        // At the method's mean luminance over the three compared pixels.
        let level = (100.0 + 105.0 + 70.0) / 3.0;
        let p = |i: usize| [c[4 * i] as f64, c[4 * i + 1] as f64, c[4 * i + 2] as f64];
        for (got, want) in p(0).iter().zip([level; 3]) {
            assert!((got - want).abs() < 1e-3 * level);
        }
        // Half way to red at +5 % (full scale 10 %).
        let half = BRIGHTER.map(|b| level * (1.0 + 0.5 * (b - 1.0)));
        for (got, want) in p(1).iter().zip(half) {
            assert!((got - want).abs() < 1e-3 * level, "{got} {want}");
        }
        // Saturated blue at −30 %.
        for (got, want) in p(2).iter().zip(DARKER.map(|b| level * b)) {
            assert!((got - want).abs() < 1e-3 * level, "{got} {want}");
        }
        assert_eq!(p(3).map(|v| (v / level * 10.0).round()), [2.0; 3]);
        let (bias, mean_abs) = difference(&method, &reference).unwrap();
        assert!((bias - (275.0 / 300.0 - 1.0)).abs() < 1e-12);
        assert!((mean_abs - 0.35 / 3.0).abs() < 1e-12);
    }
}

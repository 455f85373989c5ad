//! Exposure and tone mapping: physical exposure in EV100 (Lagarde & de Rousiers 2014,
//! "Moving Frostbite to PBR" §5.1), automatic exposure from the scene's mean log luminance,
//! and three curves.

use serde::{Deserialize, Serialize};

/// Tone curve.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum ToneCurve {
    /// ACES filmic fit of Narkowicz 2015 ("ACES Filmic Tone Mapping Curve").
    #[default]
    Aces,
    /// Hable 2010 ("Filmic Tonemapping Operators", Uncharted 2) with white point 11.2.
    Filmic,
    /// Plain clamp to [0, 1].
    Clamp,
}

impl ToneCurve {
    /// Parse `aces`, `filmic`, `clamp`.
    pub fn parse(s: &str) -> crate::Result<ToneCurve> {
        match s {
            "aces" => Ok(ToneCurve::Aces),
            "filmic" => Ok(ToneCurve::Filmic),
            "clamp" => Ok(ToneCurve::Clamp),
            _ => Err(crate::Error::invalid(
                "tonemap",
                s,
                "one of aces, filmic, clamp",
            )),
        }
    }

    /// Map an exposed linear value to [0, 1].
    #[inline]
    pub fn apply(self, x: f64) -> f64 {
        let x = x.max(0.0);
        match self {
            ToneCurve::Aces => {
                let (a, b, c, d, e) = (2.51, 0.03, 2.43, 0.59, 0.14);
                ((x * (a * x + b)) / (x * (c * x + d) + e)).clamp(0.0, 1.0)
            }
            ToneCurve::Filmic => {
                let f = |x: f64| {
                    let (a, b, c, d, e, f) = (0.15, 0.50, 0.10, 0.20, 0.02, 0.30);
                    ((x * (a * x + c * b) + d * e) / (x * (a * x + b) + d * f)) - e / f
                };
                (f(2.0 * x) / f(11.2)).clamp(0.0, 1.0)
            }
            ToneCurve::Clamp => x.min(1.0),
        }
    }
}

/// The reflected-light meter calibration constant K (cd·s/m², ISO 2720): a meter at ISO 100
/// reads EV100 = log2(L·100/K) for luminance L.
pub const METER_K: f64 = 12.5;

/// Display mid-grey: an 18 % reflectance card, linear (sRGB code 118).
pub const DISPLAY_MID_GREY: f64 = 0.18;

impl ToneCurve {
    /// The exposed value that the curve maps to `y` in (0, 1) (bisection; the curves are
    /// monotonic).
    pub fn inverse(self, y: f64) -> f64 {
        let (mut lo, mut hi) = (0.0, 1.0);
        while self.apply(hi) < y && hi < 1e6 {
            hi *= 2.0;
        }
        for _ in 0..80 {
            let mid = 0.5 * (lo + hi);
            if self.apply(mid) < y {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        0.5 * (lo + hi)
    }
}

/// The luminance (cd/m²) a light meter reads as `ev100` (ISO 2720): 2^EV100·K/100.
pub fn metered_luminance(ev100: f64) -> f64 {
    2f64.powf(ev100) * METER_K / 100.0
}

/// Scale from luminance (cd/m²) to exposed values for EV100 and a tone curve, as a camera
/// renders a photograph: the luminance its meter reads at that EV lands on display
/// mid-grey after the curve (a camera's JPEG rendering does the same; the saturation-based
/// scale 1/(1.2·2^EV) of Lagarde & de Rousiers 2014 alone put it at 0.104 before the
/// curve, 0.13 after ACES: a noon sky came out navy). Sunny 16: an 18 % card under
/// 100 klx (5730 cd/m²) at EV100 15 shows at 1.4 × mid-grey before the curve.
pub fn exposure_from_ev100(ev100: f64, curve: ToneCurve) -> f64 {
    curve.inverse(DISPLAY_MID_GREY) / metered_luminance(ev100)
}

/// EV100 that a reflected-light meter (K = 12.5, ISO 2720) reads for the scene's average
/// luminance: EV100 = log2(L_avg·100/K). With [`exposure_from_ev100`] that average shows
/// at display mid-grey.
pub fn auto_ev100(mean_luminance_cd_m2: f64) -> f64 {
    (mean_luminance_cd_m2.max(1e-6) * 100.0 / METER_K).log2()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn curves_are_monotonic_and_bounded() {
        for c in [ToneCurve::Aces, ToneCurve::Filmic, ToneCurve::Clamp] {
            let mut prev = -1.0;
            for i in 0..1000 {
                let y = c.apply(i as f64 * 0.02);
                assert!((0.0..=1.0).contains(&y) && y >= prev);
                prev = y;
            }
            assert_eq!(c.apply(0.0), 0.0f64.max(c.apply(0.0)));
        }
    }

    #[test]
    fn sunny_16_exposure() {
        // Sunny-16 daylight scenes are EV100 ≈ 15: a meter reads 2^15·12.5/100 = 4096
        // cd/m² there, which every curve shows at display mid-grey.
        assert!((auto_ev100(4096.0) - 15.0).abs() < 1e-9);
        for c in [ToneCurve::Aces, ToneCurve::Filmic, ToneCurve::Clamp] {
            let shown = c.apply(exposure_from_ev100(15.0, c) * 4096.0);
            assert!((shown - 0.18).abs() < 1e-9, "{c:?}: {shown}");
        }
        // The clamp curve is the identity below 1: mid-grey exposes to exactly 0.18.
        assert!((ToneCurve::Clamp.inverse(0.18) - 0.18).abs() < 1e-12);
        // A mid-grey card under 100 klx in sunshine (L = 0.18·100000/π ≈ 5730 cd/m²) is a
        // little brighter than the meter's average: 1.4 × mid-grey at EV100 15.
        let e = exposure_from_ev100(15.0, ToneCurve::Clamp);
        assert!((e * 5730.0 / 0.18 - 1.4).abs() < 0.01);
    }
}

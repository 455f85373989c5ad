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

/// Scale from luminance (cd/m²) to exposed values for EV100: 1/L_max with
/// L_max = 1.2·2^EV100 (saturation-based sensitivity, ISO 100, q = 0.65).
pub fn exposure_from_ev100(ev100: f64) -> f64 {
    1.0 / (1.2 * 2f64.powf(ev100))
}

/// EV100 from the average scene luminance with the reflected-light meter calibration
/// K = 12.5 (ISO 2720): EV100 = log2(L_avg·100/K).
pub fn auto_ev100(mean_luminance_cd_m2: f64) -> f64 {
    (mean_luminance_cd_m2.max(1e-6) * 100.0 / 12.5).log2()
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
        // Sunny-16 daylight scenes are EV100 ≈ 15; a mid-grey 18 % surface under 100 klx
        // has L = 0.18·100000/π ≈ 5730 cd/m², which exposes to about 0.0011·5730 ≈ 0.15.
        let e = exposure_from_ev100(15.0);
        assert!((e * 5730.0 - 0.146).abs() < 0.01);
        assert!((auto_ev100(4096.0) - 15.0).abs() < 1e-9);
    }
}

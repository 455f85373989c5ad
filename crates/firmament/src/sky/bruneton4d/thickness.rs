//! What optical thickness the tables handle. Bruneton's precomputation sums a few
//! scattering orders (and a geometric tail when the last two decrease); in optically thick
//! air the orders first grow (light scattered out of the beam is scattered again before it
//! leaves), the tail cannot be estimated, and more orders gather the tables' own
//! interpolation error instead. Measured (`hazy` with its haze's Ångström β raised; small
//! tables, `rgb`, ground, sun 60°; luminance of the tables over the reference at 20 000
//! paths, ±1–3 %, for the zenith, 30° up away from the sun, 10° up towards it;
//! docs/accuracy.md):
//!
//! | β | τ_s at 440 nm | 4 orders (+ tail) |
//! |---|---|---|
//! | 0.2 (the preset) | 0.65 | 1.06, 1.03, 1.02 |
//! | 0.5 | 1.26 | 1.13, 1.11, 1.02 |
//! | 1 | 2.3 | 1.11, 0.96, 0.64 |
//! | 2 | 4.3 | 0.68, 0.25, 0.04 |
//!
//! (10 orders for β = 2 read 1.12, 0.90, 1.25; 15 orders 1.09, 1.53: more orders do not
//! converge to the reference.) So the tables warn above [`THICK_SCATTERING_DEPTH`] and
//! refuse above [`MAX_SCATTERING_DEPTH`]; the reference path tracer takes any depth.

use crate::atmosphere::Model;
use crate::{Error, Result};

/// Vertical scattering optical depth (at the most scattering wavelength) above which the
/// tables' multiple scattering is off by 10 % and more: a note.
pub const THICK_SCATTERING_DEPTH: f64 = 1.0;
/// Above this the tables' sky is off by a factor of 2 and more: refused.
pub const MAX_SCATTERING_DEPTH: f64 = 3.0;

/// The vertical scattering optical depth of the whole air, at its most scattering
/// wavelength among the model's, and that wavelength (nm).
pub fn scattering_depth(model: &Model) -> (f64, f64) {
    let height = model.height_m();
    (0..model.channels())
        .map(|k| {
            let tau: f64 = (model.constituents.iter())
                .map(|c| c.scattering[k] * c.density.column_m(0.0, height))
                .sum();
            (tau, model.wavelengths.nm()[k])
        })
        .fold((0.0, 0.0), |a, b| if b.0 > a.0 { b } else { a })
}

/// Refuses a model too thick for the tables ([`MAX_SCATTERING_DEPTH`]).
pub fn check(model: &Model) -> Result<()> {
    let (tau, nm) = scattering_depth(model);
    if tau > MAX_SCATTERING_DEPTH {
        return Err(Error::invalid(
            "constituents (vertical scattering optical depth)",
            format!("{tau:.2} at {nm} nm"),
            format!(
                "at most {MAX_SCATTERING_DEPTH} for the precomputed tables: in air this thick \
                 their multiple scattering is off by a factor of 2 and more (docs/accuracy.md); \
                 the reference path tracer (--method reference) takes any depth"
            ),
        ));
    }
    Ok(())
}

/// What is approximated for a model thicker than [`THICK_SCATTERING_DEPTH`] (for `query`'s
/// notes and `render`'s stderr); None below it.
pub fn note(model: &Model) -> Option<String> {
    let (tau, nm) = scattering_depth(model);
    (tau > THICK_SCATTERING_DEPTH).then(|| {
        format!(
            "optically thick air: a vertical scattering optical depth of {tau:.2} at {nm} nm \
             (above {THICK_SCATTERING_DEPTH}): the tables' multiple scattering is off by 10 % \
             and more here, most towards the horizon (docs/accuracy.md); --method reference \
             is exact"
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::atmosphere::Atmosphere;
    use crate::spectrum::Wavelengths;

    #[test]
    fn presets_are_thin_enough_and_thick_haze_is_named() {
        for preset in ["earth", "bruneton2008", "hazy", "frostbite2016"] {
            for w in [Wavelengths::rgb(), Wavelengths::spectral()] {
                let model = Atmosphere::preset(preset).unwrap().resolve(&w).unwrap();
                assert!(check(&model).is_ok(), "{preset}");
                if preset != "hazy" {
                    assert!(note(&model).is_none(), "{preset}");
                }
            }
        }
    }
}

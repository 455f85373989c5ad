//! The same atmosphere over higher ground: the bottom sphere raised by a lift and the air
//! below it taken away, every constituent's density and coefficient at each remaining
//! point unchanged. A terrain's sky uses it: the tables' ground is put at the terrain's
//! floor, so their light comes from the air that is there and not from the air that the
//! terrain displaces (docs/accuracy.md, "Terrain scenes against the reference").

use super::{Atmosphere, SolarSpectrum};
use crate::medium::Coefficient;
use crate::spectrum::Wavelengths;
use crate::{Error, Result};

impl Atmosphere {
    /// This atmosphere with its ground `lift_m` (m) higher. Coefficients normalised by the
    /// vertical column (Rayleigh cross-section, ozone column, Ångström) are rescaled by the
    /// share of the column that remains, so the coefficient at density 1 is the same; a sun
    /// given as a zenith illuminance at the ground becomes its resolved spectrum at
    /// `wavelengths` (the sun outside the air does not move with the ground).
    pub fn lifted(&self, lift_m: f64, wavelengths: &Wavelengths) -> Result<Atmosphere> {
        let height = self.top_radius_m - self.bottom_radius_m;
        // Keep at least 1 km of air: the tables need a layer to parametrise.
        if !(lift_m.is_finite() && lift_m >= 0.0 && lift_m < height - 1000.0) {
            return Err(Error::invalid(
                "ground lift (m)",
                lift_m,
                format!("a number in [0, {}) m", height - 1000.0),
            ));
        }
        if lift_m == 0.0 {
            return Ok(self.clone());
        }
        let mut out = self.clone();
        if let SolarSpectrum::ZenithIlluminance { .. } = self.sun.spectrum {
            let model = self.resolve(wavelengths)?;
            out.sun.spectrum = SolarSpectrum::Table {
                wavelengths_nm: wavelengths.nm().to_vec(),
                values: model.solar_irradiance,
            };
        }
        out.bottom_radius_m += lift_m;
        out.description = format!("{} (ground lifted {lift_m:.1} m)", self.description);
        for c in &mut out.constituents {
            let old = c.density.column_m(0.0, height);
            c.density = c.density.lifted(lift_m);
            let new = c.density.column_m(0.0, height - lift_m);
            let share = if old > 0.0 { new / old } else { 0.0 };
            for coefficient in [&mut c.scattering, &mut c.absorption] {
                match coefficient {
                    Coefficient::RayleighCrossSection { column_m2 } => *column_m2 *= share,
                    Coefficient::OzoneColumn { column_du } => *column_du *= share,
                    Coefficient::Angstrom { beta, .. } => *beta *= share,
                    Coefficient::None
                    | Coefficient::Constant { .. }
                    | Coefficient::Table { .. }
                    | Coefficient::PowerLaw { .. } => {}
                }
            }
        }
        out.validate()?;
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_lifted_air_is_the_air_above_the_lift() {
        let wavelengths = Wavelengths::rgb();
        for name in ["earth", "frostbite2016", "mars"] {
            let a = Atmosphere::preset(name).unwrap();
            let m = a.resolve(&wavelengths).unwrap();
            let lift = 705.0;
            let l = a
                .lifted(lift, &wavelengths)
                .unwrap()
                .resolve(&wavelengths)
                .unwrap();
            assert_eq!(l.bottom_radius_m, m.bottom_radius_m + lift);
            assert_eq!(l.top_radius_m, m.top_radius_m);
            // Same extinction everywhere above the lift, and the vertical optical depth
            // from the new ground is the old one from the lift's altitude.
            let (mut x, mut y) = (vec![0.0; 3], vec![0.0; 3]);
            for h in [0.0, 100.0, 1500.0, 9000.0, 24_000.0, 50_000.0] {
                l.extinction_into(h, &mut x);
                m.extinction_into(h + lift, &mut y);
                for k in 0..3 {
                    assert!(
                        (x[k] / y[k] - 1.0).abs() < 1e-9,
                        "{name} h {h}: {x:?} {y:?}"
                    );
                }
            }
            let (tl, tm) = (
                l.optical_depths_vertical(0.0).total,
                m.optical_depths_vertical(lift).total,
            );
            for k in 0..3 {
                assert!(
                    (tl[k] / tm[k] - 1.0).abs() < 1e-6,
                    "{name}: {tl:?} vs {tm:?}"
                );
            }
            assert_eq!(l.solar_irradiance, m.solar_irradiance, "{name}");
        }
    }

    #[test]
    fn a_lift_through_the_top_is_refused() {
        let a = Atmosphere::earth();
        let err = a
            .lifted(59_500.0, &Wavelengths::rgb())
            .unwrap_err()
            .to_string();
        assert!(err.contains("ground lift"), "{err}");
        assert!(a.lifted(f64::NAN, &Wavelengths::rgb()).is_err());
    }
}

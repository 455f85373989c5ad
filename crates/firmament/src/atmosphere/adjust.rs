//! The few numbers users turn on an atmosphere without writing one: the aerosols' optical
//! depth, the ozone column, the air's Rayleigh scattering, the ground's albedo and the
//! planet's radius. Each rescales what the atmosphere already holds (its profiles, its
//! phase functions and its spectral shapes stay), so any preset or file can be adjusted,
//! and the result is an ordinary [`Atmosphere`]: tables, renderer and reference all see the
//! same thing, and the table cache keys on it as on any other.
//!
//! Scene files carry them as `[atmosphere.adjust]`; `query`, `bake` and `render` take them as
//! flags (`--aerosol-optical-depth`, `--ozone-du`, `--rayleigh-scale`, `--ground-albedo`,
//! `--planet-radius-m`); the viewer's panel turns them live.

use serde::{Deserialize, Serialize};

use super::{Albedo, Atmosphere};
use crate::medium::constituent::DOBSON_UNIT_M2;
use crate::medium::{Coefficient, ConstituentKind};
use crate::spectrum::{self, Wavelengths};
use crate::{Error, Result};

/// The wavelength at which the aerosol optical depth is given (nm): 550 nm, the
/// convention of AERONET's and MODIS's AOD products (Remer et al. 2005, J. Atmos. Sci. 62).
pub const AOD_WAVELENGTH_NM: f64 = 550.0;

/// The wavelength at which an absorber's column is read as ozone (nm): 602 nm, near the peak
/// of ozone's Chappuis band, where the embedded cross-section is largest in the visible.
pub const OZONE_READ_NM: f64 = 602.0;

/// Accepted ranges, one per field (inclusive).
pub const AOD_RANGE: (f64, f64) = (0.0, 3.0);
/// Ozone column (DU): 0 to a little over three times the largest ever measured (~650 DU).
pub const OZONE_RANGE_DU: (f64, f64) = (0.0, 2000.0);
/// Factor on the molecules' scattering.
pub const RAYLEIGH_SCALE_RANGE: (f64, f64) = (0.0, 10.0);
/// Planet radius (m): from a 100 km moonlet to 100 000 km (a gas giant's size).
pub const PLANET_RADIUS_RANGE_M: (f64, f64) = (1.0e5, 1.0e8);

/// Adjustments to an atmosphere; every field absent means "as the atmosphere has it".
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Adjustments {
    /// Vertical optical depth of the aerosols' extinction at 550 nm ([`AOD_WAVELENGTH_NM`]),
    /// in [0, 3]: every aerosol constituent's scattering and absorption scaled by one factor
    /// (its Ångström exponent, single-scattering albedo and profile kept).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub aerosol_optical_depth: Option<f64>,
    /// Total ozone column (Dobson units), in [0, 2000]: the absorbers' absorption scaled so
    /// that their optical depth at 602 nm is that of this column with the embedded ozone
    /// cross-section (exact for an `ozone-column` absorber).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ozone_du: Option<f64>,
    /// Factor on the molecules' scattering (1: as given), in [0, 10]; 2 is twice the air's
    /// column (a planet with twice Earth's surface pressure, as far as the sky can tell).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rayleigh_scale: Option<f64>,
    /// A grey ground albedo in [0, 1] in place of the atmosphere's.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ground_albedo: Option<f64>,
    /// The planet's radius (m), in [1e5, 1e8]: the atmosphere's top moves with the ground,
    /// keeping its thickness, so every vertical profile and optical depth stays.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub planet_radius_m: Option<f64>,
}

impl Adjustments {
    /// No adjustment at all.
    pub fn is_empty(&self) -> bool {
        *self == Adjustments::default()
    }

    /// Check each field against its range; the error names the field.
    pub fn validate(&self) -> Result<()> {
        let check = |field: &str, v: Option<f64>, (lo, hi): (f64, f64), unit: &str| match v {
            Some(v) if !(v.is_finite() && (lo..=hi).contains(&v)) => Err(Error::invalid(
                format!("adjust.{field}"),
                v,
                format!("a number in [{lo}, {hi}]{unit}"),
            )),
            _ => Ok(()),
        };
        check(
            "aerosol_optical_depth",
            self.aerosol_optical_depth,
            AOD_RANGE,
            "",
        )?;
        check("ozone_du", self.ozone_du, OZONE_RANGE_DU, " DU")?;
        check(
            "rayleigh_scale",
            self.rayleigh_scale,
            RAYLEIGH_SCALE_RANGE,
            "",
        )?;
        check("ground_albedo", self.ground_albedo, (0.0, 1.0), "")?;
        check(
            "planet_radius_m",
            self.planet_radius_m,
            PLANET_RADIUS_RANGE_M,
            " m",
        )
    }
}

impl Atmosphere {
    /// This atmosphere with `adjust` applied (itself when there is nothing to apply). An
    /// optical depth or column asked of a constituent the atmosphere lacks (an aerosol
    /// depth on an atmosphere without aerosols) is refused, with the field named.
    pub fn adjusted(&self, adjust: &Adjustments) -> Result<Atmosphere> {
        adjust.validate()?;
        if adjust.is_empty() {
            return Ok(self.clone());
        }
        let mut out = self.clone();
        let mut said = Vec::new();
        if let Some(aod) = adjust.aerosol_optical_depth {
            let now = self.aerosol_optical_depth()?;
            if now <= 0.0 {
                return Err(Error::invalid(
                    "adjust.aerosol_optical_depth",
                    aod,
                    format!(
                        "absent: the atmosphere '{}' has no aerosols to scale",
                        self.name
                    ),
                ));
            }
            out.scale(ConstituentKind::Aerosols, aod / now, true);
            said.push(format!("AOD(550 nm) {aod}"));
        }
        if let Some(du) = adjust.ozone_du {
            let now = self.ozone_du()?;
            if now <= 0.0 {
                return Err(Error::invalid(
                    "adjust.ozone_du",
                    du,
                    format!(
                        "absent: the atmosphere '{}' has no absorber to scale",
                        self.name
                    ),
                ));
            }
            out.scale(ConstituentKind::Absorber, du / now, false);
            said.push(format!("ozone {du} DU"));
        }
        if let Some(f) = adjust.rayleigh_scale {
            out.scale(ConstituentKind::Molecules, f, true);
            said.push(format!("Rayleigh ×{f}"));
        }
        if let Some(a) = adjust.ground_albedo {
            out.ground_albedo = Albedo::Grey(a);
            said.push(format!("ground albedo {a}"));
        }
        if let Some(r) = adjust.planet_radius_m {
            let height = self.top_radius_m - self.bottom_radius_m;
            out.bottom_radius_m = r;
            out.top_radius_m = r + height;
            said.push(format!("planet radius {r} m"));
        }
        out.description = format!("{} (adjusted: {})", self.description, said.join(", "));
        out.validate()?;
        Ok(out)
    }

    /// The aerosols' vertical extinction optical depth at 550 nm.
    pub fn aerosol_optical_depth(&self) -> Result<f64> {
        Ok(self.vertical_depths(AOD_WAVELENGTH_NM)?.mie[0])
    }

    /// The absorbers' column read as ozone (DU): their vertical optical depth at 602 nm over
    /// ozone's cross-section there.
    pub fn ozone_du(&self) -> Result<f64> {
        let tau = self.vertical_depths(OZONE_READ_NM)?.ozone[0];
        Ok(tau / (spectrum::ozone_cross_section_m2(OZONE_READ_NM) * DOBSON_UNIT_M2))
    }

    fn vertical_depths(&self, nm: f64) -> Result<super::OpticalDepths> {
        let model = self.resolve(&Wavelengths::from_list(&[nm])?)?;
        Ok(model.optical_depths_vertical(0.0))
    }

    /// Multiply the coefficients of every constituent of `kind` by `factor` (absorption
    /// always, scattering when `scattering`).
    fn scale(&mut self, kind: ConstituentKind, factor: f64, scattering: bool) {
        for c in self.constituents.iter_mut().filter(|c| c.kind == kind) {
            c.absorption = c.absorption.scaled(factor);
            if scattering {
                c.scattering = c.scattering.scaled(factor);
            }
        }
    }
}

impl Coefficient {
    /// The coefficient times `factor` at every wavelength (the spectral shape kept).
    pub fn scaled(&self, factor: f64) -> Coefficient {
        let mut c = self.clone();
        match &mut c {
            Coefficient::None => {}
            Coefficient::Constant { value_per_m } | Coefficient::PowerLaw { value_per_m, .. } => {
                *value_per_m *= factor
            }
            Coefficient::Table { values_per_m, .. } => {
                values_per_m.iter_mut().for_each(|v| *v *= factor)
            }
            Coefficient::RayleighCrossSection { column_m2 } => *column_m2 *= factor,
            Coefficient::OzoneColumn { column_du } => *column_du *= factor,
            Coefficient::Angstrom { beta, .. } => *beta *= factor,
        }
        c
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn depths(a: &Atmosphere, nm: &[f64]) -> super::super::OpticalDepths {
        a.resolve(&Wavelengths::from_list(nm).unwrap())
            .unwrap()
            .optical_depths_vertical(0.0)
    }

    #[test]
    fn the_aerosol_depth_is_the_one_asked_and_keeps_its_spectral_shape() {
        for preset in ["earth", "hazy", "bruneton2008", "frostbite2016", "mars"] {
            let a = Atmosphere::preset(preset).unwrap();
            let before = depths(&a, &[440.0, 550.0, 680.0]).mie;
            let b = a
                .adjusted(&Adjustments {
                    aerosol_optical_depth: Some(0.5),
                    ..Default::default()
                })
                .unwrap();
            let after = depths(&b, &[440.0, 550.0, 680.0]).mie;
            assert!((after[1] - 0.5).abs() < 1e-12, "{preset}: {after:?}");
            // The same spectral shape: the ratios of the samples hold.
            for k in [0, 2] {
                let r = (after[k] / after[1]) / (before[k] / before[1]);
                assert!((r - 1.0).abs() < 1e-12, "{preset}: {r}");
            }
            // The other groups do not move.
            assert_eq!(depths(&a, &[550.0]).rayleigh, depths(&b, &[550.0]).rayleigh);
        }
    }

    #[test]
    fn the_ozone_column_reads_back_in_dobson_units() {
        let earth = Atmosphere::earth();
        // The preset's own column: 300 DU of the embedded cross-section.
        assert!((earth.ozone_du().unwrap() - 300.0).abs() < 1e-9);
        let b = earth
            .adjusted(&Adjustments {
                ozone_du: Some(450.0),
                ..Default::default()
            })
            .unwrap();
        assert!((b.ozone_du().unwrap() - 450.0).abs() < 1e-9);
        // Independently: the optical depth at 602 nm is σ·N for N = 450 DU.
        let tau = depths(&b, &[OZONE_READ_NM]).ozone[0];
        let expected = spectrum::ozone_cross_section_m2(OZONE_READ_NM) * 450.0 * DOBSON_UNIT_M2;
        assert!((tau / expected - 1.0).abs() < 1e-9, "{tau} {expected}");
        // A tabulated absorber (Hillaire's ozone) scales too.
        let f = Atmosphere::preset("frostbite2016").unwrap();
        let g = f
            .adjusted(&Adjustments {
                ozone_du: Some(2.0 * f.ozone_du().unwrap()),
                ..Default::default()
            })
            .unwrap();
        let (a, b) = (depths(&f, &[550.0]).ozone[0], depths(&g, &[550.0]).ozone[0]);
        assert!((b / a - 2.0).abs() < 1e-12);
    }

    #[test]
    fn rayleigh_albedo_and_radius_do_what_they_say() {
        let earth = Atmosphere::earth();
        let b = earth
            .adjusted(&Adjustments {
                rayleigh_scale: Some(2.0),
                ground_albedo: Some(0.8),
                planet_radius_m: Some(3.3895e6),
                ..Default::default()
            })
            .unwrap();
        let (da, db) = (depths(&earth, &[440.0]), depths(&b, &[440.0]));
        assert!((db.rayleigh[0] / da.rayleigh[0] - 2.0).abs() < 1e-12);
        assert_eq!(da.mie, db.mie);
        assert_eq!(da.ozone, db.ozone);
        assert_eq!(b.ground_albedo, Albedo::Grey(0.8));
        assert_eq!(b.bottom_radius_m, 3.3895e6);
        assert_eq!(
            b.top_radius_m - b.bottom_radius_m,
            earth.top_radius_m - earth.bottom_radius_m
        );
        assert!(b.description.contains("Rayleigh ×2"), "{}", b.description);
        // Nothing asked: the same atmosphere (and so the same tables in the cache).
        assert_eq!(earth.adjusted(&Adjustments::default()).unwrap(), earth);
    }

    #[test]
    fn out_of_range_values_and_missing_constituents_are_refused_by_name() {
        let earth = Atmosphere::earth();
        for (adjust, field) in [
            (
                Adjustments {
                    aerosol_optical_depth: Some(-0.1),
                    ..Default::default()
                },
                "adjust.aerosol_optical_depth",
            ),
            (
                Adjustments {
                    ozone_du: Some(f64::NAN),
                    ..Default::default()
                },
                "adjust.ozone_du",
            ),
            (
                Adjustments {
                    rayleigh_scale: Some(11.0),
                    ..Default::default()
                },
                "adjust.rayleigh_scale",
            ),
            (
                Adjustments {
                    ground_albedo: Some(1.5),
                    ..Default::default()
                },
                "adjust.ground_albedo",
            ),
            (
                Adjustments {
                    planet_radius_m: Some(0.0),
                    ..Default::default()
                },
                "adjust.planet_radius_m",
            ),
        ] {
            let e = earth.adjusted(&adjust).unwrap_err().to_string();
            assert!(e.contains(field), "{e}");
        }
        // Mars has no absorber: an ozone column is refused, not silently ignored.
        let e = Atmosphere::preset("mars")
            .unwrap()
            .adjusted(&Adjustments {
                ozone_du: Some(300.0),
                ..Default::default()
            })
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("adjust.ozone_du") && e.contains("no absorber"),
            "{e}"
        );
    }
}

//! `validate --reference FILE`: the reference of an earlier run (its `--json` file) reused,
//! so that a change to a sky method is measured against the very same Monte Carlo
//! estimates in seconds instead of the reference's tens of minutes, and before/after
//! figures differ by the method alone (no second draw of the reference's noise).
//!
//! A configuration (atmosphere label, observer altitude, sun elevation) found in the file
//! takes its views' estimates from it, and must hold every view this run asks for (the same
//! directions, to 10⁻⁶ degree); a configuration the file lacks is traced as usual. The
//! file's wavelengths must be this run's.

use std::path::Path;

use anyhow::{Context, Result};
use firmament::reference::RadianceEstimate;
use serde_json::Value;

use super::views::View;

/// How close (degrees) a view's elevation and azimuth must be to the file's.
const DIRECTION_TOLERANCE_DEG: f64 = 1e-6;

/// The reference estimates read from an earlier run's JSON file.
pub struct StoredReference {
    path: String,
    configurations: Vec<StoredConfiguration>,
}

struct StoredConfiguration {
    preset: String,
    altitude_m: f64,
    sun_elevation_deg: f64,
    /// (elevation, azimuth from the sun) in degrees, and the estimate.
    views: Vec<(f64, f64, RadianceEstimate)>,
}

impl StoredReference {
    /// Read `path`, a `validate --json` file, whose wavelengths must be `wavelengths_nm`.
    pub fn read(path: &Path, wavelengths_nm: &[f64]) -> Result<StoredReference> {
        let text = std::fs::read_to_string(path)
            .with_context(|| format!("--reference: reading {}", path.display()))?;
        let value: Value = serde_json::from_str(&text).with_context(|| {
            format!(
                "--reference: {} is not JSON (accepted: the file of `validate --json`)",
                path.display()
            )
        })?;
        Self::from_value(&value, &path.display().to_string(), wavelengths_nm)
    }

    fn from_value(value: &Value, path: &str, wavelengths_nm: &[f64]) -> Result<StoredReference> {
        let bad = |what: &str| {
            anyhow::anyhow!(
                "--reference: {path} has no valid `{what}` (accepted: the file of `validate --json`)"
            )
        };
        let stored: Vec<f64> = value["wavelengths_nm"]
            .as_array()
            .ok_or_else(|| bad("wavelengths_nm"))?
            .iter()
            .map(|v| v.as_f64().ok_or_else(|| bad("wavelengths_nm")))
            .collect::<Result<_>>()?;
        if stored.len() != wavelengths_nm.len()
            || stored
                .iter()
                .zip(wavelengths_nm)
                .any(|(a, b)| (a - b).abs() > 1e-9)
        {
            anyhow::bail!(
                "--reference: {path} was traced at wavelengths {stored:?} nm, this run uses {wavelengths_nm:?} nm (accepted: a file of the same --wavelengths)"
            );
        }
        let configurations = value["configurations"]
            .as_array()
            .ok_or_else(|| bad("configurations"))?
            .iter()
            .map(|c| {
                let views = c["views"]
                    .as_array()
                    .ok_or_else(|| bad("configurations[].views"))?
                    .iter()
                    .map(|v| {
                        let r = &v["reference"];
                        let list = |key: &str| -> Result<Vec<f64>> {
                            r[key]
                                .as_array()
                                .filter(|a| a.len() == wavelengths_nm.len())
                                .ok_or_else(|| bad(&format!("views[].reference.{key}")))?
                                .iter()
                                .map(|x| x.as_f64().ok_or_else(|| bad("views[].reference")))
                                .collect()
                        };
                        let number = |x: &Value, key: &str| {
                            x.as_f64().ok_or_else(|| bad(&format!("views[].{key}")))
                        };
                        Ok((
                            number(&v["elevation_deg"], "elevation_deg")?,
                            number(&v["azimuth_from_sun_deg"], "azimuth_from_sun_deg")?,
                            RadianceEstimate {
                                radiance: list("radiance")?,
                                stderr: list("stderr")?,
                                samples: r["samples"]
                                    .as_u64()
                                    .ok_or_else(|| bad("views[].reference.samples"))?
                                    as usize,
                            },
                        ))
                    })
                    .collect::<Result<_>>()?;
                Ok(StoredConfiguration {
                    preset: c["preset"]
                        .as_str()
                        .ok_or_else(|| bad("configurations[].preset"))?
                        .to_string(),
                    altitude_m: c["altitude_m"]
                        .as_f64()
                        .ok_or_else(|| bad("configurations[].altitude_m"))?,
                    sun_elevation_deg: c["sun_elevation_deg"]
                        .as_f64()
                        .ok_or_else(|| bad("configurations[].sun_elevation_deg"))?,
                    views,
                })
            })
            .collect::<Result<_>>()?;
        Ok(StoredReference {
            path: path.to_string(),
            configurations,
        })
    }

    /// The stored estimates of `views` in the configuration (`preset`, `altitude_m`,
    /// `sun_elevation_deg`); `None` where the file lacks the configuration, an error where
    /// it has it but not every view.
    pub fn estimates(
        &self,
        preset: &str,
        altitude_m: f64,
        sun_elevation_deg: f64,
        views: &[View],
    ) -> Result<Option<Vec<RadianceEstimate>>> {
        let Some(c) = self.configurations.iter().find(|c| {
            c.preset == preset
                && c.altitude_m == altitude_m
                && c.sun_elevation_deg == sun_elevation_deg
        }) else {
            return Ok(None);
        };
        views
            .iter()
            .map(|v| {
                c.views
                    .iter()
                    .find(|(e, a, _)| {
                        (e - v.elevation_deg).abs() <= DIRECTION_TOLERANCE_DEG
                            && (a - v.azimuth_from_sun_deg).abs() <= DIRECTION_TOLERANCE_DEG
                    })
                    .map(|(_, _, estimate)| estimate.clone())
                    .ok_or_else(|| {
                        anyhow::anyhow!(
                            "--reference: {} has {preset}, {altitude_m} m, sun {sun_elevation_deg}° but not its view at elevation {:.4}°, azimuth {:.4}° from the sun (the view set has changed since: trace a new reference with --json)",
                            self.path,
                            v.elevation_deg,
                            v.azimuth_from_sun_deg
                        )
                    })
            })
            .collect::<Result<_>>()
            .map(Some)
    }

    /// The file's name, for the headline and the JSON.
    pub fn path(&self) -> &str {
        &self.path
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use firmament::math::Vec3;
    use serde_json::json;

    fn view(elevation_deg: f64, azimuth_from_sun_deg: f64) -> View {
        View {
            elevation_deg,
            azimuth_from_sun_deg,
            sun_distance_deg: 0.0,
            dir: Vec3::new(0.0, 0.0, 1.0),
        }
    }

    fn file() -> Value {
        let record = |e: f64, a: f64, l: f64| {
            json!({
                "elevation_deg": e, "azimuth_from_sun_deg": a,
                "reference": {"radiance": [l, 2.0 * l], "stderr": [0.1, 0.2], "samples": 4096},
            })
        };
        json!({
            "wavelengths_nm": [680.0, 440.0],
            "configurations": [{
                "preset": "hazy", "altitude_m": 1000.0, "sun_elevation_deg": 30.0,
                "views": [record(0.49999999999999784, 0.0, 1.0), record(60.0, 135.0, 3.0)],
            }],
        })
    }

    #[test]
    fn stored_views_are_found_by_direction_and_missing_ones_refused() {
        let stored = StoredReference::from_value(&file(), "f.json", &[680.0, 440.0]).unwrap();
        let got = stored
            .estimates("hazy", 1000.0, 30.0, &[view(60.0, 135.0), view(0.5, 0.0)])
            .unwrap()
            .unwrap();
        assert_eq!(got[0].radiance, vec![3.0, 6.0]);
        assert_eq!(got[1].radiance, vec![1.0, 2.0]);
        assert_eq!((got[1].stderr[1], got[1].samples), (0.2, 4096));
        // Another configuration: not in the file, traced as usual.
        assert!(stored
            .estimates("hazy", 1000.0, 10.0, &[view(60.0, 135.0)])
            .unwrap()
            .is_none());
        assert!(stored
            .estimates("earth", 1000.0, 30.0, &[view(60.0, 135.0)])
            .unwrap()
            .is_none());
        // The configuration without one of the views asked for: refused, naming it.
        let e = stored
            .estimates("hazy", 1000.0, 30.0, &[view(60.0, 90.0)])
            .unwrap_err()
            .to_string();
        assert!(e.contains("azimuth 90.0000°"), "{e}");
    }

    #[test]
    fn another_wavelength_set_or_a_foreign_file_is_refused() {
        let e = StoredReference::from_value(&file(), "f.json", &[680.0, 550.0, 440.0])
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("wavelengths") && e.contains("f.json"), "{e}");
        let e = StoredReference::from_value(&json!({"a": 1}), "g.json", &[680.0])
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("wavelengths_nm") && e.contains("g.json"), "{e}");
    }
}

//! Layered density profiles (Bruneton 2017's `DensityProfile`, generalised to any number of
//! layers): in each layer the dimensionless density at altitude h (m) is
//! `exp_term·exp(−h/H) + linear_term·h + constant_term`, clamped to ≥ 0. Exponential
//! (H_R = 8 km, paper §2.1), tent (ozone, Bruneton 2017) and uniform-slab atmospheres are
//! all expressible.

use serde::{Deserialize, Serialize};

use crate::math::quadrature::GL4;
use crate::{Error, Result};

/// One layer of a density profile.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DensityLayer {
    /// Thickness of the layer (m); the last layer extends to the top of the atmosphere
    /// whatever its width.
    #[serde(default)]
    pub width_m: f64,
    /// Coefficient of the exponential term (dimensionless).
    #[serde(default)]
    pub exp_term: f64,
    /// Scale height H (m) of the exponential term; `inf` (or 0 with exp_term 0) for none.
    #[serde(default = "infinite")]
    pub scale_height_m: f64,
    /// Coefficient of the linear term (per metre of altitude).
    #[serde(default)]
    pub linear_term_per_m: f64,
    /// Constant term (dimensionless).
    #[serde(default)]
    pub constant_term: f64,
}

fn infinite() -> f64 {
    f64::INFINITY
}

impl DensityLayer {
    /// An exponential layer e^{−h/H}, infinitely thick.
    pub fn exponential(scale_height_m: f64) -> Self {
        DensityLayer {
            width_m: 0.0,
            exp_term: 1.0,
            scale_height_m,
            linear_term_per_m: 0.0,
            constant_term: 0.0,
        }
    }

    /// A uniform layer of density `c`.
    pub fn constant(width_m: f64, c: f64) -> Self {
        DensityLayer {
            width_m,
            exp_term: 0.0,
            scale_height_m: f64::INFINITY,
            linear_term_per_m: 0.0,
            constant_term: c,
        }
    }

    /// A linear layer `a·h + c`.
    pub fn linear(width_m: f64, a: f64, c: f64) -> Self {
        DensityLayer {
            width_m,
            exp_term: 0.0,
            scale_height_m: f64::INFINITY,
            linear_term_per_m: a,
            constant_term: c,
        }
    }

    #[inline]
    fn density(&self, altitude_m: f64) -> f64 {
        let e = if self.exp_term != 0.0 {
            self.exp_term * (-altitude_m / self.scale_height_m).exp()
        } else {
            0.0
        };
        (e + self.linear_term_per_m * altitude_m + self.constant_term).max(0.0)
    }
}

/// A stack of layers from the ground up.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(transparent)]
pub struct DensityProfile {
    /// Layers from the ground up; altitudes inside each layer are measured from the ground.
    pub layers: Vec<DensityLayer>,
}

impl DensityProfile {
    /// One exponential layer.
    pub fn exponential(scale_height_m: f64) -> Self {
        DensityProfile {
            layers: vec![DensityLayer::exponential(scale_height_m)],
        }
    }

    /// Uniform density 1 everywhere.
    pub fn uniform() -> Self {
        DensityProfile {
            layers: vec![DensityLayer::constant(0.0, 1.0)],
        }
    }

    /// A tent: 0 below `bottom_m`, rising linearly to 1 at `peak_m`, back to 0 at `top_m`
    /// (Bruneton 2017's ozone layer uses 10, 25, 40 km).
    pub fn tent(bottom_m: f64, peak_m: f64, top_m: f64) -> Self {
        let up = 1.0 / (peak_m - bottom_m);
        let down = 1.0 / (top_m - peak_m);
        DensityProfile {
            layers: vec![
                DensityLayer::linear(peak_m, up, -bottom_m * up),
                DensityLayer::linear(0.0, -down, top_m * down),
            ],
        }
    }

    /// Dimensionless density at `altitude_m` above the ground.
    #[inline]
    pub fn density(&self, altitude_m: f64) -> f64 {
        let mut base = 0.0;
        let n = self.layers.len();
        for (i, layer) in self.layers.iter().enumerate() {
            if i + 1 == n || altitude_m < base + layer.width_m {
                return layer.density(altitude_m);
            }
            base += layer.width_m;
        }
        0.0
    }

    /// The same air seen from a ground `lift_m` higher: the density at altitude h of the
    /// result is this profile's at h + `lift_m` (layers wholly below the new ground dropped,
    /// the first one left shortened, each term re-expressed about the new ground:
    /// a·e^{−(h+l)/H} = (a·e^{−l/H})·e^{−h/H}, b·(h+l) + c = b·h + (b·l + c)).
    pub fn lifted(&self, lift_m: f64) -> DensityProfile {
        let n = self.layers.len();
        let mut layers = Vec::with_capacity(n);
        let mut base = 0.0;
        for (i, layer) in self.layers.iter().enumerate() {
            let last = i + 1 == n;
            let top = base + layer.width_m;
            if last || top > lift_m {
                let exp_term = if layer.exp_term != 0.0 {
                    layer.exp_term * (-lift_m / layer.scale_height_m).exp()
                } else {
                    0.0
                };
                layers.push(DensityLayer {
                    width_m: if last {
                        layer.width_m
                    } else {
                        top - base.max(lift_m)
                    },
                    exp_term,
                    scale_height_m: layer.scale_height_m,
                    linear_term_per_m: layer.linear_term_per_m,
                    constant_term: layer.constant_term + layer.linear_term_per_m * lift_m,
                });
            }
            base = top;
        }
        DensityProfile { layers }
    }

    /// Altitudes (m) where the profile may have a kink (layer boundaries, and where linear
    /// terms cross zero), within [0, top_m]; used to split quadratures.
    pub fn breakpoints(&self, top_m: f64) -> Vec<f64> {
        let mut points = Vec::new();
        let mut base = 0.0;
        for (i, layer) in self.layers.iter().enumerate() {
            if layer.linear_term_per_m != 0.0 && layer.exp_term == 0.0 {
                let zero = -layer.constant_term / layer.linear_term_per_m;
                if zero > 0.0 && zero < top_m {
                    points.push(zero);
                }
            }
            if i + 1 < self.layers.len() {
                base += layer.width_m;
                if base > 0.0 && base < top_m {
                    points.push(base);
                }
            }
        }
        points.sort_by(f64::total_cmp);
        points.dedup();
        points
    }

    /// Vertical integral ∫ density dh (m) from `from_m` to `to_m` (altitudes), by composite
    /// Gauss–Legendre between breakpoints; exact to ~1e-10 for these smooth pieces.
    pub fn column_m(&self, from_m: f64, to_m: f64) -> f64 {
        let mut edges = vec![from_m];
        edges.extend(
            self.breakpoints(to_m)
                .into_iter()
                .filter(|&b| b > from_m && b < to_m),
        );
        edges.push(to_m);
        let mut sum = 0.0;
        for w in edges.windows(2) {
            sum += GL4.integrate(w[0], w[1], 64, |h| self.density(h));
        }
        sum
    }

    /// Check every number; `field` is the profile's path for messages.
    pub fn validate(&self, field: &str) -> Result<()> {
        if self.layers.is_empty() {
            return Err(Error::invalid(field, "[]", "at least one layer"));
        }
        for (i, l) in self.layers.iter().enumerate() {
            let f = |name: &str| format!("{field}[{i}].{name}");
            if !(l.width_m.is_finite() && l.width_m >= 0.0) {
                return Err(Error::invalid(
                    f("width_m"),
                    l.width_m,
                    "a finite width ≥ 0 m",
                ));
            }
            if l.scale_height_m.is_nan() || l.scale_height_m <= 0.0 {
                return Err(Error::invalid(
                    f("scale_height_m"),
                    l.scale_height_m,
                    "a scale height > 0 m (inf for none)",
                ));
            }
            for (name, v) in [
                ("exp_term", l.exp_term),
                ("linear_term_per_m", l.linear_term_per_m),
                ("constant_term", l.constant_term),
            ] {
                if !v.is_finite() {
                    return Err(Error::invalid(f(name), v, "a finite number"));
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exponential_column_matches_closed_form() {
        let p = DensityProfile::exponential(8000.0);
        let exact = 8000.0 * (1.0 - (-60_000.0f64 / 8000.0).exp());
        assert!((p.column_m(0.0, 60_000.0) / exact - 1.0).abs() < 1e-10);
    }

    #[test]
    fn a_lifted_profile_is_the_same_air_from_higher_ground() {
        // The earth preset's three shapes: exponential, tent, and a slab under a decay.
        let slab = DensityProfile {
            layers: vec![
                DensityLayer::constant(2000.0, 1.0),
                DensityLayer {
                    exp_term: 2.0,
                    ..DensityLayer::exponential(3000.0)
                },
            ],
        };
        let profiles = [
            DensityProfile::exponential(8434.0),
            DensityProfile::tent(10_000.0, 25_000.0, 40_000.0),
            slab,
        ];
        for p in &profiles {
            for lift in [0.0, 705.0, 2000.0, 12_000.0, 30_000.0] {
                let q = p.lifted(lift);
                for k in 0..200 {
                    let h = k as f64 * 250.0;
                    let (a, b) = (q.density(h), p.density(h + lift));
                    assert!(
                        (a - b).abs() < 1e-12 * (1.0 + b),
                        "{p:?} lift {lift} h {h}: {a} vs {b}"
                    );
                }
                let (a, b) = (q.column_m(0.0, 60_000.0 - lift), p.column_m(lift, 60_000.0));
                assert!((a / b - 1.0).abs() < 1e-9, "{a} vs {b}");
            }
        }
    }

    #[test]
    fn tent_has_its_shape_and_area() {
        let p = DensityProfile::tent(10_000.0, 25_000.0, 40_000.0);
        assert_eq!(p.density(5_000.0), 0.0);
        assert!((p.density(25_000.0) - 1.0).abs() < 1e-12);
        assert!((p.density(17_500.0) - 0.5).abs() < 1e-12);
        assert_eq!(p.density(50_000.0), 0.0);
        assert!((p.column_m(0.0, 60_000.0) - 15_000.0).abs() < 1e-6);
    }
}

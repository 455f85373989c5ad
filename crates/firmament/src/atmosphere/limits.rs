//! What the tables' quadratures resolve: each constituent's layer against the thickness of
//! the shell between the ground and the top.
//!
//! A constituent's *layer thickness* is its column over its peak density, ∫ρ dh / max ρ
//! over [0, top − bottom] (its scale height for an exponential, 15 km for the ozone tent).
//! The passes sample the shell at fixed counts whatever its thickness: the coefficients are
//! normalised by a column of 64 Gauss–Legendre panels (`DensityProfile::column_m`), the
//! optical depths take 128 panels and the scattering integrals 50 steps along a ray, and
//! the tables' r rows spread over the whole shell (u_r = ρ/H). A layer much thinner than
//! the shell falls between the samples: a top at 10¹² m over Earth's air gave a zero
//! Rayleigh optical depth and a black sky; a shell thick for its air, orders that gained
//! energy.

use std::cell::Cell;

use super::Atmosphere;
use crate::math::quadrature::GL4;
use crate::medium::{Coefficient, Constituent, DensityProfile};
use crate::{Error, Result};

/// The largest shell thickness over a constituent's layer thickness the tables accept. The
/// column's 64 four-point Gauss–Legendre panels are then at most 3.1 layer thicknesses
/// wide, where the rule's error on an exponential is below 10⁻⁴ (it grows as the ninth
/// power of the panel: 6 % at 500, a 1.2 km haze under a 600 km shell).
pub const MAX_SHELL_OVER_LAYER: f64 = 200.0;

/// The largest shell thickness over the scattering air's thickest layer the tables accept:
/// about √(H/Δ) of the r rows lie below one layer thickness H of a shell Δ thick (u_r =
/// ρ/H_ρ, ρ ≈ √(2R·h)), 37 % (12 of 32 rows) for `earth` (Δ/H = 7.1), 22 % at 20. Beyond,
/// the orders stop converging: Earth's air with a white ground under a 350 km top (41)
/// gained energy with every order (sky irradiance at 440 nm 0.28, 0.61, 1.02 W·m⁻²·nm⁻¹ for
/// 2, 3, 4 orders, 4.8 for 8, the sun outside the air 1.83), and Earth's air on a
/// Titan-sized planet under a 600 km top (71) read +10 to +36 % in daylight.
pub const MAX_SHELL_OVER_AIR: f64 = 20.0;

/// Column over peak density (m) of `profile` over [0, `shell_m`], on panels that shrink
/// geometrically towards the ground (and break at the profile's own breakpoints), so that
/// a layer a millionth of the shell is still resolved. 0 when the density is 0 throughout.
pub fn layer_thickness_m(profile: &DensityProfile, shell_m: f64) -> f64 {
    let mut edges: Vec<f64> = (0..64).map(|k| shell_m * 0.5f64.powi(k)).collect();
    edges.push(0.0);
    edges.extend(
        profile
            .breakpoints(shell_m)
            .into_iter()
            .filter(|&b| b > 0.0 && b < shell_m),
    );
    edges.sort_by(f64::total_cmp);
    edges.dedup();
    let peak = Cell::new(0.0f64);
    let density = |h: f64| {
        let d = profile.density(h).max(0.0);
        peak.set(peak.get().max(d));
        d
    };
    let column: f64 = edges
        .windows(2)
        .map(|w| GL4.integrate(w[0], w[1], 4, density))
        .sum();
    for &h in &edges {
        density(h);
    }
    if peak.get() > 0.0 {
        column / peak.get()
    } else {
        0.0
    }
}

/// Whether a constituent takes part at all (a coefficient that is not `none`).
fn acts(c: &Constituent) -> bool {
    !matches!(c.scattering, Coefficient::None) || !matches!(c.absorption, Coefficient::None)
}

/// Refuse a shell more than [`MAX_SHELL_OVER_LAYER`] times thicker than the thinnest acting
/// constituent's layer, naming the constituent and the highest top accepted.
pub(super) fn check_shell(atmosphere: &Atmosphere) -> Result<()> {
    let shell = atmosphere.top_radius_m - atmosphere.bottom_radius_m;
    let thinnest = (atmosphere.constituents.iter().enumerate())
        .filter(|(_, c)| acts(c))
        .map(|(i, c)| (i, c, layer_thickness_m(&c.density, shell)))
        .filter(|&(_, _, layer)| layer > 0.0)
        .min_by(|a, b| a.2.total_cmp(&b.2));
    match thinnest {
        Some((i, c, layer)) if shell > MAX_SHELL_OVER_LAYER * layer => Err(Error::invalid(
            "top_radius_m",
            atmosphere.top_radius_m,
            format!(
                "at most bottom_radius_m + {MAX_SHELL_OVER_LAYER} × the thinnest layer \
                 ({} + {:.0} m: constituents[{i}] '{}' is {layer:.0} m thick, column over peak \
                 density); a shell more than {MAX_SHELL_OVER_LAYER} times thicker than a \
                 layer falls between the tables' quadrature samples",
                atmosphere.bottom_radius_m,
                MAX_SHELL_OVER_LAYER * layer,
                c.name
            ),
        )),
        _ => check_air(atmosphere),
    }
}

/// Refuse a shell more than [`MAX_SHELL_OVER_AIR`] times the thickest scattering layer.
fn check_air(atmosphere: &Atmosphere) -> Result<()> {
    let shell = atmosphere.top_radius_m - atmosphere.bottom_radius_m;
    let thickest = (atmosphere.constituents.iter())
        .filter(|c| !matches!(c.scattering, Coefficient::None))
        .map(|c| (c, layer_thickness_m(&c.density, shell)))
        .max_by(|a, b| a.1.total_cmp(&b.1));
    match thickest {
        Some((c, layer)) if layer > 0.0 && shell > MAX_SHELL_OVER_AIR * layer => {
            Err(Error::invalid(
                "top_radius_m",
                atmosphere.top_radius_m,
                format!(
                    "at most bottom_radius_m + {MAX_SHELL_OVER_AIR} × the thickest scattering \
                     layer ({} + {:.0} m: '{}' is {layer:.0} m thick); the tables' altitude \
                     rows spread over the whole shell, and over a shell this thick for its air \
                     the orders of scattering gain energy instead of converging",
                    atmosphere.bottom_radius_m,
                    MAX_SHELL_OVER_AIR * layer,
                    c.name
                ),
            ))
        }
        _ => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layer_thickness_is_the_scale_height_of_an_exponential_and_15_km_for_the_ozone_tent() {
        let h = layer_thickness_m(&DensityProfile::exponential(8434.0), 60_000.0);
        assert!((h / (8434.0 * (1.0 - (-60_000.0f64 / 8434.0).exp())) - 1.0).abs() < 1e-6);
        // Resolved even where a fixed grid would miss it entirely.
        let h = layer_thickness_m(&DensityProfile::exponential(8434.0), 1e12);
        assert!((h / 8434.0 - 1.0).abs() < 1e-6, "{h}");
        let tent = layer_thickness_m(
            &DensityProfile::tent(10_000.0, 25_000.0, 40_000.0),
            60_000.0,
        );
        assert!((tent / 15_000.0 - 1.0).abs() < 1e-6, "{tent}");
        assert_eq!(layer_thickness_m(&DensityProfile::uniform(), 5e3), 5e3);
    }
}

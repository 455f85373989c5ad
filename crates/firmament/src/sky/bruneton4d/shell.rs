//! What shell geometry the tables handle. Bruneton's parameterisation maps view and sun
//! directions through distances to the top of the atmosphere and to the ground; over a
//! shell thin for its planet those distances grow towards the horizon far faster than the
//! air's vertical extent (the horizon distance H = √(R_t² − R_g²) ≈ √(2 R_g Δ) over a shell
//! Δ thick), so the sky above the horizon falls into a few rows of u_μ and the daylit
//! sun elevations into a few of u_μs. Measured against the reference (Earth's air, the
//! planet's radius scaled; default tables, `rgb`, altitudes 0/1/10 km, sun 60/10/2°, 1 %
//! reference noise; docs/accuracy.md, "Any planet's geometry"):
//!
//! | planet | Δ / R_g | luminance, worst median / p95 |
//! |---|---|---|
//! | Earth (sun 60 and 10° only) | 9.4·10⁻³ | 0.8 / 2.4 % |
//! | 3 × Earth | 3.1·10⁻³ | 1.3 / 3.8 % |
//! | 10 × Earth | 9.4·10⁻⁴ | 1.4 / 6.0 % |
//! | 30 × Earth | 3.1·10⁻⁴ | 1.8 / 7.3 % |
//! | 100 × Earth | 9.4·10⁻⁵ | 3.8 / 15.6 % (before the μ_s joint's floor) |
//! | 1000 × Earth | 9.4·10⁻⁶ | 31 / 280 % (idem) |
//!
//! So the tables refuse a shell thinner than [`MIN_RELATIVE_THICKNESS`] of the planet's
//! radius; the reference path tracer takes any geometry. (Every real body's atmosphere
//! is thicker: a gas giant's few hundred kilometres over 60 000–70 000 km are 4·10⁻³ and
//! more.) Shells thick for their planet are bounded by the air's own thickness instead
//! (`atmosphere::limits`).

use crate::atmosphere::Model;
use crate::{Error, Result};

/// The thinnest shell the tables accept, as (top − bottom radius) over the bottom radius.
pub const MIN_RELATIVE_THICKNESS: f64 = 3.0e-3;

/// The shell's thickness over the planet's radius.
pub fn relative_thickness(model: &Model) -> f64 {
    (model.top_radius_m - model.bottom_radius_m) / model.bottom_radius_m
}

/// Refuses a shell too thin for its planet ([`MIN_RELATIVE_THICKNESS`]), naming the
/// largest planet radius the shell allows.
pub fn check(model: &Model) -> Result<()> {
    let relative = relative_thickness(model);
    if relative < MIN_RELATIVE_THICKNESS {
        let shell = model.top_radius_m - model.bottom_radius_m;
        return Err(Error::invalid(
            "bottom_radius_m (the shell's thickness top_radius_m − bottom_radius_m over it)",
            format!("{relative:.3e}"),
            format!(
                "a shell at least {MIN_RELATIVE_THICKNESS} of the planet's radius for the \
                 precomputed tables (this {shell:.0} m shell: a planet radius of at most \
                 {:.0} m): over a thinner shell the horizon distances crowd the sky into a \
                 few table rows and the sky is off by 5 % and more (docs/accuracy.md); the \
                 reference path tracer (--method reference) takes any geometry",
                shell / MIN_RELATIVE_THICKNESS
            ),
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::atmosphere::Atmosphere;
    use crate::spectrum::Wavelengths;

    fn model(bottom_m: f64, top_m: f64) -> Result<Model> {
        let mut a = Atmosphere::earth();
        a.bottom_radius_m = bottom_m;
        a.top_radius_m = top_m;
        a.resolve(&Wavelengths::rgb())
    }

    #[test]
    fn earth_and_mars_pass_and_a_shell_thinner_than_the_limit_is_refused() {
        assert!(check(&model(6.36e6, 6.42e6).unwrap()).is_ok());
        let mars = Atmosphere::preset("mars").unwrap();
        assert!(check(&mars.resolve(&Wavelengths::rgb()).unwrap()).is_ok());
        // Earth's 60 km of air at the limit's planet radius, and just beyond it.
        let limit = 60_000.0 / MIN_RELATIVE_THICKNESS;
        assert!(check(&model(limit * 0.999, limit * 0.999 + 60e3).unwrap()).is_ok());
        let e = check(&model(limit * 1.01, limit * 1.01 + 60e3).unwrap())
            .unwrap_err()
            .to_string();
        assert!(e.contains("bottom_radius_m"), "{e}");
        assert!(e.contains("20000000 m"), "{e}");
        assert!(e.contains("--method reference"), "{e}");
    }
}

//! The moon as a light: its spectral irradiance at the top of the atmosphere from the
//! sun's, the lunar colour and the phase law of its brightness, and the radiance across its
//! disk (the lit part by the Lommel–Seeliger law of a dusty surface, the dark part by
//! earthshine).
//!
//! Brightness: V = 0.21 + 5 log₁₀(r·Δ) + 0.026|α| + 4·10⁻⁹ α⁴ (r, Δ in AU, α the phase angle
//! in degrees; Allen, Astrophysical Quantities, 3rd ed. 1973, §66, as used by the
//! Astronomical Almanac), turned into illuminance by the V zero point of
//! [`crate::astro::photometry`]. Colour: the moon is redder than the sun by
//! (B−V)☾ − (B−V)☉ = 0.92 − 0.65 (Allen; Holmberg et al. 2006 for the sun), which fixes a
//! reflectance rising linearly with wavelength. Disk: Lommel–Seeliger, L ∝ μ₀/(μ₀ + μ)
//! (Hapke 1993, §8; the law of Jensen et al. 2001 without their opposition terms, whose
//! effect on the total is in the phase law above), scaled so the disk integrates to the
//! irradiance. Earthshine: the Earth as a Lambert sphere of Bond albedo 0.30 (Goode et al.
//! 2001) lighting the moon, reflected with the moon's opposition reflectance.

use std::f64::consts::PI;

use crate::astro::photometry::{illuminance_from_magnitude_lx, scale_to_illuminance};
use crate::astro::sun::ASTRONOMICAL_UNIT_M;
use crate::atmosphere::Model;
use crate::math::Vec3;

/// B−V of the moon and of the sun (Allen 1973; Holmberg, Flynn & Portinari 2006).
const MOON_B_V: f64 = 0.92;
const SUN_B_V: f64 = 0.65;
/// Effective wavelengths of the B and V bands (nm; Johnson 1953, Bessell 1990).
const B_NM: f64 = 440.0;
const V_NM: f64 = 550.0;
/// Bond albedo of the Earth (Goode et al. 2001, earthshine measurements: 0.297).
const EARTH_BOND_ALBEDO: f64 = 0.30;
/// Mean radius of the Earth (m), IUGG.
const EARTH_RADIUS_M: f64 = 6_371_000.0;

/// Where the moon is and how the sun lights it, for [`lunar_light`].
#[derive(Clone, Copy, Debug)]
pub struct MoonGeometry {
    /// Unit vector from the observer to the moon's centre (world frame).
    pub direction: Vec3,
    /// Unit vector from the moon to the sun (world frame).
    pub sun_from_moon: Vec3,
    /// The Sun–Moon–Earth angle (rad).
    pub phase_angle_rad: f64,
    /// Observer–moon distance (m).
    pub distance_m: f64,
    /// Angular radius (rad).
    pub angular_radius_rad: f64,
    /// Sun–Earth distance (AU).
    pub sun_distance_au: f64,
}

/// Radiance across the moon's disk.
#[derive(Clone, Debug)]
pub struct LunarDisk {
    /// Unit vector from the moon to the sun (world frame).
    pub sun_from_moon: Vec3,
    /// Lit radiance factor per channel (W·m⁻²·sr⁻¹·nm⁻¹): L = this × μ₀/(μ₀ + μ).
    pub lit: Vec<f64>,
    /// Earthshine radiance on the dark part, per channel.
    pub earthshine: Vec<f64>,
}

/// The lunar reflectance relative to its value at 550 nm, from the colour difference with
/// the sun: linear in wavelength through R(440)/R(550) = 10^(−0.4 Δ(B−V)), at least 0.2.
pub fn relative_reflectance(lambda_nm: f64) -> f64 {
    let ratio = 10f64.powf(-0.4 * (MOON_B_V - SUN_B_V));
    let slope = (1.0 - ratio) / (V_NM - B_NM);
    (1.0 + slope * (lambda_nm - V_NM)).max(0.2)
}

/// Visual magnitude of the moon at phase angle `alpha_deg`, sun distance `r_au` and
/// observer distance `delta_au` (Allen 1973).
pub fn moon_magnitude(alpha_deg: f64, r_au: f64, delta_au: f64) -> f64 {
    let a = alpha_deg.abs();
    0.21 + 5.0 * (r_au * delta_au).log10() + 0.026 * a + 4.0e-9 * a.powi(4)
}

/// ∫ μ₀/(μ₀ + μ) dΩ over the lit part of a disk of angular radius α (sr), with `sun` the
/// direction to the sun in the disk's frame (z towards the observer).
fn lommel_seeliger_integral(sun: Vec3, angular_radius_rad: f64) -> f64 {
    let n = 96;
    let mut s = 0.0;
    for i in 0..n {
        for j in 0..n {
            let x = (i as f64 + 0.5) / n as f64 * 2.0 - 1.0;
            let y = (j as f64 + 0.5) / n as f64 * 2.0 - 1.0;
            let z2 = 1.0 - x * x - y * y;
            if z2 <= 0.0 {
                continue;
            }
            let normal = Vec3::new(x, y, z2.sqrt());
            let mu0 = normal.dot(sun);
            if mu0 > 0.0 {
                s += mu0 / (mu0 + normal.z);
            }
        }
    }
    // Cell area (2/n)² in units of sin α.
    s * (2.0 / n as f64).powi(2) * angular_radius_rad.sin().powi(2)
}

/// A frame (x, y, z) with z = `towards_observer`.
fn disk_frame(towards_observer: Vec3) -> (Vec3, Vec3, Vec3) {
    let z = towards_observer;
    let helper = if z.z.abs() < 0.9 { Vec3::Z } else { Vec3::X };
    let x = helper.cross(z).normalize();
    (x, z.cross(x), z)
}

/// The moon's spectral irradiance at the top of the atmosphere (per channel of `model`) and
/// the radiance across its disk.
pub fn lunar_light(model: &Model, moon: &MoonGeometry) -> (Vec<f64>, LunarDisk) {
    let nm = model.wavelengths.nm();
    let colour = model.colour_matrix();
    let au_m = ASTRONOMICAL_UNIT_M;
    let alpha_deg = moon.phase_angle_rad.to_degrees();
    let shape: Vec<f64> = (model.solar_irradiance.iter().zip(nm))
        .map(|(e, &l)| e * relative_reflectance(l))
        .collect();
    let irradiance_at = |alpha: f64| {
        let v = moon_magnitude(alpha, moon.sun_distance_au, moon.distance_m / au_m);
        scale_to_illuminance(&shape, &colour, illuminance_from_magnitude_lx(v))
    };
    let irradiance = irradiance_at(alpha_deg);
    let (fx, fy, fz) = disk_frame(-moon.direction);
    let local = |v: Vec3| Vec3::new(v.dot(fx), v.dot(fy), v.dot(fz));
    let alpha = moon.angular_radius_rad;
    let integral = lommel_seeliger_integral(local(moon.sun_from_moon), alpha);
    let lit: Vec<f64> = irradiance
        .iter()
        .map(|e| if integral > 0.0 { e / integral } else { 0.0 })
        .collect();
    // Earthshine: the Earth seen from the moon at phase π − α, a Lambert sphere
    // (geometric albedo 2/3 A, phase law (sin φ + (π − φ) cos φ)/π), lights the moon from
    // the observer's direction; the moon returns it with its opposition reflectance,
    // L = E·ρ₀·μ₀/(μ₀ + μ) = E·ρ₀/2, ρ₀ from the full-moon brightness per unit sunlight.
    let phi = PI - moon.phase_angle_rad;
    let lambert = (phi.sin() + (PI - phi) * phi.cos()) / PI;
    let earth_over_sun =
        (2.0 / 3.0) * EARTH_BOND_ALBEDO * lambert * (EARTH_RADIUS_M / moon.distance_m).powi(2);
    let full = irradiance_at(0.0);
    let full_integral = lommel_seeliger_integral(Vec3::Z, alpha);
    let earthshine = full
        .iter()
        .map(|e| 0.5 * e / full_integral * earth_over_sun)
        .collect();
    (
        irradiance,
        LunarDisk {
            sun_from_moon: moon.sun_from_moon,
            lit,
            earthshine,
        },
    )
}

impl LunarDisk {
    /// Adds the radiance of the moon's surface seen along `dir` (inside the disk of a moon
    /// in direction `centre` with angular radius `alpha`), attenuated by `transmittance`.
    pub fn add_radiance(
        &self,
        dir: Vec3,
        centre: Vec3,
        alpha: f64,
        transmittance: &[f64],
        out: &mut [f64],
    ) {
        // The surface normal where `dir` meets a unit-distance sphere of radius sin α.
        let r = alpha.sin();
        let along = dir.dot(centre);
        let disc = r * r - (1.0 - along * along);
        if disc < 0.0 {
            return;
        }
        let t = along - disc.sqrt();
        let normal = ((dir * t - centre) / r).normalize_or_zero();
        let (mu0, mu) = (normal.dot(self.sun_from_moon), normal.dot(-dir).max(0.0));
        if mu0 > 0.0 {
            let law = mu0 / (mu0 + mu);
            for (k, o) in out.iter_mut().enumerate() {
                *o += (self.lit[k] * law + self.earthshine[k]) * transmittance[k];
            }
        } else {
            for (k, o) in out.iter_mut().enumerate() {
                *o += self.earthshine[k] * transmittance[k];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn full_moon_brightness_and_colour() {
        // At mean distance (384 400 km) and full phase: V ≈ −12.74, 0.32 lx.
        let v = moon_magnitude(0.0, 1.0, 384_400e3 / ASTRONOMICAL_UNIT_M);
        assert!((v + 12.74).abs() < 0.02, "{v}");
        // Half moon is 0.026·90 + 4·10⁻⁹·90⁴ = 2.60 magnitudes fainter (Allen's curve).
        let q = moon_magnitude(90.0, 1.0, 384_400e3 / ASTRONOMICAL_UNIT_M);
        assert!((q - v - 2.60).abs() < 0.01, "{}", q - v);
        // Redder than the sun: 10^(−0.4·0.27) = 0.78 at 440 nm, about 1.27 at 680 nm.
        assert!((relative_reflectance(440.0) - 0.780).abs() < 0.002);
        assert!((relative_reflectance(680.0) - 1.26).abs() < 0.01);
    }

    #[test]
    fn lommel_seeliger_disk_integral() {
        // Full phase: ∫ 1/2 dΩ over the disk = π sin²α / 2 (the grid misses < 1 %).
        let a = 0.0045;
        let full = lommel_seeliger_integral(Vec3::Z, a);
        assert!((full / (PI * a.sin().powi(2) / 2.0) - 1.0).abs() < 0.01);
        // New moon: nothing lit.
        assert_eq!(lommel_seeliger_integral(-Vec3::Z, a), 0.0);
    }
}

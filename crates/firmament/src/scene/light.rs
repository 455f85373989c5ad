//! Lights: a direction, an angular radius, a spectral irradiance at the top of the atmosphere
//! and a radiance profile across the disk. The sun is the first; the moon ([`super::lunar`])
//! the second, lighting the same sky tables scaled by its own irradiance.

use std::f64::consts::PI;

use crate::atmosphere::{LimbDarkening, Model};
use crate::math::sphere::safe_sqrt;
use crate::math::Vec3;
use crate::scene::lunar::{lunar_light, LunarDisk, MoonGeometry};

/// A light outside the atmosphere.
#[derive(Clone, Debug)]
pub struct Light {
    /// Unit vector towards the centre of its disk (world frame).
    pub direction: Vec3,
    /// Angular radius of the disk (rad).
    pub angular_radius_rad: f64,
    /// Spectral irradiance at the top of the atmosphere, per channel (W·m⁻²·nm⁻¹).
    pub irradiance: Vec<f64>,
    /// Radiance across the disk.
    pub disk: DiskProfile,
    /// Whether images show the disk (the light still lights the scene when not).
    pub visible_disk: bool,
}

/// The radiance across a light's disk outside the atmosphere, per channel.
#[derive(Clone, Debug)]
pub enum DiskProfile {
    /// A self-luminous sphere (the sun): the centre's radiance times a polynomial law in μ,
    /// the cosine of the emergence angle (I(μ)/I(1) = max(Σ a_j μ^j, 0)).
    Emitting {
        /// Radiance at the disk's centre (W·m⁻²·sr⁻¹·nm⁻¹), per channel.
        centre_radiance: Vec<f64>,
        /// The law's coefficients a_0 … a_5, per channel.
        law: Vec<[f64; 6]>,
    },
    /// A sphere lit by the sun (the moon): its phase, terminator and earthshine.
    Lunar(LunarDisk),
}

impl Light {
    /// The sun of `model` in direction `direction`: its angular radius, solar spectrum and
    /// limb darkening law, the centre radiance such that the disk integrates to the
    /// irradiance.
    pub fn sun(model: &Model, direction: Vec3, visible_disk: bool) -> Light {
        let alpha = model.sun_angular_radius_rad;
        let nm = model.wavelengths.nm();
        let law = model.limb_darkening;
        Light {
            direction,
            angular_radius_rad: alpha,
            irradiance: model.solar_irradiance.clone(),
            disk: DiskProfile::Emitting {
                centre_radiance: model
                    .solar_irradiance
                    .iter()
                    .zip(nm)
                    .map(|(e, &l)| e / disk_solid_angle_weighted(alpha, law, l))
                    .collect(),
                law: nm
                    .iter()
                    .map(|&l| limb_darkening_coefficients(law, l))
                    .collect(),
            },
            visible_disk,
        }
    }

    /// The moon of `model`'s sun (its spectrum) in the geometry `moon`: irradiance and disk
    /// from [`lunar_light`].
    pub fn moon(model: &Model, moon: &MoonGeometry, visible_disk: bool) -> Light {
        let (irradiance, disk) = lunar_light(model, moon);
        Light {
            direction: moon.direction,
            angular_radius_rad: moon.angular_radius_rad,
            irradiance,
            disk: DiskProfile::Lunar(disk),
            visible_disk,
        }
    }

    /// Its irradiance relative to `reference` (W·m⁻²·nm⁻¹ per channel; 0 where that is 0):
    /// the factor by which results computed for the reference light (the model's sun, which
    /// the tables hold) scale to this one.
    pub fn scale_against(&self, reference: &[f64]) -> Vec<f64> {
        self.irradiance
            .iter()
            .zip(reference)
            .map(|(l, s)| if *s > 0.0 { l / s } else { 0.0 })
            .collect()
    }

    /// Adds the disk's radiance seen along `dir`, attenuated by `transmittance`, when `dir`
    /// falls inside the disk.
    pub fn add_disk_radiance(&self, dir: Vec3, transmittance: &[f64], out: &mut [f64]) {
        let alpha = self.angular_radius_rad;
        let cos_angle = dir.dot(self.direction).clamp(-1.0, 1.0);
        if cos_angle <= alpha.cos() {
            return;
        }
        match &self.disk {
            DiskProfile::Emitting {
                centre_radiance,
                law,
            } => {
                let x = cos_angle.acos().sin() / alpha.sin();
                let mu = safe_sqrt(1.0 - x * x);
                for (k, o) in out.iter_mut().enumerate() {
                    *o += centre_radiance[k] * polynomial_law(&law[k], mu) * transmittance[k];
                }
            }
            DiskProfile::Lunar(moon) => {
                moon.add_radiance(dir, self.direction, alpha, transmittance, out)
            }
        }
    }
}

/// max(Σ a_j μ^j, 0) with μ clamped to [0, 1].
#[inline]
fn polynomial_law(a: &[f64; 6], mu: f64) -> f64 {
    let mu = mu.clamp(0.0, 1.0);
    let mut s = 0.0;
    let mut p = 1.0;
    for c in a {
        s += c * p;
        p *= mu;
    }
    s.max(0.0)
}

/// The sun's limb darkening I(μ)/I(1) at `lambda_nm`: 1 without darkening; Neckel (1996),
/// Solar Physics 167, 223–248, eq. 2 and Table II, I(μ)/I(1) = Σ a_k μ^k with
/// a_k = A_k + B_k/λ + C_k/λ⁵ (λ in µm), valid 422.5–1100 nm; shorter wavelengths use
/// 422.5 nm.
pub fn limb_darkening(law: LimbDarkening, mu: f64, lambda_nm: f64) -> f64 {
    polynomial_law(&limb_darkening_coefficients(law, lambda_nm), mu)
}

/// The polynomial coefficients a_0..a_5 of [`limb_darkening`] at `lambda_nm`
/// (`[1, 0, …]` without darkening).
pub fn limb_darkening_coefficients(law: LimbDarkening, lambda_nm: f64) -> [f64; 6] {
    match law {
        LimbDarkening::None => [1.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        LimbDarkening::Neckel1996 => {
            let l = (lambda_nm.clamp(422.5, 1100.0)) / 1000.0;
            let l5 = l.powi(5);
            [
                0.75267 - 0.265577 / l,
                0.93874 + 0.265577 / l - 0.004095 / l5,
                -1.89287 + 0.012582 / l5,
                2.42234 - 0.017117 / l5,
                -1.71150 + 0.011977 / l5,
                0.49062 - 0.003347 / l5,
            ]
        }
    }
}

/// ∫_disk I(μ)/I(1) dΩ for a disk of angular radius α (sr): E = L_centre × this.
pub fn disk_solid_angle_weighted(alpha: f64, law: LimbDarkening, lambda_nm: f64) -> f64 {
    // θ from the disk centre; on the solar sphere μ = cos of the emergence angle =
    // sqrt(1 − (sin θ / sin α)²).
    let steps = 512;
    let mut s = 0.0;
    for i in 0..steps {
        let theta = (i as f64 + 0.5) / steps as f64 * alpha;
        let x = theta.sin() / alpha.sin();
        let mu = safe_sqrt(1.0 - x * x);
        s += limb_darkening(law, mu, lambda_nm) * theta.sin();
    }
    2.0 * PI * s * alpha / steps as f64
}

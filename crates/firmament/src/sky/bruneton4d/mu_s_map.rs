//! The non-linear μ_s coordinate of the 4D scattering table: Bruneton 2017's mapping (from
//! the distance to the top along the sun ray, with the minimum sun elevation) up to a joint,
//! linear in the sun's zenith angle above it ([`x_mu_s`], [`MuSMap`]). WGSL twin:
//! `shaders/bruneton4d/mu_s_map.wgsl`.

use super::params::Radii;
use crate::math::sphere::{clamp_cosine, distance_to_top_atmosphere_boundary};

/// The non-linear μ_s coordinate in [0, 1]: Bruneton 2017's (from the distance to the top
/// along the sun ray from the ground, with the configurable minimum sun elevation) up to a
/// joint at his coordinate 26/31 (18° elevation for μ_s,min = cos 108°), scaled to [0, 26/39];
/// above it linear in the sun's zenith angle up to 1 (zenith).
///
/// Bruneton's mapping alone puts 5 of 32 samples above 18° and none between 46.4° and 90°:
/// anti-solar views under a 60° sun read up to +7 % (docs/accuracy.md). At 40 samples the
/// first 27 are exactly his 32-sample grid's (every sunset and twilight sample stays where
/// it was) and the other 13 are 5.5° apart up to the zenith. A blend of his mapping with an
/// angle-linear one (reverted, commit f436594) took samples from the horizon instead.
#[inline]
pub fn x_mu_s(radii: &Radii, mu_s: f64) -> f64 {
    MuSMap::new(radii).x(mu_s)
}

/// Inverse of [`x_mu_s`].
#[inline]
pub fn mu_s_from_x(radii: &Radii, x: f64) -> f64 {
    MuSMap::new(radii).mu_s(x)
}

/// Bruneton's coordinate of the joint of [`x_mu_s`]: sample 26 of his 32 (sun elevation
/// 18.0° for μ_s,min = cos 108°, 19.1° for cos 102°).
pub const MU_S_JOINT_BRUNETON_X: f64 = 26.0 / 31.0;
/// Where the joint lies in [`x_mu_s`]: sample 26 of 40 (Bruneton's sample 26 of 32).
pub const MU_S_JOINT_X: f64 = 26.0 / 39.0;
/// The lowest sun elevation (degrees) of the joint. Bruneton's coordinate 26/31 lies at
/// 18–19° over Earth's geometry, but his mapping follows the distance to the top along the
/// sun ray, and over a shell thin for its planet those distances grow so fast towards the
/// horizon that the coordinate slides down (6.3° for Earth's air on a planet 10× Earth's
/// radius, 2.0° at 100×): the 13 angle-linear samples above it were then 6.4° apart and the
/// sky under a 10° sun read −4 % throughout (docs/accuracy.md). The joint is held at this
/// elevation or above; `earth`, `mars` and every thicker shell keep Bruneton's coordinate.
pub const MU_S_JOINT_MIN_ELEVATION_DEG: f64 = 15.0;

/// [`x_mu_s`] with its constants computed once (hot loops).
#[derive(Clone, Copy, Debug)]
pub struct MuSMap {
    top: f64,
    bottom: f64,
    h: f64,
    d_min: f64,
    inv_range: f64,
    big_a: f64,
    /// Bruneton's coordinate at the joint: [`MU_S_JOINT_BRUNETON_X`], or that of
    /// [`MU_S_JOINT_MIN_ELEVATION_DEG`] where higher.
    joint_b: f64,
}

impl MuSMap {
    /// Constants for these radii.
    pub fn new(radii: &Radii) -> MuSMap {
        let d_min = radii.top - radii.bottom;
        let d_max = radii.h();
        let big_d = distance_to_top_atmosphere_boundary(radii.bottom, radii.mu_s_min, radii.top);
        let mut map = MuSMap {
            top: radii.top,
            bottom: radii.bottom,
            h: d_max,
            d_min,
            inv_range: 1.0 / (d_max - d_min),
            big_a: (big_d - d_min) / (d_max - d_min),
            joint_b: MU_S_JOINT_BRUNETON_X,
        };
        let floor = map.bruneton_x(MU_S_JOINT_MIN_ELEVATION_DEG.to_radians().sin());
        map.joint_b = MU_S_JOINT_BRUNETON_X.max(floor);
        map
    }

    /// Bruneton's own coordinate of μ_s (his `GetScatteringTextureUvwzFromRMuMuSNu`).
    #[inline]
    fn bruneton_x(&self, mu_s: f64) -> f64 {
        let d = distance_to_top_atmosphere_boundary(self.bottom, mu_s, self.top);
        let a = (d - self.d_min) * self.inv_range;
        ((1.0 - a / self.big_a).max(0.0) / (1.0 + a)).clamp(0.0, 1.0)
    }

    /// Bruneton's coordinate at the joint (the GPU computes it from the joint's angle).
    pub fn joint_bruneton_x(&self) -> f64 {
        self.joint_b
    }

    /// The sun's zenith angle at the joint of [`x_mu_s`] (rad; the GPU's uniform holds it).
    /// Computed when needed: below the joint (every sunset lookup) it costs nothing.
    pub fn theta_joint(&self) -> f64 {
        self.bruneton_mu_s(self.joint_b).acos()
    }

    /// Same as [`x_mu_s`].
    #[inline]
    pub fn x(&self, mu_s: f64) -> f64 {
        let bruneton = self.bruneton_x(mu_s);
        if bruneton <= self.joint_b {
            MU_S_JOINT_X * bruneton / self.joint_b
        } else {
            let (theta, theta_joint) = (clamp_cosine(mu_s).acos(), self.theta_joint());
            let above = (theta_joint - theta) / theta_joint;
            (MU_S_JOINT_X + (1.0 - MU_S_JOINT_X) * above).clamp(0.0, 1.0)
        }
    }

    /// Same as [`mu_s_from_x`].
    #[inline]
    pub fn mu_s(&self, x: f64) -> f64 {
        if x <= MU_S_JOINT_X {
            self.bruneton_mu_s(x * self.joint_b / MU_S_JOINT_X)
        } else {
            let above = ((x - MU_S_JOINT_X) / (1.0 - MU_S_JOINT_X)).min(1.0);
            (self.theta_joint() * (1.0 - above)).cos()
        }
    }

    /// Inverse of Bruneton's mapping (his `GetRMuMuSNuFromScatteringTextureUvwz`).
    fn bruneton_mu_s(&self, x: f64) -> f64 {
        let (h, big_a) = (self.h, self.big_a);
        let a = (big_a - x * big_a) / (1.0 + x * big_a);
        let d = self.d_min + a.min(big_a) * (h - self.d_min);
        if d == 0.0 {
            1.0
        } else {
            clamp_cosine((h * h - d * d) / (2.0 * self.bottom * d))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const G: Radii = crate::sky::bruneton4d::params::EARTH_RADII;

    #[test]
    fn mu_s_samples_below_the_joint_are_brunetons_32() {
        // Bruneton's mapping alone, inverted at his sample i of 32 (params before the joint).
        let map = MuSMap::new(&G);
        for i in 0..=26 {
            let (mu_s, x) = (map.bruneton_mu_s(i as f64 / 31.0), i as f64 / 39.0);
            assert!((mu_s_from_x(&G, x) - mu_s).abs() < 1e-12, "sample {i}");
            assert!((x_mu_s(&G, mu_s) - x).abs() < 1e-10, "sample {i}");
        }
        assert_eq!(mu_s_from_x(&G, 1.0), 1.0);
        assert!((x_mu_s(&G, 1.0) - 1.0).abs() < 1e-12 && x_mu_s(&G, G.mu_s_min).abs() < 1e-9);
    }

    #[test]
    fn the_joint_stays_at_brunetons_sample_over_earth_and_at_15_degrees_over_a_thin_shell() {
        assert_eq!(MuSMap::new(&G).joint_bruneton_x(), MU_S_JOINT_BRUNETON_X);
        let elevation = |m: &MuSMap| 90.0 - m.theta_joint().to_degrees();
        assert!((elevation(&MuSMap::new(&G)) - 19.04).abs() < 0.05);
        // Earth's 60 km over a planet 10× Earth's radius: Bruneton's sample 26 lies at 6.3°.
        let thin = Radii {
            bottom: 63.6e6,
            top: 63.66e6,
            mu_s_min: G.mu_s_min,
        };
        let map = MuSMap::new(&thin);
        assert!((elevation(&map) - MU_S_JOINT_MIN_ELEVATION_DEG).abs() < 1e-9);
        assert!(map.joint_bruneton_x() > MU_S_JOINT_BRUNETON_X);
        // The mapping is continuous and monotonic through the moved joint, and round-trips.
        let mut last = -1.0;
        for i in 0..=2000 {
            let mu_s = thin.mu_s_min + (1.0 - thin.mu_s_min) * i as f64 / 2000.0;
            let x = map.x(mu_s);
            assert!(x >= last, "{mu_s}");
            assert!((map.mu_s(x) - mu_s).abs() < 1e-9, "{mu_s}");
            last = x;
        }
    }
}

//! What the 3D-table method precomputes: table sizes, scattering orders and the quadrature
//! counts of its passes ([`Elek3dConfig`]).

use super::params::SunZenithMapping;
use crate::sky::bruneton4d::TableSizes;
use crate::{Error, Result};

/// Sizes and counts of the 3D-table method.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Elek3dConfig {
    /// Scattering texels along the altitude (u_h = (h/H)^`height_power`). Default 32.
    pub altitude: usize,
    /// Scattering texels along the view's zenith cosine, even: the lower half holds rays
    /// that meet the ground, the upper half the others (the horizon split of Bruneton &
    /// Neyret 2008 §4 and Yusov 2013). Default 128.
    pub view_zenith: usize,
    /// Scattering texels along the sun's zenith cosine. Default 32.
    pub sun_zenith: usize,
    /// Sky-irradiance (μ_s, r) texels, the 4D tables' mapping (linear in both) and rows
    /// (64: docs/accuracy.md, "The irradiance table along r"). Default (64, 64).
    pub irradiance: (usize, usize),
    /// Transmittance (μ, r) texels, the 4D tables' table and mapping. Default (256, 64).
    pub transmittance: (usize, usize),
    /// 4-point Gauss–Legendre segments per transmittance ray. Default 32, a quarter of the
    /// 4D tables' 128: the scattering tables move by at most 0.1 % (3·10⁻⁵ in the mean).
    pub transmittance_segments: usize,
    /// Scattering orders summed (1 = single scattering only). Default 4, as the 4D tables.
    pub orders: usize,
    /// Add the geometric tail of the orders beyond `orders` (as the 4D tables'
    /// `order_tail`; needs `orders` ≥ 3). Default true.
    pub order_tail: bool,
    /// Equal intervals along each view ray of the single- and multiple-scattering passes,
    /// even (an exponentially fitted Simpson rule on pairs, `ray`). Default 40.
    pub ray_steps: usize,
    /// Gauss–Legendre nodes in the view–sun azimuth over its sunlit range, for the
    /// azimuthal mean of the sun's transmittance in single scattering. Default 8 (the
    /// single scattering within 0.4 % of 32 nodes, 10⁻⁵ in the mean).
    pub azimuth_nodes: usize,
    /// Midpoint nodes in azimuth over [0, π] for the azimuthal means of the multiple
    /// scattering along rays (fewer where the suns of a sample's azimuths lie within a texel)
    /// and of the ground's irradiance. Default 4 (within 2.5 % of 16 nodes, 10⁻⁴ in the mean).
    pub multiple_azimuth_nodes: usize,
    /// (radius, central angle) texels of the table of the sun's azimuth-averaged
    /// transmittance (`sun_cone`). Default (128, 64).
    pub sun_cone: (usize, usize),
    /// Gauss–Legendre nodes of the incident zenith cosine on each side of the horizon, for
    /// the scattering density. Default 24.
    pub gather_nodes: usize,
    /// Power of the altitude mapping, u_h = (h/H)^p (Yusov 2013: 0.5). In (0, 1].
    pub height_power: f64,
    /// Power of the view-zenith mapping on each side of the horizon (Yusov 2013: 0.2).
    /// In (0, 1].
    pub view_zenith_power: f64,
    /// The sun-zenith mapping. Default Yusov's (Bruneton & Neyret 2008's arctangent).
    pub sun_zenith_mapping: SunZenithMapping,
}

impl Default for Elek3dConfig {
    fn default() -> Self {
        Elek3dConfig {
            altitude: 32,
            view_zenith: 128,
            sun_zenith: 32,
            irradiance: (64, 64),
            transmittance: (256, 64),
            transmittance_segments: 32,
            orders: 4,
            order_tail: true,
            ray_steps: 40,
            azimuth_nodes: 8,
            multiple_azimuth_nodes: 4,
            sun_cone: (128, 64),
            gather_nodes: 24,
            height_power: 0.5,
            view_zenith_power: 0.2,
            sun_zenith_mapping: SunZenithMapping::Yusov,
        }
    }
}

impl Elek3dConfig {
    /// Small tables for fast tests (16 × 64 × 16 scattering texels).
    pub fn small() -> Self {
        Elek3dConfig {
            altitude: 16,
            view_zenith: 64,
            sun_zenith: 16,
            irradiance: (32, 16),
            transmittance: (128, 32),
            sun_cone: (64, 32),
            gather_nodes: 16,
            ..Elek3dConfig::default()
        }
    }

    /// Refuse sizes and counts that cannot work, naming the field.
    pub fn validate(&self) -> Result<()> {
        let sizes = [
            ("elek3d.altitude", self.altitude),
            ("elek3d.view_zenith", self.view_zenith),
            ("elek3d.sun_zenith", self.sun_zenith),
            ("elek3d.irradiance.mu_s", self.irradiance.0),
            ("elek3d.irradiance.r", self.irradiance.1),
            ("elek3d.transmittance.mu", self.transmittance.0),
            ("elek3d.transmittance.r", self.transmittance.1),
            ("elek3d.sun_cone.r", self.sun_cone.0),
            ("elek3d.sun_cone.alpha", self.sun_cone.1),
        ];
        for (field, v) in sizes {
            if !(2..=4096).contains(&v) {
                return Err(Error::invalid(field, v, "an integer from 2 to 4096"));
            }
        }
        if !self.view_zenith.is_multiple_of(2) || self.view_zenith < 4 {
            return Err(Error::invalid(
                "elek3d.view_zenith",
                self.view_zenith,
                "an even integer from 4 to 4096 (two halves split at the horizon)",
            ));
        }
        let texels = self.altitude * self.view_zenith * self.sun_zenith;
        if texels > 16 << 20 {
            return Err(Error::invalid(
                "elek3d",
                format!("{texels} scattering texels"),
                "at most 16777216 texels",
            ));
        }
        let counts = [
            (
                "elek3d.transmittance_segments",
                self.transmittance_segments,
                1,
                4096,
            ),
            ("elek3d.orders", self.orders, 1, 50),
            ("elek3d.azimuth_nodes", self.azimuth_nodes, 1, 256),
            (
                "elek3d.multiple_azimuth_nodes",
                self.multiple_azimuth_nodes,
                1,
                256,
            ),
            ("elek3d.gather_nodes", self.gather_nodes, 1, 512),
        ];
        for (field, v, lo, hi) in counts {
            if !(lo..=hi).contains(&v) {
                return Err(Error::invalid(
                    field,
                    v,
                    format!("an integer from {lo} to {hi}"),
                ));
            }
        }
        if !self.ray_steps.is_multiple_of(2) || !(2..=4096).contains(&self.ray_steps) {
            return Err(Error::invalid(
                "elek3d.ray_steps",
                self.ray_steps,
                "an even integer from 2 to 4096",
            ));
        }
        for (field, p) in [
            ("elek3d.height_power", self.height_power),
            ("elek3d.view_zenith_power", self.view_zenith_power),
        ] {
            if !(p.is_finite() && p > 0.0 && p <= 1.0) {
                return Err(Error::invalid(field, p, "a number in (0, 1]"));
            }
        }
        Ok(())
    }

    /// The 4D tables' sizes with this transmittance and irradiance (what
    /// [`crate::sky::bruneton4d::Lookup`] and the twilight extrapolation read); the
    /// scattering fields hold this method's sizes, with one ν texel.
    pub fn table_sizes(&self) -> TableSizes {
        TableSizes {
            transmittance_mu: self.transmittance.0,
            transmittance_r: self.transmittance.1,
            scattering_r: self.altitude,
            scattering_mu: self.view_zenith,
            scattering_mu_s: self.sun_zenith,
            scattering_nu: 1,
            irradiance_mu_s: self.irradiance.0,
            irradiance_r: self.irradiance.1,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_validate_and_bad_values_name_their_field() {
        Elek3dConfig::default().validate().unwrap();
        Elek3dConfig::small().validate().unwrap();
        let cases: [(Elek3dConfig, &str); 5] = [
            (
                Elek3dConfig {
                    view_zenith: 63,
                    ..Default::default()
                },
                "elek3d.view_zenith",
            ),
            (
                Elek3dConfig {
                    altitude: 1,
                    ..Default::default()
                },
                "elek3d.altitude",
            ),
            (
                Elek3dConfig {
                    orders: 0,
                    ..Default::default()
                },
                "elek3d.orders",
            ),
            (
                Elek3dConfig {
                    view_zenith_power: 0.0,
                    ..Default::default()
                },
                "elek3d.view_zenith_power",
            ),
            (
                Elek3dConfig {
                    height_power: f64::NAN,
                    ..Default::default()
                },
                "elek3d.height_power",
            ),
        ];
        for (config, field) in cases {
            let message = config.validate().unwrap_err().to_string();
            assert!(message.contains(field), "{message}");
        }
    }
}

//! The precomputed tables of one atmosphere and what to precompute ([`TableConfig`]).

use serde::{Deserialize, Serialize};

use super::params::TableSizes;
use super::precompute;
use super::table::{Table2, Table4};
use crate::atmosphere::Model;
use crate::{Error, Result};

/// How single Mie scattering is stored (Bruneton 2017 `combine_scattering_textures`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum MieStorage {
    /// A full table per wavelength.
    #[default]
    Separate,
    /// Only the first wavelength's Mie; the others follow from the ratio rule of Bruneton &
    /// Neyret 2008 §4 (eq. 9's approximation).
    RedOnly,
}

/// What to precompute.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TableConfig {
    /// Table sizes.
    pub sizes: TableSizes,
    /// Scattering orders summed (1 = single scattering only). Default 4.
    pub orders: usize,
    /// Single Mie storage.
    pub mie: MieStorage,
    /// Add the geometric tail of the orders beyond `orders` to the multiple scattering and
    /// the irradiance ([`precompute::order_tail_factors`]; needs `orders` ≥ 3). Default
    /// true: 4 orders with the tail are as accurate as 8 without.
    #[serde(default = "default_true")]
    pub order_tail: bool,
}

fn default_true() -> bool {
    true
}

impl Default for TableConfig {
    fn default() -> Self {
        TableConfig {
            sizes: TableSizes::default(),
            orders: 4,
            mie: MieStorage::Separate,
            order_tail: true,
        }
    }
}

impl TableConfig {
    /// Check sizes and orders.
    pub fn validate(&self) -> Result<()> {
        self.sizes.validate()?;
        if !(1..=50).contains(&self.orders) {
            return Err(Error::invalid(
                "orders",
                self.orders,
                "an integer in [1, 50]",
            ));
        }
        Ok(())
    }
}

/// The precomputed tables for one atmosphere and wavelength grid.
#[derive(Clone, Debug)]
pub struct Tables {
    /// What was computed.
    pub config: TableConfig,
    /// Wavelengths (nm), one channel each.
    pub wavelengths_nm: Vec<f64>,
    /// Hash of the atmosphere and wavelengths ([`Model::hash`]).
    pub atmosphere_hash: u64,
    /// T(r, μ) to the top of the atmosphere, derived from `optical_depth`
    /// ([`Table2::transmittance_of_optical_depth`]).
    pub transmittance: Table2,
    /// τ(r, μ) = −ln T to the top of the atmosphere, capped at
    /// [`table::MAX_OPTICAL_DEPTH`]: what the table files store and the transmittance
    /// lookups interpolate.
    ///
    /// [`table::MAX_OPTICAL_DEPTH`]: super::table::MAX_OPTICAL_DEPTH
    pub optical_depth: Table2,
    /// Indirect (sky) ground irradiance E(r, μ_s), W·m⁻²·nm⁻¹.
    pub irradiance: Table2,
    /// Single scattering by the molecular (Rayleigh) group without its phase function
    /// (W·m⁻²·sr⁻¹·nm⁻¹ per unit phase).
    pub single_rayleigh: Table4,
    /// Single scattering by the aerosol (Mie) group without its phase function (every
    /// channel, or the first only: [`MieStorage`]).
    pub single_mie: Table4,
    /// Mean radiance of each scattering order over the table texels, per channel (order 1
    /// first): to see that orders decrease.
    pub order_means: Vec<Vec<f64>>,
    /// Ratio rule factors `(β_R[0]/β_M[0])·(β_M[k]/β_R[k])` for [`MieStorage::RedOnly`].
    pub mie_ratio: Vec<f64>,
    /// Multiple scattering, orders 2 to N summed, as radiance (W·m⁻²·sr⁻¹·nm⁻¹). Bruneton
    /// 2017 folds it into the single Rayleigh table divided by the molecular phase function; kept apart,
    /// its interpolation in μ_s does not mix the phase function's values at different ν
    /// (that mix read the anti-solar sky near the horizon +8 % high under a high sun).
    pub multiple: Table4,
}

impl Tables {
    /// Precompute with default settings and no progress report.
    pub fn compute(model: &Model, config: &TableConfig) -> Result<Tables> {
        precompute::precompute(model, config, &|_, _| {}, None)
    }

    /// Whether these tables belong to this model.
    pub fn check_matches(&self, model: &Model, path: &str) -> Result<()> {
        if self.wavelengths_nm != model.wavelengths.nm() {
            return Err(Error::TableFile {
                path: path.to_string(),
                reason: format!(
                    "computed for wavelengths {:?} nm, but {:?} nm are asked for",
                    self.wavelengths_nm,
                    model.wavelengths.nm()
                ),
            });
        }
        if self.atmosphere_hash != model.hash {
            return Err(Error::TableFile {
                path: path.to_string(),
                reason: format!(
                    "computed for another atmosphere (parameter hash {:016x}, this atmosphere's is {:016x}); bake them again",
                    self.atmosphere_hash, model.hash
                ),
            });
        }
        Ok(())
    }

    /// Number of channels.
    pub fn channels(&self) -> usize {
        self.wavelengths_nm.len()
    }
}

//! Bruneton & Neyret 2008, *Precomputed Atmospheric Scattering*, as refined in Bruneton
//! 2017: transmittance, irradiance and 4D scattering tables precomputed for one atmosphere
//! ([`precompute`]), their parameterisations ([`params`]), storage and filtering
//! ([`table`]), lookups ([`lookup`]), the versioned file format ([`file`](mod@file)), and the
//! evaluation of the paper's eq. 16 pieces from them ([`view`]).

pub mod amortised;
pub mod cache;
pub mod compact;
pub mod file;
pub mod lookup;
pub mod mu_s_blend;
pub mod mu_s_logs;
pub mod mu_s_map;
pub mod params;
pub mod precompute;
pub mod r_blend;
pub mod shell;
pub mod table;
mod tables;
pub mod thickness;
pub mod twilight;
pub mod view;

pub use amortised::AmortisedTables;
pub use lookup::Lookup;
use mu_s_logs::MuSLogs;
pub use params::TableSizes;
pub use table::{Table2, Table4};
pub use tables::{MieStorage, TableConfig, Tables};
pub use view::Bruneton4dView;

use super::{SkyMethod, SkyView};
use crate::atmosphere::Model;
use crate::math::Vec3;
use crate::scene::light::Light;
use crate::Result;

/// The 4D-table sky method: a model with its precomputed tables.
pub struct Bruneton4d {
    /// The resolved atmosphere.
    pub model: Model,
    /// Its tables. They must not change once a view has looked them up: `logs` is made
    /// from them.
    pub tables: Tables,
    /// The μ_s log blend's logarithms of the single Rayleigh, single Mie and multiple
    /// scattering tables ([`mu_s_logs`]), each sample's made on first use.
    logs: [MuSLogs; 3],
}

impl Bruneton4d {
    /// Pair a model with tables computed for it (refused if they do not match).
    pub fn new(model: Model, tables: Tables) -> Result<Bruneton4d> {
        tables.check_matches(&model, "(in memory)")?;
        Ok(Bruneton4d::pair(model, tables))
    }

    /// The model and its tables, with the (empty) log stores.
    fn pair(model: Model, tables: Tables) -> Bruneton4d {
        let sizes = tables.config.sizes;
        let cells = mu_s_blend::twilight_cells(&params::Radii::of(&model), sizes.scattering_mu_s);
        let logs = || MuSLogs::new(cells, sizes.scattering_mu_s);
        Bruneton4d {
            model,
            tables,
            logs: [logs(), logs(), logs()],
        }
    }

    /// The log stores of the single Rayleigh, single Mie and multiple scattering tables.
    pub(crate) fn logs(&self) -> &[MuSLogs; 3] {
        &self.logs
    }

    /// Precompute the tables for `model` (no progress report) and pair them.
    pub fn compute(model: Model, config: &TableConfig) -> Result<Bruneton4d> {
        let tables = Tables::compute(&model, config)?;
        Ok(Bruneton4d::pair(model, tables))
    }

    /// Number of wavelengths.
    pub fn channels(&self) -> usize {
        self.model.channels()
    }

    /// Table lookups for a light of angular radius `light_angular_radius_rad`.
    pub fn lookup(&self, light_angular_radius_rad: f64) -> Lookup<'_> {
        Lookup {
            sun_angular_radius: light_angular_radius_rad,
            ..Lookup::new(
                &self.model,
                self.tables.config.sizes,
                &self.tables.optical_depth,
            )
        }
    }
}

impl SkyMethod for Bruneton4d {
    fn model(&self) -> &Model {
        &self.model
    }

    fn view<'a>(&'a self, observer: Vec3, light: &'a Light) -> Box<dyn SkyView + 'a> {
        Box::new(Bruneton4dView::new(self, observer, light))
    }
}

//! The precomputation as a resumable job: Algorithm 4.1's passes cut into units
//! ([`super::plan`]) run one after the other, any number at a time, so that a table update
//! can be spread over several frames (Hillaire 2016 §2 "Our approach"). The intermediate
//! tables (ΔE, ΔJ, ΔS and the sums) live in the job until the last unit assembles the
//! [`Tables`]; no unit depends on how the others were grouped into calls, so any schedule
//! gives the tables of [`super::precompute`] bit for bit.

use super::direct_irradiance::compute_direct_irradiance;
use super::indirect_irradiance::indirect_irradiance_rows;
use super::multiple_scattering::multiple_scattering_slices;
use super::order_tail::{
    add_radiance_sums, add_scaled, add_sums, cap_by_energy, mean_of_sums, order_tail_factors,
};
use super::phase_kernels::PhaseKernels;
use super::plan::{fits, plan, Pass, Unit};
use super::scattering_density::scattering_density_slices;
use super::single_scattering::single_scattering_slices;
use super::transmittance::optical_depth_rows;
use super::{Previous, ScatteringGrid, TRANSMITTANCE_SEGMENTS};
use crate::atmosphere::Model;
use crate::sky::bruneton4d::lookup::Lookup;
use crate::sky::bruneton4d::params::{Radii, TableSizes};
use crate::sky::bruneton4d::table::{Table2, Table4};
use crate::sky::bruneton4d::{MieStorage, TableConfig, Tables};
use crate::Result;

/// A precomputation of the tables of one model, run unit by unit ([`PrecomputeJob::run_unit`],
/// [`PrecomputeJob::step_to`]) and assembled by [`PrecomputeJob::finish`].
pub struct PrecomputeJob {
    model: Model,
    config: TableConfig,
    grid: ScatteringGrid,
    units: Vec<Unit>,
    next: usize,
    done_weight: f64,
    total_weight: f64,
    work: Work,
}

/// The tables being built and the intermediate ones.
struct Work {
    optical_depth: Table2,
    delta_irradiance: Table2,
    irradiance: Table2,
    single_rayleigh: Table4,
    single_mie: Table4,
    kernels: PhaseKernels,
    density: Table4,
    delta_multiple: Table4,
    multiple: Table4,
    /// The running per-channel sum of the order being computed (for its mean).
    sum: Vec<f64>,
    order_means: Vec<Vec<f64>>,
    /// Set by the last unit.
    tables: Option<Tables>,
}

impl PrecomputeJob {
    /// Check the configuration and the model (as [`super::precompute`] does) and plan the
    /// units; nothing is computed yet.
    pub fn new(model: Model, config: &TableConfig) -> Result<PrecomputeJob> {
        config.validate()?;
        crate::sky::bruneton4d::thickness::check(&model)?;
        crate::sky::bruneton4d::shell::check(&model)?;
        let n = model.channels();
        crate::spectrum::check_channels(n, "the precomputed tables")?;
        let s = config.sizes;
        let radii = Radii::of(&model);
        let grid = ScatteringGrid::new(&radii, &s).with_graded_rays(&model, &s);
        let units = plan(config, n, model.constituents.len());
        let total_weight = units.iter().map(|u| u.weight).sum();
        let multiple_orders = config.orders >= 2;
        // Tables only the orders ≥ 2 use stay empty for single scattering alone.
        let table4 = |needed: bool| {
            if needed {
                Table4::for_sizes(&s, n)
            } else {
                Table4::new(0, s.scattering_mu, s.scattering_mu_s, s.scattering_nu, n)
            }
        };
        let work = Work {
            optical_depth: Table2::new(s.transmittance_mu, s.transmittance_r, n),
            delta_irradiance: Table2::new(s.irradiance_mu_s, s.irradiance_r, n),
            irradiance: Table2::new(s.irradiance_mu_s, s.irradiance_r, n),
            single_rayleigh: Table4::for_sizes(&s, n),
            single_mie: Table4::for_sizes(&s, n),
            kernels: if multiple_orders {
                PhaseKernels::zeroed(&s)
            } else {
                PhaseKernels { b: Vec::new() }
            },
            density: table4(multiple_orders),
            delta_multiple: table4(multiple_orders),
            multiple: Table4::for_sizes(&s, n),
            sum: vec![0.0; n],
            order_means: Vec::with_capacity(config.orders),
            tables: None,
        };
        Ok(PrecomputeJob {
            model,
            config: *config,
            grid,
            units,
            next: 0,
            done_weight: 0.0,
            total_weight,
            work,
        })
    }

    /// The model the tables are computed for.
    pub fn model(&self) -> &Model {
        &self.model
    }

    /// Every unit, in the order they run.
    pub fn units(&self) -> &[Unit] {
        &self.units
    }

    /// The unit the next [`PrecomputeJob::run_unit`] runs (None when all have run).
    pub fn next_unit(&self) -> Option<&Unit> {
        self.units.get(self.next)
    }

    /// Units run so far.
    pub fn units_done(&self) -> usize {
        self.next
    }

    /// Whether every unit has run.
    pub fn is_done(&self) -> bool {
        self.next == self.units.len()
    }

    /// The sum of the weights of the units run.
    pub fn done_weight(&self) -> f64 {
        self.done_weight
    }

    /// The sum of every unit's weight.
    pub fn total_weight(&self) -> f64 {
        self.total_weight
    }

    /// The share of the whole cost done, in [0, 1].
    pub fn fraction(&self) -> f64 {
        if self.is_done() {
            1.0
        } else {
            self.done_weight / self.total_weight
        }
    }

    /// Run the next unit; false when none was left.
    pub fn run_unit(&mut self) -> bool {
        let Some(unit) = self.units.get(self.next).cloned() else {
            return false;
        };
        self.run(&unit);
        self.next += 1;
        self.done_weight += unit.weight;
        true
    }

    /// Run units, in order, while the cost done stays at or under `fraction` of the whole
    /// (all of them for `fraction` ≥ 1): a schedule over N frames calls it with k/N at frame
    /// k, so that a frame does at most 1/N of the cost plus one unit and the last one ends
    /// the job. Returns the number of units run.
    pub fn step_to(&mut self, fraction: f64) -> usize {
        let mut count = 0;
        while let Some(unit) = self.next_unit() {
            if !fits(self.done_weight, unit.weight, fraction, self.total_weight) {
                break;
            }
            self.run_unit();
            count += 1;
        }
        count
    }

    /// Run what is left and hand back the model and its tables.
    pub fn finish(mut self) -> (Model, Tables) {
        while self.run_unit() {}
        let tables = self
            .work
            .tables
            .take()
            .expect("the last unit assembles the tables");
        (self.model, tables)
    }

    fn run(&mut self, unit: &Unit) {
        let model = &self.model;
        let s = self.config.sizes;
        let n = model.channels();
        let groups = &model.groups;
        let grid = &self.grid;
        let w = &mut self.work;
        let z = unit.slices.clone();
        let slab = s.scattering_mu * s.scattering_nu * s.scattering_mu_s * n;
        let part = z.start * slab..z.end * slab;
        match unit.pass {
            Pass::Transmittance => {
                let row = s.transmittance_mu * n;
                let out = &mut w.optical_depth.data[z.start * row..z.end * row];
                optical_depth_rows(
                    model,
                    &s,
                    &|r, mu, d, columns| {
                        model.columns_along_ray(r, mu, d, TRANSMITTANCE_SEGMENTS, columns)
                    },
                    z,
                    out,
                );
            }
            Pass::DirectIrradiance => {
                let lookup = Lookup::new(model, s, &w.optical_depth);
                w.delta_irradiance = compute_direct_irradiance(model, &lookup);
            }
            Pass::SingleScattering => {
                let lookup = Lookup::new(model, s, &w.optical_depth);
                single_scattering_slices(
                    model,
                    &lookup,
                    grid,
                    groups,
                    z.clone(),
                    &mut w.single_rayleigh.data[part.clone()],
                    &mut w.single_mie.data[part],
                );
                // The order-1 mean in table order, slice after slice.
                add_radiance_sums(
                    &w.single_rayleigh,
                    &w.single_mie,
                    groups,
                    grid,
                    z.clone(),
                    &mut w.sum,
                );
                if z.end == s.scattering_r {
                    w.order_means.push(mean_of_sums(&w.single_rayleigh, &w.sum));
                    w.sum.iter_mut().for_each(|v| *v = 0.0);
                }
            }
            Pass::PhaseKernels => {
                let lookup = Lookup::new(model, s, &w.optical_depth);
                w.kernels.compute_slices(&lookup, grid, groups, z);
            }
            Pass::ScatteringDensity { order } => {
                let lookup = Lookup::new(model, s, &w.optical_depth);
                let previous = previous(
                    order,
                    &w.single_rayleigh,
                    &w.single_mie,
                    &w.delta_multiple,
                    model,
                );
                scattering_density_slices(
                    model,
                    &lookup,
                    grid,
                    groups,
                    &w.kernels,
                    &previous,
                    &w.delta_irradiance,
                    z,
                    &mut w.density.data[part],
                );
            }
            Pass::IndirectIrradiance { order } => {
                // ΔJ of order + 1 has read the previous ΔE: it is overwritten in place.
                let lookup = Lookup::new(model, s, &w.optical_depth);
                let previous = previous(
                    order + 1,
                    &w.single_rayleigh,
                    &w.single_mie,
                    &w.delta_multiple,
                    model,
                );
                let row = s.irradiance_mu_s * n;
                let rows = z.start * row..z.end * row;
                indirect_irradiance_rows(
                    model,
                    &lookup,
                    &previous,
                    z,
                    &mut w.delta_irradiance.data[rows.clone()],
                );
                for (a, b) in w.irradiance.data[rows.clone()]
                    .iter_mut()
                    .zip(&w.delta_irradiance.data[rows])
                {
                    *a += *b;
                }
            }
            Pass::MultipleScattering { .. } => {
                // ΔJ and ΔE of this order have read the previous ΔS: overwritten in place.
                let lookup = Lookup::new(model, s, &w.optical_depth);
                multiple_scattering_slices(
                    model,
                    &lookup,
                    grid,
                    &w.density,
                    z.clone(),
                    &mut w.delta_multiple.data[part.clone()],
                );
                add_sums(&w.delta_multiple, z.clone(), &mut w.sum);
                for (a, b) in w.multiple.data[part.clone()]
                    .iter_mut()
                    .zip(&w.delta_multiple.data[part])
                {
                    *a += *b;
                }
                if z.end == s.scattering_r {
                    w.order_means.push(mean_of_sums(&w.delta_multiple, &w.sum));
                    w.sum.iter_mut().for_each(|v| *v = 0.0);
                }
            }
            Pass::Finish => {
                let tables = assemble(model, &self.config, w);
                w.tables = Some(tables);
            }
        }
    }
}

/// The radiance field of order `order − 1`, what ΔJ and ΔE of order `order` integrate.
fn previous<'a>(
    order: usize,
    single_rayleigh: &'a Table4,
    single_mie: &'a Table4,
    delta_multiple: &'a Table4,
    model: &'a Model,
) -> Previous<'a> {
    if order == 2 {
        Previous::Single {
            rayleigh: single_rayleigh,
            mie: single_mie,
            groups: &model.groups,
        }
    } else {
        Previous::Multiple(delta_multiple)
    }
}

/// The order tail (when asked for and the orders allow one), the Mie storage, and the
/// tables assembled; the intermediate tables are dropped.
fn assemble(model: &Model, config: &TableConfig, w: &mut Work) -> Tables {
    let s: TableSizes = config.sizes;
    let n = model.channels();
    if config.orders >= 2 && config.order_tail {
        if let Some(mut f) = order_tail_factors(&w.order_means) {
            cap_by_energy(
                &mut f,
                &w.irradiance,
                &w.delta_irradiance,
                &model.solar_irradiance,
            );
            add_scaled(&mut w.multiple.data, &w.delta_multiple.data, &f);
            add_scaled(&mut w.irradiance.data, &w.delta_irradiance.data, &f);
        }
    }
    let empty4 = || Table4::new(0, 0, 0, 0, n);
    let take4 = |t: &mut Table4| std::mem::replace(t, empty4());
    let take2 = |t: &mut Table2| std::mem::replace(t, Table2::new(0, 0, n));
    let single_mie = take4(&mut w.single_mie);
    let single_mie = match config.mie {
        MieStorage::Separate => single_mie,
        MieStorage::RedOnly => {
            let mut red = Table4::for_sizes(&s, 1);
            for (i, v) in red.data.iter_mut().enumerate() {
                *v = single_mie.data[i * n];
            }
            red
        }
    };
    w.density = empty4();
    w.delta_multiple = empty4();
    w.kernels = PhaseKernels { b: Vec::new() };
    let optical_depth = take2(&mut w.optical_depth);
    Tables {
        config: *config,
        wavelengths_nm: model.wavelengths.nm().to_vec(),
        atmosphere_hash: model.hash,
        transmittance: optical_depth.transmittance_of_optical_depth(),
        optical_depth,
        irradiance: take2(&mut w.irradiance),
        single_rayleigh: take4(&mut w.single_rayleigh),
        single_mie,
        order_means: std::mem::take(&mut w.order_means),
        mie_ratio: model.groups.mie_ratio(),
        multiple: take4(&mut w.multiple),
    }
}

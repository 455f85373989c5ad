//! `--method`: which sky method answers (render, query, validate, bench), and the CPU sky a
//! method builds from the atmosphere flags.

use std::time::Instant;

use anyhow::Result;
use clap::ValueEnum;
use firmament::atmosphere::Model;
use firmament::sky::bruneton4d::Bruneton4d;
use firmament::sky::elek3d::{Elek3d, Elek3dConfig};
use firmament::sky::hillaire2020::{Hillaire2020, HillaireConfig, MultipleScatteringModel};
use firmament::sky::SkyMethod;
use serde_json::{json, Value};

use crate::common::AtmosphereArgs;

/// The `--method` flag.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum Method {
    /// Bruneton & Neyret 2008's precomputed 4D tables (`lut` is the same).
    #[default]
    #[value(alias = "lut")]
    Bruneton4d,
    /// Hillaire 2020: transmittance and multiple-scattering tables, a sky-view table per
    /// view, a ray march for the rest (cheap to rebuild: for atmospheres that change).
    Hillaire2020,
    /// Elek 2009 with Yusov 2013's parameterisation: the 4D tables without the view–sun
    /// azimuth, a 3D table (Frostbite 2016; no Earth's shadow, the multiple scattering's
    /// aureole spread over every azimuth: docs/accuracy.md).
    Elek3d,
    /// The spectral Monte Carlo reference path tracer.
    Reference,
}

impl Method {
    /// Its name on the command line and in JSON.
    pub fn name(self) -> &'static str {
        match self {
            Method::Bruneton4d => "bruneton4d",
            Method::Hillaire2020 => "hillaire2020",
            Method::Elek3d => "elek3d",
            Method::Reference => "reference",
        }
    }
}

/// A sky method built on the CPU.
pub enum CpuSky {
    Bruneton4d(Box<Bruneton4d>),
    Hillaire2020(Box<Hillaire2020>),
    Elek3d(Box<Elek3d>),
}

impl CpuSky {
    /// The method behind the seam.
    pub fn method(&self) -> &dyn SkyMethod {
        match self {
            CpuSky::Bruneton4d(s) => s.as_ref(),
            CpuSky::Hillaire2020(s) => s.as_ref(),
            CpuSky::Elek3d(s) => s.as_ref(),
        }
    }

    /// The atmosphere it evaluates.
    pub fn model(&self) -> &Model {
        self.method().model()
    }

    /// The 4D tables, when that is the method.
    pub fn bruneton4d(&self) -> Option<&Bruneton4d> {
        match self {
            CpuSky::Bruneton4d(s) => Some(s),
            _ => None,
        }
    }

    /// The method's name.
    pub fn name(&self) -> &'static str {
        match self {
            CpuSky::Bruneton4d(_) => Method::Bruneton4d.name(),
            CpuSky::Hillaire2020(_) => Method::Hillaire2020.name(),
            CpuSky::Elek3d(_) => Method::Elek3d.name(),
        }
    }

    /// What the method's tables are, for provenance: the 4D tables' configuration, or
    /// Hillaire's sizes and sample counts.
    pub fn tables_json(&self) -> Value {
        match self {
            CpuSky::Bruneton4d(s) => serde_json::to_value(s.tables.config).unwrap_or(Value::Null),
            CpuSky::Hillaire2020(s) => hillaire_json(&s.config, s.max_f_ms),
            CpuSky::Elek3d(s) => elek3d_json(&s.config),
        }
    }
}

/// The 3D tables in words, for provenance.
pub const ELEK3D_IN_WORDS: &str = "elek3d (3D scattering tables without the view-sun azimuth)";

/// The 3D tables' configuration as JSON.
pub fn elek3d_json(c: &Elek3dConfig) -> Value {
    json!({ "elek3d": format!("{c:?}") })
}

/// Hillaire's sizes and counts as JSON.
pub fn hillaire_json(c: &HillaireConfig, max_f_ms: f64) -> Value {
    json!({
        "multiple_scattering_model": match c.multiple_scattering_model {
            MultipleScatteringModel::Isotropic => "isotropic (Hillaire 2020)".to_string(),
            MultipleScatteringModel::Harmonics(d) => format!("harmonics of degree {d} (firmament)"),
        },
        "transmittance": [c.transmittance.0, c.transmittance.1],
        "multiple_scattering": [c.multiple_scattering.0, c.multiple_scattering.1],
        "multiple_scattering_orders": c.multiple_scattering_orders,
        "multiple_scattering_directions": c.multiple_scattering_directions,
        "multiple_scattering_steps": c.multiple_scattering_steps,
        "sky_view": [c.sky_view.0, c.sky_view.1],
        "sky_view_steps": c.sky_view_steps,
        "irradiance": [c.irradiance.0, c.irradiance.1],
        "march_steps": c.march_steps,
        "max_f_ms": max_f_ms,
    })
}

impl AtmosphereArgs {
    /// The sky of `method` on the CPU (the 4D tables through [`AtmosphereArgs::sky`]: file,
    /// cache or precomputed); `reference` is not a tabulated method and is refused here.
    pub fn cpu_sky(&self, method: Method, quiet: bool) -> Result<CpuSky> {
        match method {
            Method::Bruneton4d => Ok(CpuSky::Bruneton4d(Box::new(self.sky(quiet)?))),
            Method::Hillaire2020 => {
                if let Some(path) = &self.tables {
                    anyhow::bail!(
                        "`--tables {}` holds 4D tables: `--method hillaire2020` builds its own (in milliseconds)",
                        path.display()
                    );
                }
                let model = self.model()?;
                let config = self.hillaire.config();
                Ok(CpuSky::Hillaire2020(Box::new(hillaire(
                    model, &config, quiet,
                )?)))
            }
            Method::Elek3d => {
                if let Some(path) = &self.tables {
                    anyhow::bail!(
                        "`--tables {}` holds 4D tables: `--method elek3d` builds its own 3D ones",
                        path.display()
                    );
                }
                let model = self.model()?;
                let started = Instant::now();
                let channels = model.channels();
                let config = Elek3dConfig {
                    orders: self.order_args.orders,
                    order_tail: self.order_args.order_tail,
                    ..Elek3dConfig::default()
                };
                let sky = Elek3d::compute(model, &config)?;
                if !quiet {
                    eprintln!(
                        "tables: {:.2} s (elek3d: 3D tables, {} orders; {channels} wavelengths)",
                        started.elapsed().as_secs_f64(),
                        config.orders
                    );
                }
                Ok(CpuSky::Elek3d(Box::new(sky)))
            }
            Method::Reference => {
                anyhow::bail!("`--method reference` has no tables: it is the path tracer")
            }
        }
    }
}

/// Hillaire's configuration with the second order in harmonics of `degree` (0: Hillaire's
/// isotropic field).
/// Hillaire 2020's options on the commands that evaluate it (query, render, validate).
#[derive(clap::Args, Clone, Copy, Debug, PartialEq, Eq)]
pub struct HillaireArgs {
    /// With `--method hillaire2020`: the second order of multiple scattering as spherical
    /// harmonics up to this degree, each constituent's phase function applied to it
    /// (firmament's extension, 1–8; 6 halves Hillaire's p95 on earth, docs/accuracy.md),
    /// instead of Hillaire's isotropic field (0, the default: as Unreal and Bevy do).
    #[arg(long, default_value_t = 0, value_name = "DEGREE")]
    pub hillaire_harmonics: usize,
    /// With `--method hillaire2020`: the highest scattering order computed explicitly, 2–16
    /// (2, the default: Hillaire's, every further order from the 1/(1 − f_ms) series; from
    /// 4 the rest by the geometric tail of the last two, as the 4D tables do). With
    /// `--hillaire-harmonics 6`, 4 orders take the ground's −5 % bias on earth to about −1 %
    /// at ~3× the build (docs/accuracy.md).
    #[arg(long, default_value_t = 2, value_name = "N")]
    pub hillaire_orders: usize,
}

impl Default for HillaireArgs {
    fn default() -> Self {
        HillaireArgs {
            hillaire_harmonics: 0,
            hillaire_orders: 2,
        }
    }
}

impl HillaireArgs {
    /// The method's configuration (the harmonics with the gather rule they need).
    pub fn config(&self) -> HillaireConfig {
        let base = HillaireConfig {
            multiple_scattering_orders: self.hillaire_orders,
            ..HillaireConfig::default()
        };
        match self.hillaire_harmonics {
            0 => base,
            d => HillaireConfig {
                multiple_scattering_model: MultipleScatteringModel::Harmonics(d),
                // The harmonics need more gather directions than the isotropic mean.
                multiple_scattering_directions: (24, 12),
                ..base
            },
        }
    }

    /// Refuse the options with a method that does not take them.
    pub fn check(&self, methods: &[Method]) -> Result<()> {
        if methods.contains(&Method::Hillaire2020) {
            return Ok(());
        }
        if self.hillaire_harmonics != 0 {
            anyhow::bail!("`--hillaire-harmonics` is for `--method hillaire2020`");
        }
        if self.hillaire_orders != 2 {
            anyhow::bail!("`--hillaire-orders` is for `--method hillaire2020`");
        }
        Ok(())
    }
}

/// Hillaire 2020's tables for `model`, with a `tables:` line on stderr unless `quiet`.
pub fn hillaire(model: Model, config: &HillaireConfig, quiet: bool) -> Result<Hillaire2020> {
    let started = Instant::now();
    let channels = model.channels();
    let sky = Hillaire2020::compute(model, config)?;
    if !quiet {
        eprintln!(
            "tables: {:.1} ms (hillaire2020: transmittance, multiple scattering (f_ms ≤ {:.2}), sky irradiance; {channels} wavelengths)",
            started.elapsed().as_secs_f64() * 1e3,
            sky.max_f_ms
        );
    }
    Ok(sky)
}

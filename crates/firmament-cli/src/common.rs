//! What several subcommands share: choosing the atmosphere and wavelengths, getting the
//! tables (from a file, from the cache, or computed with a progress bar and cached),
//! progress bars and spinners,
//! Ctrl-C, the checks of flag values, and the median that bench and validate report.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::OnceLock;
use std::time::{Duration, Instant};

use anyhow::{Context, Result};
use clap::Args;
use firmament::atmosphere::{Adjustments, Atmosphere, Model};
use firmament::scene::file::DEFAULT_WAVELENGTHS;
use firmament::sky::bruneton4d::cache::{Loaded, TableCache};
use firmament::sky::bruneton4d::{
    self as lut, Bruneton4d, MieStorage, TableConfig, TableSizes, Tables,
};
use firmament::spectrum::Wavelengths;
use indicatif::{ProgressBar, ProgressStyle};

/// Set by Ctrl-C; long work checks it and stops cleanly.
pub fn cancel_flag() -> &'static AtomicBool {
    static FLAG: OnceLock<AtomicBool> = OnceLock::new();
    FLAG.get_or_init(|| {
        let _ = ctrlc::set_handler(|| {
            if cancel_flag().swap(true, Ordering::SeqCst) {
                // Second Ctrl-C: leave at once.
                std::process::exit(130);
            }
            eprintln!("\ninterrupted: stopping (Ctrl-C again to quit at once)");
        });
        AtomicBool::new(false)
    })
}

/// Which atmosphere, which wavelengths, which tables.
#[derive(Args, Debug, Clone)]
pub struct AtmosphereArgs {
    /// Embedded preset: earth (default), bruneton2008, frostbite2016, hazy, mars.
    #[arg(long, conflicts_with = "atmosphere")]
    pub preset: Option<String>,
    /// Atmosphere TOML file (see `firmament atmosphere show earth` for the schema).
    #[arg(long, value_name = "FILE")]
    pub atmosphere: Option<PathBuf>,
    /// Wavelengths: `spectral` (16 samples 365–815 nm, the default: right colours and
    /// luminance), `rgb` (680, 550, 440 nm: fast, a sunset mauve) or a list `NM,NM,...`.
    /// With --tables: the file's.
    #[arg(long, value_name = "spectral|rgb|NM,NM,...")]
    pub wavelengths: Option<String>,
    /// Precomputed tables from `firmament bake` (must match the atmosphere and wavelengths).
    #[arg(long, value_name = "FILE")]
    pub tables: Option<PathBuf>,
    /// Neither read nor write the table cache: compute the tables (in f32) and keep nothing.
    /// The cache is `$FIRMAMENT_CACHE_DIR`, else `$XDG_CACHE_HOME/firmament` or
    /// `~/.cache/firmament`, at most `$FIRMAMENT_CACHE_LIMIT_MB` MiB (default 2048).
    #[arg(long)]
    pub no_cache: bool,
    /// Scattering orders and their tail, when no --tables are given.
    #[command(flatten)]
    pub order_args: OrderArgs,
    /// The atmosphere's aerosols, ozone, Rayleigh scattering, ground or radius changed.
    #[command(flatten)]
    pub adjust: AdjustArgs,
    /// Table sizes when no --tables are given: `default` (Bruneton 2017's sizes) or `small` (fast, coarse).
    #[arg(long, default_value = "default", value_name = "default|small")]
    pub table_size: String,
    /// Store single Mie scattering for every wavelength (`separate`) or only the first (`red-only`, ratio rule).
    #[arg(long, default_value = "separate", value_name = "separate|red-only")]
    pub mie: String,
    /// Hillaire 2020's options; set from the commands' own `--hillaire-harmonics` and
    /// `--hillaire-orders`.
    #[arg(skip)]
    pub hillaire: crate::method::HillaireArgs,
    /// The ground's albedo per wavelength in place of the atmosphere's (a scene's terrain
    /// sets it to its own mean, so the tables' ground bounce is the terrain's).
    #[arg(skip)]
    pub ground_albedo: Option<Vec<f64>>,
    /// The tables' ground raised this far (m) above the planet's sphere, the air below it
    /// taken away (`Atmosphere::lifted`): a scene's terrain sets it to its floor, so the
    /// tables' light comes from the air that the terrain leaves.
    #[arg(skip)]
    pub ground_lift_m: Option<f64>,
}

/// Changes to the preset's or file's atmosphere (`firmament::atmosphere::Adjustments`, a
/// scene's `[atmosphere.adjust]`); errors name the field as `adjust.NAME`.
#[derive(Args, Debug, Clone, Default)]
pub struct AdjustArgs {
    /// The aerosols' vertical optical depth at 550 nm, 0–3 (earth: 0.087, hazy: 0.36):
    /// every aerosol's extinction scaled to it, its spectral shape kept.
    #[arg(long, value_name = "TAU")]
    pub aerosol_optical_depth: Option<f64>,
    /// The ozone column (Dobson units), 0–2000 (earth: 300): the absorbers scaled to it.
    #[arg(long, value_name = "DU")]
    pub ozone_du: Option<f64>,
    /// Factor on the air molecules' (Rayleigh) scattering, 0–10.
    #[arg(long, value_name = "FACTOR")]
    pub rayleigh_scale: Option<f64>,
    /// A grey ground albedo, 0–1, in place of the atmosphere's.
    #[arg(long = "ground-albedo", value_name = "0-1")]
    pub grey_ground_albedo: Option<f64>,
    /// The planet's radius (m), 1e5–1e8; the atmosphere keeps its thickness.
    #[arg(long, value_name = "M")]
    pub planet_radius_m: Option<f64>,
}

impl AdjustArgs {
    /// The flags as the library's adjustments.
    pub fn adjustments(&self) -> Adjustments {
        Adjustments {
            aerosol_optical_depth: self.aerosol_optical_depth,
            ozone_du: self.ozone_du,
            rayleigh_scale: self.rayleigh_scale,
            ground_albedo: self.grey_ground_albedo,
            planet_radius_m: self.planet_radius_m,
        }
    }

    /// The same flags from the library's adjustments (a scene's).
    pub fn of(a: &Adjustments) -> AdjustArgs {
        AdjustArgs {
            aerosol_optical_depth: a.aerosol_optical_depth,
            ozone_du: a.ozone_du,
            rayleigh_scale: a.rayleigh_scale,
            grey_ground_albedo: a.ground_albedo,
            planet_radius_m: a.planet_radius_m,
        }
    }
}

/// The orders of scattering computed tables sum (`query`, `bake`, `render`, through
/// [`AtmosphereArgs`]); refused with --tables, whose file fixes them.
#[derive(Args, Debug, Clone, Copy)]
pub struct OrderArgs {
    /// Scattering orders to precompute (not with --tables: the file's are used).
    #[arg(long, default_value_t = 4, conflicts_with = "tables")]
    pub orders: usize,
    /// Without the geometric tail of the orders beyond --orders (by default added from the
    /// ratio of the last two orders when --orders ≥ 3): the plain truncated sum (not with
    /// --tables).
    #[arg(long = "no-order-tail", action = clap::ArgAction::SetFalse, conflicts_with = "tables")]
    pub order_tail: bool,
}

impl Default for AtmosphereArgs {
    /// The values of an empty command line (the defaults live once, in the clap attributes).
    fn default() -> Self {
        #[derive(clap::Parser)]
        struct Defaults {
            #[command(flatten)]
            atmosphere: AtmosphereArgs,
        }
        <Defaults as clap::Parser>::parse_from(["firmament"]).atmosphere
    }
}

impl AtmosphereArgs {
    /// The chosen atmosphere.
    pub fn atmosphere(&self) -> Result<Atmosphere> {
        let base = match (&self.atmosphere, &self.preset) {
            (Some(path), _) => Atmosphere::from_file(path)?,
            (None, Some(name)) => Atmosphere::preset(name)?,
            (None, None) => Atmosphere::preset("earth")?,
        };
        Ok(base.adjusted(&self.adjust.adjustments())?)
    }

    /// The wavelengths: --wavelengths, else those of the --tables file, else spectral.
    pub fn wavelengths(&self) -> Result<Wavelengths> {
        Ok(match (&self.wavelengths, &self.tables) {
            (Some(w), _) => Wavelengths::parse(w)?,
            (None, Some(path)) => {
                Wavelengths::from_list(&lut::file::read_header(path)?.wavelengths_nm)?
            }
            (None, None) => Wavelengths::parse(DEFAULT_WAVELENGTHS)?,
        })
    }

    /// The resolved model.
    pub fn model(&self) -> Result<Model> {
        let wavelengths = self.wavelengths()?;
        let mut atmosphere = self.atmosphere()?;
        if let Some(lift) = self.ground_lift_m {
            atmosphere = atmosphere.lifted(lift, &wavelengths)?;
        }
        let mut model = atmosphere.resolve(&wavelengths)?;
        if let Some(albedo) = &self.ground_albedo {
            model.ground_albedo.clone_from(albedo);
        }
        Ok(model)
    }

    /// The same arguments with the planet's own ground (no lift): the atmosphere as it is,
    /// for the reference path tracer, which meets the terrain itself.
    pub fn unlifted(&self) -> AtmosphereArgs {
        AtmosphereArgs {
            ground_lift_m: None,
            ..self.clone()
        }
    }

    /// The table configuration for a fresh precomputation.
    pub fn table_config(&self) -> Result<TableConfig> {
        let sizes = match self.table_size.as_str() {
            "default" => TableSizes::default(),
            "small" => TableSizes::small(),
            other => anyhow::bail!(
                "invalid value for `--table-size`: {other} (accepted: default, small)"
            ),
        };
        let mie = match self.mie.as_str() {
            "separate" => MieStorage::Separate,
            "red-only" => MieStorage::RedOnly,
            other => {
                anyhow::bail!("invalid value for `--mie`: {other} (accepted: separate, red-only)")
            }
        };
        let config = TableConfig {
            sizes,
            orders: self.order_args.orders,
            mie,
            order_tail: self.order_args.order_tail,
        };
        config.validate()?;
        Ok(config)
    }

    /// Model and tables (read from --tables, from the cache, or computed and cached),
    /// paired.
    pub fn sky(&self, quiet: bool) -> Result<Bruneton4d> {
        let model = self.model()?;
        let tables = match &self.tables {
            Some(path) => {
                let t = lut::file::read(path)?;
                t.check_matches(&model, &path.display().to_string())?;
                t
            }
            None if self.no_cache => compute_tables(&model, &self.table_config()?, quiet)?,
            None => cached_tables(&model, &self.table_config()?, quiet)?,
        };
        Ok(Bruneton4d::new(model, tables)?)
    }
}

/// Precompute with a progress bar on stderr (hidden when `quiet` or not a terminal) and say
/// how long it took.
pub fn compute_tables(model: &Model, config: &TableConfig, quiet: bool) -> Result<Tables> {
    let started = Instant::now();
    let tables = precompute_with_bar(model, config, quiet)?;
    if !quiet {
        print_tables_time(started, model, config, "", "");
    }
    Ok(tables)
}

/// The clouds of a scene file over a planet of `planet_radius_m`, their noise textures
/// from the user's cache directory ([`TableCache::from_env`]) or computed (about 2 s) and
/// kept there, with a line on stderr (unless `quiet`).
pub fn scene_clouds(
    scene: &firmament::scene::SceneFile,
    planet_radius_m: f64,
    no_cache: bool,
    quiet: bool,
) -> Result<Vec<firmament::scene::clouds::CloudMedium>> {
    if scene.clouds.is_empty() {
        return Ok(Vec::new());
    }
    let started = Instant::now();
    // The noise volumes from the table cache's directory, unless --no-cache.
    let cache = match no_cache {
        true => None,
        false => TableCache::from_env()?.map(|c| c.dir),
    };
    let clouds = scene.build_clouds(planet_radius_m, cache.as_deref())?;
    if !quiet {
        eprintln!(
            "clouds: {} layer{} ({}) ready in {:.2} s",
            clouds.len(),
            if clouds.len() == 1 { "" } else { "s" },
            clouds
                .iter()
                .map(|c| format!(
                    "{:?} {:.0}–{:.0} m",
                    c.layer.params.kind, c.layer.params.bottom_m, c.layer.params.top_m
                )
                .to_lowercase())
                .collect::<Vec<_>>()
                .join(", "),
            started.elapsed().as_secs_f64()
        );
    }
    Ok(clouds)
}

/// The tables from the user's cache ([`TableCache::from_env`]), or computed and cached
/// there, with a line on stderr saying which (unless `quiet`) and a warning when a cached
/// file was unusable (deleted, computed again) or the tables could not be cached.
pub fn cached_tables(model: &Model, config: &TableConfig, quiet: bool) -> Result<Tables> {
    let Some(cache) = TableCache::from_env()? else {
        if !quiet {
            eprintln!("note: no table cache (neither $FIRMAMENT_CACHE_DIR, $XDG_CACHE_HOME nor $HOME is set)");
        }
        return compute_tables(model, config, quiet);
    };
    let started = Instant::now();
    match cache.load(model, config) {
        Loaded::Hit { tables, path } => {
            if !quiet {
                eprintln!(
                    "tables: from cache {} in {:.2} s ({} wavelengths, {} orders)",
                    path.display(),
                    started.elapsed().as_secs_f64(),
                    model.channels(),
                    config.orders
                );
            }
            return Ok(*tables);
        }
        Loaded::Discarded { path, reason } => eprintln!(
            "warning: the cached tables {} were unusable ({reason}): deleted, computing them again",
            path.display()
        ),
        Loaded::Missing { .. } => {}
    }
    let started = Instant::now();
    let tables = precompute_with_bar(model, config, quiet)?;
    let line = tables_line(started.elapsed().as_secs_f64(), model, config, "", "");
    match cache.store(&tables, model, config) {
        Ok(stored) => {
            if !quiet {
                let evicted = match stored.evicted.len() {
                    0 => String::new(),
                    n => format!(
                        " ({n} least recently used file{} removed to stay within {} MiB)",
                        if n == 1 { "" } else { "s" },
                        cache.limit_bytes >> 20
                    ),
                };
                eprintln!("{line}; cached at {}{evicted}", stored.path.display());
            }
            Ok(*stored.tables)
        }
        Err(e) => {
            if !quiet {
                eprintln!("{line}");
            }
            eprintln!("warning: tables not cached: {e}");
            Ok(tables)
        }
    }
}

/// The precomputation under a progress bar.
fn precompute_with_bar(model: &Model, config: &TableConfig, quiet: bool) -> Result<Tables> {
    let bar = progress_bar(1000, quiet);
    bar.set_message("precomputing tables");
    let tables = lut::precompute::precompute(
        model,
        config,
        &|stage, fraction| {
            bar.set_position((fraction * 1000.0) as u64);
            bar.set_message(stage.to_string());
        },
        Some(cancel_flag()),
    );
    bar.finish_and_clear();
    tables.context("precomputing the tables")
}

/// The line on stderr after a precomputation started at `started`: `tables: SECONDS
/// s{place} (N wavelengths, M orders{note})`.
pub fn print_tables_time(
    started: Instant,
    model: &Model,
    config: &TableConfig,
    place: &str,
    note: &str,
) {
    let seconds = started.elapsed().as_secs_f64();
    eprintln!("{}", tables_line(seconds, model, config, place, note));
}

/// `tables: SECONDS s{place} (N wavelengths, M orders{note})`.
fn tables_line(
    seconds: f64,
    model: &Model,
    config: &TableConfig,
    place: &str,
    note: &str,
) -> String {
    format!(
        "tables: {seconds:.2} s{place} ({} wavelengths, {} orders{note})",
        model.channels(),
        config.orders
    )
}

/// `wavelengths: spectral (16 samples 365–815 nm)` on stderr, unless `quiet`: which
/// wavelengths a picture or an answer is computed at.
pub fn print_wavelengths(model: &Model, quiet: bool) {
    if !quiet {
        eprintln!("wavelengths: {}", model.wavelengths.describe());
    }
}

/// A progress bar drawn on stderr only for work long enough to need one.
pub fn progress_bar(len: u64, quiet: bool) -> ProgressBar {
    if quiet {
        return ProgressBar::hidden();
    }
    drawn(
        ProgressBar::new(len),
        "{spinner} [{elapsed_precise}] {wide_bar} {percent:>3}% {msg}",
    )
}

/// A progress bar drawn with `template` (indicatif's keys), hidden when `quiet`.
pub fn drawn_bar(len: u64, quiet: bool, template: &str) -> ProgressBar {
    if quiet {
        return ProgressBar::hidden();
    }
    drawn(ProgressBar::new(len), template)
}

/// A spinner on stderr for work that reports no progress (the GPU's); hidden when `quiet`.
pub fn spinner(message: &str, quiet: bool) -> ProgressBar {
    if quiet {
        return ProgressBar::hidden();
    }
    let bar = drawn(
        ProgressBar::new_spinner(),
        "{spinner} [{elapsed_precise}] {msg}",
    );
    bar.set_message(message.to_string());
    bar
}

/// `bar` drawn with `template`, ticking by itself.
fn drawn(bar: ProgressBar, template: &str) -> ProgressBar {
    bar.set_style(ProgressStyle::with_template(template).expect("valid template"));
    bar.enable_steady_tick(Duration::from_millis(200));
    bar
}

/// Check a finite number is within [lo, hi]; the message names the flag.
pub fn check_range(flag: &str, v: f64, lo: f64, hi: f64, unit: &str) -> Result<()> {
    if v.is_finite() && v >= lo && v <= hi {
        Ok(())
    } else {
        anyhow::bail!("invalid value for `{flag}`: {v} (accepted: a number in [{lo}, {hi}] {unit})")
    }
}

/// The reference path tracer's `--samples`: at least 2 paths (a standard error needs two).
pub fn check_reference_samples(samples: usize) -> Result<()> {
    if samples < 2 {
        anyhow::bail!("invalid value for `--samples`: {samples} (accepted: an integer ≥ 2)");
    }
    Ok(())
}

/// The directory of a path exists (for clear errors before long work).
pub fn check_output_dir(path: &Path, flag: &str) -> Result<()> {
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    if !dir.is_dir() {
        anyhow::bail!(
            "invalid value for `{flag}`: {} (directory {} does not exist)",
            path.display(),
            dir.display()
        );
    }
    Ok(())
}

/// The median of a sorted sample (NaN when it is empty).
pub fn median_of_sorted(sorted: &[f64]) -> f64 {
    let n = sorted.len();
    if n == 0 {
        return f64::NAN;
    }
    if n % 2 == 1 {
        sorted[n / 2]
    } else {
        0.5 * (sorted[n / 2 - 1] + sorted[n / 2])
    }
}

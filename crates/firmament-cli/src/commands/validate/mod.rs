//! `firmament validate`: a sky method (the 4D tables, Hillaire 2020) measured against the
//! Monte Carlo reference.
//!
//! For each configuration (preset × observer altitude × sun elevation) a documented set of
//! view directions is traced by the reference path tracer (sky only, sun disk excluded:
//! the same quantity as `SkyView::sky_radiance`) and evaluated with the precomputed tables; the
//! relative errors of luminance (Y) and of each wavelength's radiance are summarised by
//! their median, 95th percentile and maximum, next to the reference's own median relative
//! standard error, the signed median (bias), and the root mean square with and without the
//! reference's noise (√(⟨e²⟩ − ⟨σ²⟩): what remains is the table method's own error). See
//! `docs/accuracy.md` for the set, the results and their analysis.
//!
//! View directions (azimuths relative to the sun; the sky is symmetric about the sun's
//! vertical plane, so 0–180° covers it):
//! - above the horizon: elevations 0.5, 1, 2, 4, 7, 10, 15, 25, 40, 60° at relative
//!   azimuths 0, 30, 60, 90, 135, 180°, and the zenith;
//! - around the sun: 2, 4 and 8° from its centre, towards the zenith, sideways and towards
//!   the horizon (views within 1° of the sun are skipped: the disk is excluded);
//! - below the horizon when the observer is above the ground: −1, −3, −10, −30, −60°, the
//!   geometric horizon ±0.1, ±0.5° and −2° below it, the nadir; from space also just
//!   inside the atmosphere's limb and three elevations between the limb and the horizon.
//!
//! Views whose reference radiance is 0 (rays that miss the atmosphere) are skipped.
//! The reference uses adaptive sample counts: a pilot of 1024 paths per wavelength, then
//! enough paths for the target relative standard error of luminance (capped), unless
//! `--samples` fixes the count.

mod compare;
mod reuse;
mod sampling;
mod summary;
mod views;

use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result};
use clap::{Args, ValueEnum};
use firmament::math::Vec3;
use firmament::spectrum::ColourMatrix;
use serde_json::{json, Value};

use crate::common::{
    check_output_dir, check_range, check_reference_samples, progress_bar, AtmosphereArgs, OrderArgs,
};
use crate::method::{CpuSky, HillaireArgs, Method};
use compare::{compare_method, ViewRecord};
use reuse::StoredReference;
use sampling::{trace_views, SamplePlan, PILOT_SAMPLES};
use summary::{RelativeErrors, Summaries};
use views::{direction_from_elevation_deg, views};

/// The accuracy goal `validate` checks (docs/accuracy.md): over the views of `earth` with
/// the sun at least [`DAYLIGHT_DEG`] high, the median of the luminance's relative errors at
/// most 2 % and their 95th percentile at most 5 %.
const MEDIAN_LIMIT: f64 = 0.02;
const P95_LIMIT: f64 = 0.05;
/// Daylight: sun elevation at least this (degrees).
const DAYLIGHT_DEG: f64 = 5.0;

/// Arguments of `firmament validate`.
#[derive(Args, Debug)]
pub struct ValidateArgs {
    /// Presets to validate, comma-separated (default: earth,bruneton2008,hazy; --quick: earth).
    #[arg(long, value_name = "NAME,...")]
    pub preset: Option<String>,
    /// Atmosphere TOML files to validate, comma-separated, after the presets (with no
    /// --preset, the files alone): e.g. the extreme geometries of `atmospheres/`. Each is
    /// labelled by its file stem.
    #[arg(long, value_name = "FILE,...")]
    pub atmosphere: Option<String>,
    /// Write every figure (per view and summaries) to this JSON file.
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
    /// Reduced set for CI: earth, altitudes 0 and 1 km (with views down to the ground), sun
    /// elevations 30 and 10°, 23–35 views each, small tables, 1 % target noise; fails when
    /// the daylight thresholds are broken.
    #[arg(long)]
    pub quick: bool,
    /// Fixed paths per wavelength and view (default: adaptive, see --target-stderr).
    #[arg(long)]
    pub samples: Option<usize>,
    /// Target relative standard error of the reference luminance per view, in percent
    /// (default 0.5; --quick 1.0). Adaptive counts are capped at --max-samples.
    #[arg(long, value_name = "PERCENT")]
    pub target_stderr: Option<f64>,
    /// Cap of the adaptive paths per wavelength and view.
    #[arg(long, default_value_t = 65_536)]
    pub max_samples: usize,
    /// Sky methods to validate, comma-separated: bruneton4d (or lut), hillaire2020, elek3d; several
    /// are compared against the same reference (the first is checked against the
    /// thresholds).
    #[arg(long, default_value = "bruneton4d", value_name = "METHOD,...")]
    pub method: String,
    /// Scattering orders of the 4D tables; a list `4,8` compares several against the same
    /// reference (the first is the one checked against the thresholds).
    #[arg(long, default_value = "4", value_name = "N,...")]
    pub orders: String,
    #[command(flatten)]
    pub hillaire: crate::method::HillaireArgs,
    /// Tables without the geometric tail of the orders beyond --orders.
    #[arg(long)]
    pub no_order_tail: bool,
    /// Table sizes: default or small (default: default; --quick: small).
    #[arg(long, value_name = "default|small")]
    pub table_size: Option<String>,
    /// Observer altitudes (m), comma-separated (default: 0,1000,10000,100000; --quick: 0,1000).
    #[arg(long, value_name = "M,...")]
    pub altitudes: Option<String>,
    /// Sun elevations (degrees), comma-separated (default: 90,60,30,10,5,2,0,-3,-6).
    #[arg(long, value_name = "DEG,...", allow_hyphen_values = true)]
    pub sun_elevations: Option<String>,
    /// Only the daylight sun elevations (≥ 5°) of the chosen set.
    #[arg(long)]
    pub daylight: bool,
    /// Wavelengths: rgb, spectral or NM,NM,...
    #[arg(long, default_value = "rgb")]
    pub wavelengths: String,
    /// Seed of the reference's random streams.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Reuse the reference of an earlier run: its `--json` file. Its configurations are
    /// read, not traced (they must hold this run's views and wavelengths), so a method's
    /// before and after are compared against the very same estimates in seconds; the
    /// configurations it lacks are traced.
    #[arg(long, value_name = "FILE")]
    pub reference: Option<PathBuf>,
    /// Print nothing but the results and errors.
    #[arg(long, short)]
    pub quiet: bool,
}

fn parse_list<T: std::str::FromStr>(flag: &str, s: &str, what: &str) -> Result<Vec<T>> {
    let v: Option<Vec<T>> = s.split(',').map(|p| p.trim().parse().ok()).collect();
    match v {
        Some(v) if !v.is_empty() => Ok(v),
        _ => anyhow::bail!("invalid value for `{flag}`: {s:?} (accepted: {what})"),
    }
}

/// What a run validates, from the arguments; everything is checked before the long work.
struct Selection {
    /// Preset names and atmosphere files (their stems label them).
    presets: Vec<Source>,
    altitudes_m: Vec<f64>,
    sun_elevations_deg: Vec<f64>,
    /// The methods, each 4D one with each of `orders`; the first is checked.
    methods: Vec<Method>,
    /// Scattering orders of each 4D table configuration.
    orders: Vec<usize>,
    table_size: String,
    wavelengths: String,
    order_tail: bool,
    hillaire: HillaireArgs,
    samples: SamplePlan,
}

impl Selection {
    fn from_args(args: &ValidateArgs) -> Result<Selection> {
        let names: Vec<String> = match (&args.preset, &args.atmosphere) {
            (Some(p), _) => parse_list("--preset", p, "preset names separated by commas")?,
            (None, Some(_)) => Vec::new(),
            (None, None) if args.quick => vec!["earth".into()],
            (None, None) => vec!["earth".into(), "bruneton2008".into(), "hazy".into()],
        };
        let mut presets: Vec<Source> = names.into_iter().map(Source::Preset).collect();
        if let Some(files) = &args.atmosphere {
            let files: Vec<PathBuf> =
                parse_list("--atmosphere", files, "TOML files separated by commas")?;
            for f in files {
                if !f.is_file() {
                    anyhow::bail!(
                        "invalid value for `--atmosphere`: {} is not a file (accepted: atmosphere TOML files separated by commas)",
                        f.display()
                    );
                }
                presets.push(Source::File(f));
            }
        }
        let altitudes_m: Vec<f64> = match &args.altitudes {
            Some(s) => parse_list("--altitudes", s, "altitudes in m separated by commas")?,
            None if args.quick => vec![0.0, 1000.0],
            None => vec![0.0, 1000.0, 10_000.0, 100_000.0],
        };
        for &a in &altitudes_m {
            check_range("--altitudes", a, 0.0, 1e9, "m")?;
        }
        let mut sun_elevations_deg: Vec<f64> = match &args.sun_elevations {
            Some(s) => parse_list("--sun-elevations", s, "degrees separated by commas")?,
            None if args.quick => vec![30.0, 10.0],
            None => vec![90.0, 60.0, 30.0, 10.0, 5.0, 2.0, 0.0, -3.0, -6.0],
        };
        for &e in &sun_elevations_deg {
            check_range("--sun-elevations", e, -90.0, 90.0, "degrees")?;
        }
        if args.daylight {
            sun_elevations_deg.retain(|&e| e >= DAYLIGHT_DEG);
            if sun_elevations_deg.is_empty() {
                anyhow::bail!("`--daylight` leaves no sun elevation ≥ {DAYLIGHT_DEG}°");
            }
        }
        let orders: Vec<usize> =
            parse_list("--orders", &args.orders, "integers separated by commas")?;
        let methods: Vec<Method> = args
            .method
            .split(',')
            .map(|m| match Method::from_str(m.trim(), true) {
                Ok(Method::Reference) | Err(_) => anyhow::bail!(
                    "invalid value for `--method`: {m:?} (accepted: bruneton4d (or lut), hillaire2020, elek3d, separated by commas)"
                ),
                Ok(m) => Ok(m),
            })
            .collect::<Result<_>>()?;
        args.hillaire.check(&methods)?;
        let table_size = args
            .table_size
            .clone()
            .unwrap_or_else(|| if args.quick { "small" } else { "default" }.into());
        let samples = match args.samples {
            Some(n) => {
                check_reference_samples(n)?;
                SamplePlan::Fixed(n)
            }
            None => {
                let pct = args
                    .target_stderr
                    .unwrap_or(if args.quick { 1.0 } else { 0.5 });
                check_range("--target-stderr", pct, 0.01, 50.0, "percent")?;
                SamplePlan::Adaptive {
                    target: pct / 100.0,
                    max: if args.quick {
                        args.max_samples.min(16_384)
                    } else {
                        args.max_samples
                    },
                }
            }
        };
        let selection = Selection {
            presets,
            altitudes_m,
            sun_elevations_deg,
            methods,
            orders,
            table_size,
            wavelengths: args.wavelengths.clone(),
            order_tail: !args.no_order_tail,
            hillaire: args.hillaire,
            samples,
        };
        for p in &selection.presets {
            for &o in &selection.orders {
                selection.atmosphere(p, o).table_config()?;
            }
            selection.atmosphere(p, selection.orders[0]).model()?;
        }
        Ok(selection)
    }

    /// What is compared with the reference: each method, a 4D one once per `orders`.
    fn candidates(&self) -> Vec<Candidate> {
        self.methods
            .iter()
            .flat_map(|&method| match method {
                Method::Bruneton4d => self
                    .orders
                    .iter()
                    .map(|&o| Candidate {
                        method,
                        orders: Some(o),
                    })
                    .collect::<Vec<_>>(),
                _ => vec![Candidate {
                    method,
                    orders: None,
                }],
            })
            .collect()
    }

    /// The atmosphere and tables of `preset` with `orders`.
    fn atmosphere(&self, preset: &Source, orders: usize) -> AtmosphereArgs {
        let (preset, atmosphere) = match preset {
            Source::Preset(name) => (Some(name.clone()), None),
            Source::File(path) => (None, Some(path.clone())),
        };
        AtmosphereArgs {
            preset,
            atmosphere,
            wavelengths: Some(self.wavelengths.clone()),
            order_args: OrderArgs {
                orders,
                order_tail: self.order_tail,
            },
            table_size: self.table_size.clone(),
            hillaire: self.hillaire,
            ..AtmosphereArgs::default()
        }
    }

    /// The first line printed.
    fn headline(&self) -> String {
        format!(
            "firmament validate: {} vs Monte Carlo reference; relative errors over views \
             (sun disk excluded), reference's median relative standard error in brackets; 4D tables \
             {}, orders {:?}{}, reference {}",
            self.candidates().iter().map(Candidate::label).collect::<Vec<_>>().join(", "),
            self.table_size,
            self.orders,
            if self.order_tail {
                " + geometric tail"
            } else {
                " (no tail)"
            },
            match self.samples {
                SamplePlan::Fixed(n) => format!("{n} paths/λ"),
                SamplePlan::Adaptive { target, max } => format!(
                    "adaptive to {:.2}% luminance stderr ({PILOT_SAMPLES}–{max} paths/λ)",
                    100.0 * target
                ),
            }
        )
    }
}

/// Run `firmament validate`; prints the table and returns an error when the daylight
/// thresholds are broken (after writing the JSON).
pub fn run(args: &ValidateArgs) -> Result<()> {
    let started = Instant::now();
    if let Some(path) = &args.json {
        check_output_dir(path, "--json")?;
    }
    let selection = Selection::from_args(args)?;
    let candidates = selection.candidates();
    let mut configurations_json = Vec::new();
    let mut wavelengths_nm: Vec<f64> = Vec::new();
    // Earth daylight aggregates, one per candidate.
    let mut daylight: Vec<Option<RelativeErrors>> = candidates.iter().map(|_| None).collect();
    let mut configuration_index = 0u64;
    let mut stored: Option<StoredReference> = None;
    println!("{}", selection.headline());
    for source in &selection.presets {
        let preset = source.label();
        let skies: Vec<CpuSky> = candidates
            .iter()
            .map(|c| {
                selection
                    .atmosphere(source, c.orders.unwrap_or(selection.orders[0]))
                    .cpu_sky(c.method, args.quiet)
                    .with_context(|| format!("{} for {preset}", c.label()))
            })
            .collect::<Result<_>>()?;
        let model = skies[0].model();
        wavelengths_nm = model.wavelengths.nm().to_vec();
        if let (Some(path), None) = (&args.reference, &stored) {
            let read = StoredReference::read(path, &wavelengths_nm)?;
            if !args.quiet {
                println!(
                    "reference read from {} where it has the configuration",
                    read.path()
                );
            }
            stored = Some(read);
        }
        let colour = ColourMatrix::new(&wavelengths_nm);
        let configurations: Vec<(f64, f64)> = selection
            .altitudes_m
            .iter()
            .flat_map(|&a| selection.sun_elevations_deg.iter().map(move |&e| (a, e)))
            .collect();
        let view_sets: Vec<_> = configurations
            .iter()
            .map(|&(a, e)| views(model, a, direction_from_elevation_deg(e, 0.0), args.quick))
            .collect();
        let total: usize = view_sets.iter().map(|v| v.0.len()).sum();
        let bar = progress_bar(total as u64, args.quiet);
        bar.set_message(format!("reference: {preset}"));
        for (&(altitude, elevation), (views, skipped)) in configurations.iter().zip(&view_sets) {
            configuration_index += 1;
            let reference_started = Instant::now();
            let sun = direction_from_elevation_deg(elevation, 0.0);
            let camera = Vec3::new(0.0, 0.0, model.bottom_radius_m + altitude);
            let reused = match &stored {
                Some(s) => s.estimates(&preset, altitude, elevation, views)?,
                None => None,
            };
            let from_file = reused.is_some();
            let estimates = match reused {
                Some(estimates) => {
                    bar.inc(views.len() as u64);
                    estimates
                }
                None => trace_views(
                    model,
                    &colour,
                    camera,
                    sun,
                    views,
                    &selection.samples,
                    args.seed,
                    configuration_index,
                    &bar,
                )?,
            };
            let reference_seconds = reference_started.elapsed().as_secs_f64();
            let samples: Vec<usize> = estimates.iter().map(|e| e.samples).collect();
            let mut records: Vec<ViewRecord> = views
                .iter()
                .zip(estimates)
                .map(|(v, e)| ViewRecord::new(v, e, &colour))
                .collect();
            let errors: Vec<RelativeErrors> = skies
                .iter()
                .zip(&candidates)
                .map(|(sky, c)| {
                    compare_method(sky.method(), c, &colour, camera, sun, views, &mut records)
                })
                .collect();
            let summaries: Vec<Summaries> = errors
                .iter()
                .map(|e| e.summaries(&wavelengths_nm))
                .collect();
            bar.suspend(|| {
                println!(
                    "{preset} altitude {altitude} m, sun elevation {elevation}°: {} views ({} skipped), {}–{} paths/λ, reference {}",
                    views.len(),
                    skipped,
                    samples.iter().min().unwrap_or(&0),
                    samples.iter().max().unwrap_or(&0),
                    if from_file {
                        "read from --reference".to_string()
                    } else {
                        format!("{reference_seconds:.1} s")
                    }
                );
                for (c, s) in candidates.iter().zip(&summaries) {
                    if candidates.len() > 1 {
                        println!("  {}:", c.label());
                    }
                    s.print();
                }
            });
            if matches!(source, Source::Preset(n) if n == "earth") && elevation >= DAYLIGHT_DEG {
                for (aggregate, e) in daylight.iter_mut().zip(&errors) {
                    aggregate
                        .get_or_insert_with(|| RelativeErrors::new(wavelengths_nm.len()))
                        .extend(e);
                }
            }
            configurations_json.push(json!({
                "preset": preset,
                "altitude_m": altitude,
                "sun_elevation_deg": elevation,
                "views_skipped": skipped,
                "reference_seconds": reference_seconds,
                "reference_from_file": from_file,
                "tables": candidates.iter().zip(&summaries).map(|(c, s)| json!({
                    "method": c.method.name(),
                    "orders": c.orders,
                    "summary": s,
                })).collect::<Vec<_>>(),
                "views": records,
            }));
        }
        bar.finish_and_clear();
    }

    let mut aggregates = Vec::new();
    let mut broken: Option<String> = None;
    for (oi, aggregate) in daylight.iter().enumerate() {
        let Some(aggregate) = aggregate else { continue };
        let summaries = aggregate.summaries(&wavelengths_nm);
        let y = &summaries.luminance;
        let pass = y.median <= MEDIAN_LIMIT && y.p95 <= P95_LIMIT;
        println!(
            "earth daylight (sun elevation ≥ {DAYLIGHT_DEG}°), all altitudes, {}: {} views{}",
            candidates[oi].label(),
            y.count,
            if pass { "" } else { "  THRESHOLDS BROKEN" }
        );
        summaries.print();
        if oi == 0 && !pass {
            broken = Some(format!(
                "{}: earth daylight luminance error: median {:.2}% (limit {:.0}%), p95 {:.2}% (limit {:.0}%)",
                candidates[oi].label(),
                100.0 * y.median,
                100.0 * MEDIAN_LIMIT,
                100.0 * y.p95,
                100.0 * P95_LIMIT
            ));
        }
        aggregates.push(json!({
            "preset": "earth",
            "selection": format!("sun elevation >= {DAYLIGHT_DEG} deg, all altitudes of this run"),
            "method": candidates[oi].method.name(),
            "orders": candidates[oi].orders,
            "summary": summaries,
            "pass": pass,
        }));
    }
    let elapsed = started.elapsed().as_secs_f64();
    println!("validate: {elapsed:.1} s");
    if let Some(path) = &args.json {
        let value = json!({
            "command": std::env::args().collect::<Vec<_>>(),
            "quick": args.quick,
            "presets": selection.presets.iter().map(Source::label).collect::<Vec<_>>(),
            "altitudes_m": selection.altitudes_m,
            "sun_elevations_deg": selection.sun_elevations_deg,
            "methods": selection.methods.iter().map(|m| m.name()).collect::<Vec<_>>(),
            "orders": selection.orders,
            "order_tail": selection.order_tail,
            "table_size": selection.table_size,
            "wavelengths_nm": wavelengths_nm,
            "seed": args.seed,
            "reference_file": args.reference.as_ref().map(|p| p.display().to_string()),
            "samples": match selection.samples {
                SamplePlan::Fixed(n) => json!({ "fixed": n }),
                SamplePlan::Adaptive { target, max } => json!({
                    "adaptive_target_relative_stderr_luminance": target,
                    "pilot": PILOT_SAMPLES,
                    "max": max,
                }),
            },
            "definitions": {
                "relative_error": "table / reference - 1, per view; summaries over views of |relative error|",
                "luminance": "CIE Y from the spectral samples (ColourMatrix), cd m-2",
                "views": "sky only (SkyView::sky_radiance of the 4D tables vs reference::sky_radiance, include_ground = false): in-scattered radiance, the sun disk seen directly excluded; views within 1 deg of the sun skipped; azimuths relative to the sun",
                "p95": "nearest-rank 95th percentile",
            },
            "thresholds": {
                "selection": "earth, sun elevation >= 5 deg",
                "median": MEDIAN_LIMIT,
                "p95": P95_LIMIT,
            },
            "aggregates": aggregates,
            "configurations": configurations_json,
            "elapsed_s": elapsed,
            "threads": rayon::current_num_threads(),
        });
        write_json(path, &value)?;
        if !args.quiet {
            eprintln!("wrote {}", path.display());
        }
    }
    if let Some(msg) = broken {
        anyhow::bail!("daylight thresholds broken: {msg}");
    }
    Ok(())
}

/// An atmosphere `validate` measures: an embedded preset or a TOML file.
enum Source {
    Preset(String),
    File(PathBuf),
}

impl Source {
    /// The preset's name, or the file's stem.
    fn label(&self) -> String {
        match self {
            Source::Preset(name) => name.clone(),
            Source::File(path) => path.file_stem().map_or_else(
                || path.display().to_string(),
                |s| s.to_string_lossy().into(),
            ),
        }
    }
}

/// One sky method compared with the reference: a method, and the orders of 4D tables.
pub struct Candidate {
    pub method: Method,
    pub orders: Option<usize>,
}

impl Candidate {
    /// "bruneton4d, 4 orders" or "hillaire2020".
    pub fn label(&self) -> String {
        match self.orders {
            Some(o) => format!("{}, {o} orders", self.method.name()),
            None => self.method.name().to_string(),
        }
    }
}

/// Write `value` to `path`, atomically.
fn write_json(path: &Path, value: &Value) -> Result<()> {
    let text = serde_json::to_string_pretty(value)?;
    firmament::io::write_atomic(path, |out| Ok(out.write_all(text.as_bytes())?))
        .with_context(|| format!("writing {}", path.display()))
}

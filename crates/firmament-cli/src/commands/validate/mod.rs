//! `firmament validate`: the table method measured against the Monte Carlo reference.
//!
//! For each configuration (preset × observer altitude × sun elevation) a documented set of
//! view directions is traced by the reference path tracer (sky only, sun disk excluded:
//! the same quantity as `Sky::sky_radiance`) and evaluated with the precomputed tables; the
//! relative errors of luminance (Y) and of each wavelength's radiance are summarised by
//! their median, 95th percentile and maximum, next to the reference's own median relative
//! standard error, the signed median (bias), and the root mean square with and without the
//! reference's noise (√(⟨e²⟩ − ⟨σ²⟩): what remains is the table method's own error). See `docs/accuracy.md` for the set, the results and their analysis.
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

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use anyhow::{Context, Result};
use clap::Args;
use firmament::atmosphere::Model;
use firmament::math::sphere::ray_sphere;
use firmament::math::{direction_from_zenith_azimuth, Vec3};
use firmament::reference::{self, RadianceEstimate, ReferenceSettings};
use firmament::scene::Light;
use firmament::sky::bruneton4d::Bruneton4d;
use firmament::sky::{Shadow, SkyMethod};
use firmament::spectrum::ColourMatrix;
use rayon::prelude::*;
use serde_json::{json, Value};

use crate::common::{cancel_flag, check_output_dir, progress_bar, AtmosphereArgs};

/// Daylight thresholds of SPEC §7 (sun elevation ≥ 5°, `earth`): luminance error median and
/// 95th percentile.
const MEDIAN_LIMIT: f64 = 0.02;
const P95_LIMIT: f64 = 0.05;
/// Daylight: sun elevation at least this (degrees).
const DAYLIGHT_DEG: f64 = 5.0;
/// Pilot paths per wavelength for the adaptive sample count.
const PILOT: usize = 1024;

/// Arguments of `firmament validate`.
#[derive(Args, Debug)]
pub struct ValidateArgs {
    /// Presets to validate, comma-separated (default: earth,bruneton2008,hazy; --quick: earth).
    #[arg(long, value_name = "NAME,...")]
    pub preset: Option<String>,
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
    /// Scattering orders of the tables; a list `4,8` compares several against the same
    /// reference (the first is the one checked against the thresholds).
    #[arg(long, default_value = "4", value_name = "N,...")]
    pub orders: String,
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

/// A view: direction and its description.
#[derive(Clone, Copy, Debug)]
struct View {
    elevation_deg: f64,
    azimuth_from_sun_deg: f64,
    /// Angle from the sun's centre (degrees).
    sun_distance_deg: f64,
    dir: Vec3,
}

fn view_from_dir(dir: Vec3, sun: Vec3) -> View {
    let dir = dir.normalize_or_zero();
    let elevation = dir[2].clamp(-1.0, 1.0).asin().to_degrees();
    // Sun at azimuth 0 (north = +y, east = +x).
    let azimuth = dir[0].atan2(dir[1]).to_degrees().abs();
    View {
        elevation_deg: elevation,
        azimuth_from_sun_deg: if dir[0].hypot(dir[1]) < 1e-12 {
            0.0
        } else {
            azimuth
        },
        sun_distance_deg: dir.dot(sun).clamp(-1.0, 1.0).acos().to_degrees(),
        dir,
    }
}

fn dir_from(elevation_deg: f64, azimuth_deg: f64) -> Vec3 {
    direction_from_zenith_azimuth(
        (90.0 - elevation_deg).to_radians(),
        azimuth_deg.to_radians(),
    )
}

/// Elevation (degrees, negative) of the tangent to a sphere of `radius` seen from `r`.
fn dip_deg(r: f64, radius: f64) -> Option<f64> {
    (r > radius).then(|| -(radius / r).acos().to_degrees())
}

/// The documented view set (module documentation), or the reduced one of `--quick`.
fn views(model: &Model, altitude_m: f64, sun: Vec3, quick: bool) -> (Vec<View>, usize) {
    let r = model.bottom_radius_m + altitude_m;
    let camera = Vec3::new(0.0, 0.0, r);
    let mut dirs: Vec<Vec3> = Vec::new();
    let (above, azimuths, rings): (&[f64], &[f64], &[f64]) = if quick {
        (
            &[1.0, 3.0, 10.0, 30.0, 60.0],
            &[0.0, 60.0, 120.0, 180.0],
            &[3.0],
        )
    } else {
        (
            &[0.5, 1.0, 2.0, 4.0, 7.0, 10.0, 15.0, 25.0, 40.0, 60.0],
            &[0.0, 30.0, 60.0, 90.0, 135.0, 180.0],
            &[2.0, 4.0, 8.0],
        )
    };
    let mut elevations: Vec<f64> = above.to_vec();
    if altitude_m > 0.0 && quick {
        // Down towards the ground (the ground half of the tables), the horizon excluded.
        elevations.extend([-3.0, -30.0, -60.0]);
    }
    if altitude_m > 0.0 && !quick {
        let mut below = vec![-1.0, -3.0, -10.0, -30.0, -60.0];
        if let Some(g) = dip_deg(r, model.bottom_radius_m) {
            below.extend([g + 0.5, g + 0.1, g - 0.1, g - 0.5, g - 2.0]);
            if let Some(t) = dip_deg(r, model.top_radius_m) {
                below.push(t - 0.1);
                for f in [0.25, 0.5, 0.75] {
                    below.push(t + f * (g - t));
                }
            }
        }
        below.retain(|&e| e < 0.0 && e > -89.0);
        elevations.extend(below);
    }
    for &e in &elevations {
        for &a in azimuths {
            dirs.push(dir_from(e, a));
        }
    }
    dirs.push(Vec3::Z);
    if altitude_m > 0.0 && !quick {
        dirs.push(Vec3::NEG_Z);
    }
    // Rings around the sun: towards the zenith, sideways, towards the horizon.
    let e1 = {
        let v = Vec3::Z - Vec3::Z.dot(sun) * sun;
        if v.dot(v) < 1e-12 {
            Vec3::Y
        } else {
            v.normalize()
        }
    };
    let e2 = sun.cross(e1);
    for &d in rings {
        let (s, c) = d.to_radians().sin_cos();
        for phi in [0.0f64, 90.0, 180.0] {
            let (sp, cp) = phi.to_radians().sin_cos();
            dirs.push((c * sun + s * (cp * e1 + sp * e2)).normalize());
        }
    }
    let mut skipped = 0;
    let mut out: Vec<View> = Vec::new();
    for d in dirs {
        let v = view_from_dir(d, sun);
        // Sun disk excluded; at the ground only views above the horizon; rays that miss
        // the atmosphere carry no light.
        let misses = !matches!(ray_sphere(camera, v.dir, model.top_radius_m), Some((_, far)) if far > 0.0)
            || (r >= model.top_radius_m && camera.dot(v.dir) >= 0.0);
        if v.sun_distance_deg < 1.0 || (altitude_m <= 0.0 && v.elevation_deg < 0.25) || misses {
            skipped += 1;
            continue;
        }
        out.push(v);
    }
    (out, skipped)
}

/// Summary statistics of absolute relative errors.
#[derive(Clone, Debug, Default)]
struct Summary {
    median: f64,
    p95: f64,
    max: f64,
    /// Median of the signed relative errors (bias).
    signed_median: f64,
    /// Median relative standard error of the reference.
    ref_stderr_median: f64,
    /// Root mean square of the relative errors.
    rms: f64,
    /// The RMS with the reference's noise removed, √max(⟨e²⟩ − ⟨σ²⟩, 0): the error e of a
    /// view is the table's own error plus the reference's relative noise σ (independent,
    /// mean 0), so ⟨e²⟩ − ⟨σ²⟩ estimates the mean square of the table's own error.
    rms_noise_removed: f64,
    count: usize,
}

fn median(sorted: &[f64]) -> f64 {
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

fn summarise(errors: &[f64], ref_stderr: &[f64]) -> Summary {
    let mut abs: Vec<f64> = errors.iter().map(|e| e.abs()).collect();
    abs.sort_by(f64::total_cmp);
    let mut signed = errors.to_vec();
    signed.sort_by(f64::total_cmp);
    let mut se = ref_stderr.to_vec();
    se.sort_by(f64::total_cmp);
    let n = abs.len();
    let mean_sq = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>() / v.len().max(1) as f64;
    let (e2, s2) = (mean_sq(errors), mean_sq(ref_stderr));
    Summary {
        rms: e2.sqrt(),
        rms_noise_removed: (e2 - s2).max(0.0).sqrt(),
        median: median(&abs),
        p95: if n == 0 {
            f64::NAN
        } else {
            abs[((0.95 * n as f64).ceil() as usize).clamp(1, n) - 1]
        },
        max: abs.last().copied().unwrap_or(f64::NAN),
        signed_median: median(&signed),
        ref_stderr_median: median(&se),
        count: n,
    }
}

impl Summary {
    fn json(&self) -> Value {
        json!({
            "median": self.median,
            "p95": self.p95,
            "max": self.max,
            "signed_median": self.signed_median,
            "reference_median_relative_stderr": self.ref_stderr_median,
            "rms": self.rms,
            "rms_noise_removed": self.rms_noise_removed,
            "count": self.count,
        })
    }

    fn line(&self, label: &str) -> String {
        let pct = |v: f64| format!("{:6.2}%", 100.0 * v);
        format!(
            "  {label:>8}  med {} p95 {} max {}  (ref se {})  bias {:+.2}%  rms {} (noise removed {})",
            pct(self.median),
            pct(self.p95),
            pct(self.max),
            pct(self.ref_stderr_median),
            100.0 * self.signed_median,
            pct(self.rms).trim_start(),
            pct(self.rms_noise_removed).trim_start()
        )
    }
}

/// Per-view errors of one table configuration against the reference.
struct Errors {
    luminance: Vec<f64>,
    luminance_se: Vec<f64>,
    /// Per channel: (errors, reference relative stderr).
    channels: Vec<(Vec<f64>, Vec<f64>)>,
}

impl Errors {
    fn new(n: usize) -> Errors {
        Errors {
            luminance: Vec::new(),
            luminance_se: Vec::new(),
            channels: vec![(Vec::new(), Vec::new()); n],
        }
    }

    fn extend(&mut self, o: &Errors) {
        self.luminance.extend(&o.luminance);
        self.luminance_se.extend(&o.luminance_se);
        for (a, b) in self.channels.iter_mut().zip(&o.channels) {
            a.0.extend(&b.0);
            a.1.extend(&b.1);
        }
    }

    fn summaries(&self) -> (Summary, Vec<Summary>) {
        (
            summarise(&self.luminance, &self.luminance_se),
            self.channels.iter().map(|(e, s)| summarise(e, s)).collect(),
        )
    }
}

fn summary_json(errors: &Errors, nm: &[f64]) -> Value {
    let (y, ch) = errors.summaries();
    json!({
        "luminance": y.json(),
        "wavelengths": ch.iter().zip(nm).map(|(s, l)| {
            let mut v = s.json();
            v["wavelength_nm"] = json!(l);
            v
        }).collect::<Vec<_>>(),
    })
}

fn print_summary(errors: &Errors, nm: &[f64]) {
    let (y, ch) = errors.summaries();
    println!("{}", y.line("Y"));
    for (s, l) in ch.iter().zip(nm) {
        println!("{}", s.line(&format!("{l:.0} nm")));
    }
}

/// Reference estimate for one view: a pilot, then enough paths for the target (or a fixed
/// count). The same key keeps the pilot's paths in the final estimate.
fn reference_view(
    model: &Model,
    colour: &ColourMatrix,
    camera: Vec3,
    view: Vec3,
    sun: Vec3,
    plan: &SamplePlan,
    seed: u64,
    key: u64,
) -> RadianceEstimate {
    let settings = |samples| ReferenceSettings {
        samples,
        seed,
        ..Default::default()
    };
    if let SamplePlan::Fixed(n) = plan {
        return reference::sky_radiance_keyed(model, camera, view, sun, &settings(*n), key);
    }
    let SamplePlan::Adaptive { target, max } = *plan else {
        unreachable!()
    };
    let pilot = reference::sky_radiance_keyed(model, camera, view, sun, &settings(PILOT), key);
    let rel = relative_luminance_stderr(colour, &pilot);
    if !rel.is_finite() || rel <= target {
        return pilot;
    }
    let want = (PILOT as f64 * (rel / target).powi(2) * 1.1).ceil() as usize;
    let n = want.div_ceil(256) * 256;
    let n = n.clamp(PILOT, max.max(PILOT));
    if n == PILOT {
        return pilot;
    }
    reference::sky_radiance_keyed(model, camera, view, sun, &settings(n), key)
}

fn luminance_and_stderr(colour: &ColourMatrix, e: &RadianceEstimate) -> (f64, f64) {
    let n = e.radiance.len();
    let y = colour.to_xyz(&e.radiance)[1];
    let mut var = 0.0;
    let mut unit = vec![0.0; n];
    for k in 0..n {
        unit[k] = 1.0;
        var += (colour.to_xyz(&unit)[1] * e.stderr[k]).powi(2);
        unit[k] = 0.0;
    }
    (y, var.sqrt())
}

fn relative_luminance_stderr(colour: &ColourMatrix, e: &RadianceEstimate) -> f64 {
    let (y, se) = luminance_and_stderr(colour, e);
    if y > 0.0 {
        se / y
    } else {
        f64::INFINITY
    }
}

#[derive(Clone, Copy, Debug)]
enum SamplePlan {
    Fixed(usize),
    Adaptive { target: f64, max: usize },
}

/// Run `firmament validate`; prints the table and returns an error when the daylight
/// thresholds are broken (after writing the JSON).
pub fn run(args: &ValidateArgs) -> Result<()> {
    let started = Instant::now();
    if let Some(path) = &args.json {
        check_output_dir(path, "--json")?;
    }
    let presets: Vec<String> = match &args.preset {
        Some(p) => parse_list("--preset", p, "preset names separated by commas")?,
        None if args.quick => vec!["earth".into()],
        None => vec!["earth".into(), "bruneton2008".into(), "hazy".into()],
    };
    let altitudes: Vec<f64> = match &args.altitudes {
        Some(s) => parse_list("--altitudes", s, "altitudes in m separated by commas")?,
        None if args.quick => vec![0.0, 1000.0],
        None => vec![0.0, 1000.0, 10_000.0, 100_000.0],
    };
    for &a in &altitudes {
        crate::common::check_range("--altitudes", a, 0.0, 1e9, "m")?;
    }
    let mut elevations: Vec<f64> = match &args.sun_elevations {
        Some(s) => parse_list("--sun-elevations", s, "degrees separated by commas")?,
        None if args.quick => vec![30.0, 10.0],
        None => vec![90.0, 60.0, 30.0, 10.0, 5.0, 2.0, 0.0, -3.0, -6.0],
    };
    for &e in &elevations {
        crate::common::check_range("--sun-elevations", e, -90.0, 90.0, "degrees")?;
    }
    if args.daylight {
        elevations.retain(|&e| e >= DAYLIGHT_DEG);
        if elevations.is_empty() {
            anyhow::bail!("`--daylight` leaves no sun elevation ≥ {DAYLIGHT_DEG}°");
        }
    }
    let orders: Vec<usize> = parse_list("--orders", &args.orders, "integers separated by commas")?;
    let table_size = args
        .table_size
        .clone()
        .unwrap_or_else(|| if args.quick { "small" } else { "default" }.into());
    let plan = match args.samples {
        Some(n) if n < 2 => {
            anyhow::bail!("invalid value for `--samples`: {n} (accepted: an integer ≥ 2)")
        }
        Some(n) => SamplePlan::Fixed(n),
        None => {
            let pct = args
                .target_stderr
                .unwrap_or(if args.quick { 1.0 } else { 0.5 });
            crate::common::check_range("--target-stderr", pct, 0.01, 50.0, "percent")?;
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
    // Everything is checked (presets, orders, sizes) before the long work starts.
    let atmosphere_args = |preset: &str, orders: usize| AtmosphereArgs {
        preset: Some(preset.to_string()),
        atmosphere: None,
        wavelengths: args.wavelengths.clone(),
        tables: None,
        orders,
        table_size: table_size.clone(),
        mie: "separate".into(),
        order_tail: !args.no_order_tail,
    };
    for p in &presets {
        for &o in &orders {
            atmosphere_args(p, o).table_config()?;
        }
        atmosphere_args(p, orders[0]).model()?;
    }

    let cancel = cancel_flag();
    let mut configs_json = Vec::new();
    let mut nm: Vec<f64> = Vec::new();
    // Earth daylight aggregates, one per table configuration (orders).
    let mut daylight: Vec<Option<Errors>> = (0..orders.len()).map(|_| None).collect();
    let mut config_index = 0u64;
    println!(
        "firmament validate: table method vs Monte Carlo reference; relative errors over views \
         (sun disk excluded), reference's median relative standard error in brackets; tables \
         {table_size}, orders {:?}{}, reference {}",
        orders,
        if args.no_order_tail {
            " (no tail)"
        } else {
            " + geometric tail"
        },
        match plan {
            SamplePlan::Fixed(n) => format!("{n} paths/λ"),
            SamplePlan::Adaptive { target, max } => format!(
                "adaptive to {:.2}% luminance stderr ({PILOT}–{max} paths/λ)",
                100.0 * target
            ),
        }
    );
    for preset in &presets {
        let skies: Vec<Bruneton4d> = orders
            .iter()
            .map(|&o| {
                atmosphere_args(preset, o)
                    .sky(args.quiet)
                    .with_context(|| format!("tables for {preset}, {o} orders"))
            })
            .collect::<Result<_>>()?;
        let model = &skies[0].model;
        nm = model.wavelengths.nm().to_vec();
        let colour = ColourMatrix::new(&nm);
        let n_ch = nm.len();
        let configs: Vec<(f64, f64)> = altitudes
            .iter()
            .flat_map(|&a| elevations.iter().map(move |&e| (a, e)))
            .collect();
        let view_sets: Vec<(Vec<View>, usize)> = configs
            .iter()
            .map(|&(a, e)| views(model, a, dir_from(e, 0.0), args.quick))
            .collect();
        let total: usize = view_sets.iter().map(|v| v.0.len()).sum();
        let bar = progress_bar(total as u64, args.quiet);
        bar.set_message(format!("reference: {preset}"));
        for (&(altitude, elevation), (view_list, skipped)) in configs.iter().zip(&view_sets) {
            config_index += 1;
            let t0 = Instant::now();
            let sun = dir_from(elevation, 0.0);
            let camera = Vec3::new(0.0, 0.0, model.bottom_radius_m + altitude);
            let interrupted = AtomicBool::new(false);
            let estimates: Vec<Option<RadianceEstimate>> = view_list
                .par_iter()
                .enumerate()
                .map(|(i, v)| {
                    if cancel.load(Ordering::Relaxed) {
                        interrupted.store(true, Ordering::Relaxed);
                        return None;
                    }
                    let e = reference_view(
                        model,
                        &colour,
                        camera,
                        v.dir,
                        sun,
                        &plan,
                        args.seed,
                        (config_index << 16) | i as u64,
                    );
                    bar.inc(1);
                    Some(e)
                })
                .collect();
            if interrupted.load(Ordering::Relaxed) {
                bar.finish_and_clear();
                anyhow::bail!("interrupted");
            }
            let estimates: Vec<RadianceEstimate> = estimates.into_iter().flatten().collect();
            let ref_seconds = t0.elapsed().as_secs_f64();
            let mut per_orders = Vec::new();
            let mut views_json: Vec<Value> = Vec::new();
            let mut config_errors = Vec::new();
            for (oi, sky) in skies.iter().enumerate() {
                let mut errors = Errors::new(n_ch);
                let (mut l, mut t) = (vec![0.0; n_ch], vec![0.0; n_ch]);
                let light = Light::sun(model, sun, false);
                let view = sky.view(camera, &light);
                for (vi, (v, e)) in view_list.iter().zip(&estimates).enumerate() {
                    view.sky_radiance(v.dir, Shadow::None, &mut l, &mut t);
                    let (y_ref, y_se) = luminance_and_stderr(&colour, e);
                    let y_tab = colour.to_xyz(&l)[1];
                    let mut ch_err = vec![Value::Null; n_ch];
                    if y_ref > 0.0 {
                        errors.luminance.push(y_tab / y_ref - 1.0);
                        errors.luminance_se.push(y_se / y_ref);
                    }
                    for k in 0..n_ch {
                        if e.radiance[k] > 0.0 {
                            let err = l[k] / e.radiance[k] - 1.0;
                            errors.channels[k].0.push(err);
                            errors.channels[k].1.push(e.stderr[k] / e.radiance[k]);
                            ch_err[k] = json!(err);
                        }
                    }
                    if oi == 0 {
                        views_json.push(json!({
                            "elevation_deg": v.elevation_deg,
                            "azimuth_from_sun_deg": v.azimuth_from_sun_deg,
                            "sun_distance_deg": v.sun_distance_deg,
                            "reference": {
                                "radiance": e.radiance,
                                "stderr": e.stderr,
                                "samples": e.samples,
                                "luminance_cd_m2": y_ref,
                                "luminance_stderr": y_se,
                            },
                            "tables": [],
                        }));
                    }
                    views_json[vi]["tables"]
                        .as_array_mut()
                        .expect("array")
                        .push(json!({
                            "orders": orders[oi],
                            "radiance": l,
                            "luminance_cd_m2": y_tab,
                            "relative_error_luminance": if y_ref > 0.0 { json!(y_tab / y_ref - 1.0) } else { Value::Null },
                            "relative_error": ch_err,
                        }));
                }
                per_orders.push(json!({
                    "orders": orders[oi],
                    "summary": summary_json(&errors, &nm),
                }));
                config_errors.push(errors);
            }
            bar.suspend(|| {
                let samples: Vec<usize> = estimates.iter().map(|e| e.samples).collect();
                println!(
                    "{preset} altitude {altitude} m, sun elevation {elevation}°: {} views ({} skipped), {}–{} paths/λ, reference {:.1} s",
                    view_list.len(),
                    skipped,
                    samples.iter().min().unwrap_or(&0),
                    samples.iter().max().unwrap_or(&0),
                    ref_seconds
                );
                for (oi, errors) in config_errors.iter().enumerate() {
                    if orders.len() > 1 {
                        println!("  orders {}:", orders[oi]);
                    }
                    print_summary(errors, &nm);
                }
            });
            if preset == "earth" && elevation >= DAYLIGHT_DEG {
                for (agg, e) in daylight.iter_mut().zip(&config_errors) {
                    agg.get_or_insert_with(|| Errors::new(n_ch)).extend(e);
                }
            }
            configs_json.push(json!({
                "preset": preset,
                "altitude_m": altitude,
                "sun_elevation_deg": elevation,
                "views_skipped": skipped,
                "reference_seconds": ref_seconds,
                "tables": per_orders,
                "views": views_json,
            }));
        }
        bar.finish_and_clear();
    }

    let mut aggregates = Vec::new();
    let mut broken: Option<String> = None;
    for (oi, agg) in daylight.iter().enumerate() {
        let Some(agg) = agg else { continue };
        let (y, _) = agg.summaries();
        let pass = y.median <= MEDIAN_LIMIT && y.p95 <= P95_LIMIT;
        println!(
            "earth daylight (sun elevation ≥ {DAYLIGHT_DEG}°), all altitudes, orders {}: {} views{}",
            orders[oi],
            y.count,
            if pass { "" } else { "  THRESHOLDS BROKEN" }
        );
        print_summary(agg, &nm);
        if oi == 0 && !pass {
            broken = Some(format!(
                "earth daylight luminance error: median {:.2}% (limit {:.0}%), p95 {:.2}% (limit {:.0}%)",
                100.0 * y.median,
                100.0 * MEDIAN_LIMIT,
                100.0 * y.p95,
                100.0 * P95_LIMIT
            ));
        }
        aggregates.push(json!({
            "preset": "earth",
            "selection": format!("sun elevation >= {DAYLIGHT_DEG} deg, all altitudes of this run"),
            "orders": orders[oi],
            "summary": summary_json(agg, &nm),
            "pass": pass,
        }));
    }
    let elapsed = started.elapsed().as_secs_f64();
    println!("validate: {elapsed:.1} s");
    if let Some(path) = &args.json {
        let value = json!({
            "command": std::env::args().collect::<Vec<_>>(),
            "quick": args.quick,
            "presets": presets,
            "altitudes_m": altitudes,
            "sun_elevations_deg": elevations,
            "orders": orders,
            "order_tail": !args.no_order_tail,
            "table_size": table_size,
            "wavelengths_nm": nm,
            "seed": args.seed,
            "samples": match plan {
                SamplePlan::Fixed(n) => json!({ "fixed": n }),
                SamplePlan::Adaptive { target, max } => json!({
                    "adaptive_target_relative_stderr_luminance": target,
                    "pilot": PILOT,
                    "max": max,
                }),
            },
            "definitions": {
                "relative_error": "table / reference - 1, per view; summaries over views of |relative error|",
                "luminance": "CIE Y from the spectral samples (ColourMatrix), cd m-2",
                "views": "sky only (Sky::sky_radiance vs reference::sky_radiance, include_ground = false): in-scattered radiance, the sun disk seen directly excluded; views within 1 deg of the sun skipped; azimuths relative to the sun",
                "p95": "nearest-rank 95th percentile",
            },
            "thresholds": {
                "selection": "earth, sun elevation >= 5 deg",
                "median": MEDIAN_LIMIT,
                "p95": P95_LIMIT,
            },
            "aggregates": aggregates,
            "configurations": configs_json,
            "elapsed_s": elapsed,
            "threads": rayon::current_num_threads(),
        });
        write_json_atomic(path, &value)?;
        if !args.quiet {
            eprintln!("wrote {}", path.display());
        }
    }
    if let Some(msg) = broken {
        anyhow::bail!("daylight thresholds broken: {msg}");
    }
    Ok(())
}

/// Write JSON to a temporary file next to `path`, then rename it over `path`.
fn write_json_atomic(path: &std::path::Path, value: &Value) -> Result<()> {
    let mut tmp = path.as_os_str().to_owned();
    tmp.push(format!(".tmp{}", std::process::id()));
    let tmp = PathBuf::from(tmp);
    let text = serde_json::to_string_pretty(value)?;
    std::fs::write(&tmp, text).with_context(|| format!("writing {}", tmp.display()))?;
    std::fs::rename(&tmp, path).with_context(|| {
        let _ = std::fs::remove_file(&tmp);
        format!("renaming {} to {}", tmp.display(), path.display())
    })?;
    Ok(())
}

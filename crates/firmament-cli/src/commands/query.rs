//! `firmament query`: radiometric answers as one JSON object.

use anyhow::Result;
use clap::Args;
use firmament::astro::Sky;
use firmament::math::{direction_from_zenith_azimuth, Vec3};
use firmament::reference::{self, ReferenceSettings};
use firmament::scene::sky_lights::{sources_of, SkySources};
use firmament::scene::sun_direction;
use firmament::sky::bruneton4d as lut;
use firmament::sky::{Shadow, SkyView};
use firmament::spectrum::{xyz_to_linear_srgb, ColourMatrix};
use serde::Serialize;
use serde_json::json;

use super::provenance::provenance;

use crate::backend::{Backend, BackendChoice};
use crate::commands::astro::AstroArgs;
use crate::common::{check_range, check_reference_samples, print_wavelengths, AtmosphereArgs};
use crate::method::{CpuSky, Method};

/// Arguments of `firmament query`.
#[derive(Args, Debug, Clone)]
pub struct QueryArgs {
    #[command(flatten)]
    pub atmosphere: AtmosphereArgs,
    /// A scene file: the views are what its camera's observer sees, terrain included, with
    /// its atmosphere, sun and terrain (the camera's direction and image are not used).
    #[arg(long, value_name = "FILE", conflicts_with_all = ["altitude_m", "sun_zenith_deg", "sun_azimuth_deg", "time"])]
    pub scene: Option<std::path::PathBuf>,
    /// With --scene: its `[[clouds]]` left out (the terrain's accuracy measured without the
    /// clouds' lighting, which is measured on its own).
    #[arg(long)]
    pub no_clouds: bool,
    /// Observer altitude above the ground (m); above the atmosphere top is space.
    #[arg(long, allow_hyphen_values = true, required_unless_present = "scene")]
    pub altitude_m: Option<f64>,
    /// Sun zenith angle (degrees, 0–180; above 90 the sun is below the horizon); required
    /// unless --time is given.
    #[arg(long, allow_hyphen_values = true)]
    pub sun_zenith_deg: Option<f64>,
    #[arg(long, allow_hyphen_values = true, help = format!(
        "Sun azimuth (degrees clockwise from north) [default: {}, as `render`'s]",
        firmament::scene::file::SceneSun::default().azimuth_deg
    ))]
    pub sun_azimuth_deg: Option<f64>,
    /// A date and a place instead of the sun's angles (the moon and, at night, the night
    /// sky's glow then add to the views).
    #[command(flatten)]
    pub astro: AstroArgs,
    /// A view direction `ZENITH_DEG,AZIMUTH_DEG` (azimuth clockwise from north); repeatable.
    #[arg(
        long = "view",
        value_name = "ZENITH_DEG,AZIMUTH_DEG",
        allow_hyphen_values = true
    )]
    pub views: Vec<String>,
    /// Method for the views: `bruneton4d` (or `lut`: the precomputed 4D tables),
    /// `hillaire2020` (Hillaire 2020's tables and march) or `reference` (Monte Carlo path
    /// tracer; adds `radiance_stderr` and `samples` to each view).
    #[arg(long, value_enum, default_value_t = Method::Bruneton4d, value_name = "bruneton4d|lut|hillaire2020|elek3d|reference")]
    pub method: Method,
    #[command(flatten)]
    pub hillaire: crate::method::HillaireArgs,
    /// Paths per wavelength and view for `--method reference`.
    #[arg(long, default_value_t = 10_000)]
    pub samples: usize,
    /// Seed of the random streams for `--method reference`.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Where the tables are computed when no --tables are given: `cpu`, `gpu` (wgpu, any
    /// adapter; read back) or `auto` (a hardware GPU when wgpu finds one, else the CPU).
    /// The views themselves are a few table lookups and run on the CPU.
    #[arg(long, value_enum, value_name = "cpu|gpu|auto", default_value_t = BackendChoice::Auto)]
    pub backend: BackendChoice,
    /// Print nothing on stderr but errors (the JSON still goes to stdout).
    #[arg(long, short)]
    pub quiet: bool,
}

/// The answer for one `--view`; the last three only with `--method reference`.
#[derive(Serialize)]
pub(crate) struct ViewAnswer {
    zenith_deg: f64,
    azimuth_deg: f64,
    radiance: Vec<f64>,
    luminance_cd_m2: f64,
    xyz: [f64; 3],
    srgb_linear: [f64; 3],
    transmittance: Vec<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    radiance_stderr: Option<Vec<f64>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    luminance_cd_m2_stderr: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    samples: Option<usize>,
}

impl ViewAnswer {
    /// The answer for the view (zenith, azimuth) in degrees: its radiance per wavelength
    /// (`nm`) with luminance and colours, its transmittance, and the reference's estimate
    /// when there is one (whose radiance `radiance` already holds).
    pub(crate) fn new(
        (zenith_deg, azimuth_deg): (f64, f64),
        colour: &ColourMatrix,
        radiance: Vec<f64>,
        transmittance: Vec<f64>,
        estimate: Option<reference::RadianceEstimate>,
    ) -> ViewAnswer {
        let xyz = colour.to_xyz(&radiance);
        ViewAnswer {
            zenith_deg,
            azimuth_deg,
            luminance_cd_m2: xyz[1],
            xyz,
            srgb_linear: xyz_to_linear_srgb(xyz),
            radiance,
            transmittance,
            luminance_cd_m2_stderr: estimate
                .as_ref()
                .map(|e| colour.luminance_and_stderr(&e.radiance, &e.stderr).1),
            samples: estimate.as_ref().map(|e| e.samples),
            radiance_stderr: estimate.map(|e| e.stderr),
        }
    }
}

pub(crate) fn parse_view(s: &str) -> Result<(f64, f64)> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    let parsed: Vec<f64> = parts.iter().filter_map(|p| p.parse().ok()).collect();
    if parts.len() != 2 || parsed.len() != 2 {
        anyhow::bail!(
            "invalid value for `--view`: {s:?} (accepted: ZENITH_DEG,AZIMUTH_DEG, e.g. 45,180)"
        );
    }
    check_range("--view (zenith)", parsed[0], 0.0, 180.0, "degrees")?;
    check_range("--view (azimuth)", parsed[1], -360.0, 360.0, "degrees")?;
    Ok((parsed[0], parsed[1]))
}

/// The moon's place and light when --time is given (null without; `irradiance` null when
/// it is below the horizon and so not a light).
fn moon_json(
    sky_now: &Option<Sky>,
    views: &[Box<dyn SkyView + '_>],
    sources: &SkySources,
    camera: Vec3,
    colour: &ColourMatrix,
) -> serde_json::Value {
    let Some(s) = sky_now else {
        return serde_json::Value::Null;
    };
    let light = match (sources.lights.get(1), views.get(1)) {
        (Some(moon), Some(view)) => {
            let n = moon.irradiance.len();
            let (mut direct, mut diffuse) = (vec![0.0; n], vec![0.0; n]);
            let lux = |v: &[f64]| colour.to_xyz(v)[1];
            view.sun_and_sky_irradiance(camera, Vec3::Z, &mut direct, &mut diffuse);
            json!({
                "irradiance_toa": moon.irradiance,
                "illuminance_toa_lux": lux(&moon.irradiance),
                "direct_lux": lux(&direct),
                "sky_lux": lux(&diffuse),
            })
        }
        _ => serde_json::Value::Null,
    };
    json!({
        "zenith_deg": s.moon.zenith_deg,
        "apparent_zenith_deg": s.moon.apparent_zenith_deg,
        "azimuth_deg": s.moon.azimuth_deg,
        "illuminated_fraction": s.moon.illuminated_fraction,
        "phase_angle_deg": s.moon.phase_angle_deg,
        "light": light,
    })
}

/// Run the query and return the JSON.
pub fn run(args: &QueryArgs) -> Result<serde_json::Value> {
    let reference = match args.method {
        Method::Bruneton4d | Method::Hillaire2020 | Method::Elek3d => None,
        Method::Reference => {
            let settings = ReferenceSettings {
                samples: args.samples,
                seed: args.seed,
                ..Default::default()
            };
            // The flag's own wording; the other settings are the defaults.
            check_reference_samples(settings.samples)?;
            Some(settings)
        }
    };
    args.hillaire.check(&[args.method])?;
    let args = &QueryArgs {
        atmosphere: AtmosphereArgs {
            hillaire: args.hillaire,
            ..args.atmosphere.clone()
        },
        ..args.clone()
    };
    if args.scene.is_some() {
        return super::query_scene::run(args, reference);
    }
    if args.no_clouds {
        anyhow::bail!("--no-clouds leaves a scene's clouds out: it needs --scene FILE");
    }
    let altitude_m = args
        .altitude_m
        .expect("--altitude-m is required without --scene");
    check_range("--altitude-m", altitude_m, 0.0, 1e12, "m")?;
    let astro = args.astro.resolve()?;
    let (sun_zenith_deg, sun_azimuth_deg) = match (&astro, args.sun_zenith_deg) {
        (Some(_), _) => (f64::NAN, f64::NAN),
        (None, Some(z)) => (
            z,
            (args.sun_azimuth_deg)
                .unwrap_or(firmament::scene::file::SceneSun::default().azimuth_deg),
        ),
        (None, None) => anyhow::bail!("the sun's place is needed: --sun-zenith-deg (and --sun-azimuth-deg), or --time with --lat-deg/--lon-deg"),
    };
    if astro.is_none() {
        check_range("--sun-zenith-deg", sun_zenith_deg, 0.0, 180.0, "degrees")?;
        check_range(
            "--sun-azimuth-deg",
            sun_azimuth_deg,
            -360.0,
            360.0,
            "degrees",
        )?;
    }
    let views: Vec<(f64, f64)> = args
        .views
        .iter()
        .map(|v| parse_view(v))
        .collect::<Result<_>>()?;
    print_wavelengths(&args.atmosphere.model()?, args.quiet);
    let sky = match (&args.atmosphere.tables, args.method) {
        (_, m @ (Method::Hillaire2020 | Method::Elek3d)) => {
            if !args.quiet {
                eprintln!("backend: cpu ({} builds its tables on the CPU)", m.name());
            }
            args.atmosphere.cpu_sky(m, args.quiet)?
        }
        // Nothing to compute: no adapter to open.
        (Some(path), _) => {
            if !args.quiet {
                eprintln!(
                    "backend: cpu (tables read from {}; the views are CPU lookups)",
                    path.display()
                );
            }
            CpuSky::Bruneton4d(Box::new(args.atmosphere.sky(true)?))
        }
        (None, _) => CpuSky::Bruneton4d(Box::new(
            args.atmosphere
                .sky_on(&Backend::open(args.backend, args.quiet)?, args.quiet)?,
        )),
    };
    let model = sky.model();
    let nm = model.wavelengths.nm().to_vec();
    let n = nm.len();

    let camera = Vec3::new(0.0, 0.0, model.bottom_radius_m + altitude_m);
    let up = Vec3::Z;
    let sky_now = match astro {
        Some((instant, place, weather)) => Some(Sky::at(instant, place, &weather)?),
        None => None,
    };
    let sources = match &sky_now {
        Some(s) => sources_of(model, s, false, false),
        None => SkySources::sun(model, sun_direction(sun_zenith_deg, sun_azimuth_deg), false),
    };
    if reference.is_some() && (sources.lights.len() > 1 || sources.background.is_some()) {
        anyhow::bail!("`--method reference` traces the sun's light only so far: a --time with the moon up or the sun down is not supported with it");
    }
    let sun = sources.lights[0].direction;
    let (sun_zenith_deg, sun_azimuth_deg) = match &sky_now {
        Some(s) => (s.sun.apparent_zenith_deg, s.sun.azimuth_deg),
        None => (sun_zenith_deg, sun_azimuth_deg),
    };

    let optical_depths = model.optical_depths_vertical(altitude_m);
    let mut sun_transmittance = vec![0.0; n];
    let views_of_lights: Vec<_> = (sources.lights.iter())
        .map(|l| sky.method().view(camera, l))
        .collect();
    let sky_view = &views_of_lights[0];
    sky_view.transmittance_to_light(camera, &mut sun_transmittance);
    let (mut sun_irradiance, mut sky_irradiance) = (vec![0.0; n], vec![0.0; n]);
    sky_view.sun_and_sky_irradiance(camera, up, &mut sun_irradiance, &mut sky_irradiance);
    let colour = model.colour_matrix();
    let lux = |v: &[f64]| colour.to_xyz(v)[1];

    let mut answers = Vec::new();
    for (i, &(zenith_deg, azimuth_deg)) in views.iter().enumerate() {
        let dir = direction_from_zenith_azimuth(zenith_deg.to_radians(), azimuth_deg.to_radians());
        let (mut radiance, mut transmittance) = (vec![0.0; n], vec![0.0; n]);
        sky_view.sky_radiance(dir, Shadow::None, &mut radiance, &mut transmittance);
        // The other lights (the moon) and the night glow add to the sky.
        let mut other = vec![0.0; n];
        for view in &views_of_lights[1..] {
            view.sky_radiance(dir, Shadow::None, &mut other, &mut []);
            radiance.iter_mut().zip(&other).for_each(|(r, o)| *r += o);
        }
        if let Some(b) = &sources.background {
            let f = b.factor(camera, dir);
            for k in 0..n {
                radiance[k] += b.zenith_radiance[k] * f * transmittance[k];
            }
        }
        let estimate = reference.as_ref().map(|settings| {
            let e = reference::sky_radiance_keyed(model, camera, dir, sun, settings, i as u64);
            radiance.copy_from_slice(&e.radiance);
            e
        });
        answers.push(ViewAnswer::new(
            (zenith_deg, azimuth_deg),
            &colour,
            radiance,
            transmittance,
            estimate,
        ));
    }
    let mut notes = vec![
        json!("views: the sky's radiance without the sun's disk; a view into the ground gives the air's radiance between the observer and the ground, without the ground's own reflected light"),
        json!("irradiance: on a horizontal surface at the observer over the planet's smooth sphere (no terrain horizon): sun = the direct beam through the tables' transmittance times the cosine, sky = the tables' irradiance of the hemisphere above the surface, ground bounce included through the multiple scattering"),
        json!("sun_transmittance: along the straight ray to the sun (no refraction), with the planet's occlusion of the disk"),
    ];
    let method_notes = match &reference {
        None => json!([]),
        Some(s) => json!([
            format!(
                "views: spectral Monte Carlo reference path tracer, {} paths per wavelength and view, seed {} (view i uses stream key i); sky only: the sun disk seen directly and the ground's own radiance are excluded, as for `lut`",
                s.samples, s.seed
            ),
            "transmittance (per view), sun_transmittance, irradiance and optical depths: from the 4D tables and the model, as for `bruneton4d`",
        ]),
    };
    if let serde_json::Value::Array(m) = method_notes {
        notes.extend(m);
    }
    // What the tables approximate here (with `--method reference` the transmittance and
    // irradiance still come from them): a sun below their lowest, optically thick air.
    let mu_s = camera.normalize().dot(sun);
    if sky.bruneton4d().is_some() {
        notes.extend(lut::twilight::note(model.mu_s_min, mu_s).map(|s| json!(s)));
        notes.extend(lut::thickness::note(model).map(|s| json!(s)));
    }
    let method = match (&reference, args.method) {
        (Some(_), _) => {
            "reference (Monte Carlo path tracer) for the views, bruneton4d tables for the rest"
        }
        (None, Method::Hillaire2020) => {
            "hillaire2020 (transmittance, multiple-scattering and sky-view tables; ray march)"
        }
        (None, Method::Elek3d) => crate::method::ELEK3D_IN_WORDS,
        (None, _) => "bruneton4d (precomputed tables)",
    };
    Ok(json!({
        "method": args.method.name(),
        "wavelengths_nm": nm,
        "units": {
            "radiance": "W m-2 sr-1 nm-1",
            "irradiance": "W m-2 nm-1",
            "luminance": "cd m-2 (CIE 1931 2 deg, 683 lm/W; spectrum linearly interpolated between samples)",
        },
        "altitude_m": altitude_m,
        "sun": { "zenith_deg": sun_zenith_deg, "azimuth_deg": sun_azimuth_deg },
        "moon": moon_json(&sky_now, &views_of_lights, &sources, camera, &colour),
        "optical_depth_zenith": optical_depths,
        "solar_irradiance_toa": model.solar_irradiance,
        "solar_illuminance_toa_lux": lux(&model.solar_irradiance),
        "sun_transmittance": sun_transmittance,
        "irradiance": {
            "sun": sun_irradiance,
            "sky": sky_irradiance,
            "sun_lux": lux(&sun_irradiance),
            "sky_lux": lux(&sky_irradiance),
        },
        "views": answers,
        "notes": notes,
        "provenance": provenance(model, method, Some(sky.tables_json())),
    }))
}

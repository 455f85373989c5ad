//! `firmament render`'s flags and how they override the scene file, which overrides the
//! built-in default scene.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use firmament::render::ToneCurve;
use firmament::scene::file::{SceneLocation, SceneTime};
use firmament::scene::{Projection, SceneFile as Scene};

use crate::backend::BackendChoice;
use crate::commands::astro::AstroArgs;

/// Arguments of `firmament render`; flags override the scene file, which overrides the
/// built-in default scene.
#[derive(Args, Debug)]
pub struct RenderArgs {
    /// Scene file (TOML; see scenes/ for examples).
    #[arg(long, value_name = "FILE")]
    pub scene: Option<PathBuf>,
    /// Camera: perspective, fisheye, equirect, cubemap, orbit.
    #[arg(long)]
    pub camera: Option<String>,
    /// Image width (pixels).
    #[arg(long)]
    pub width: Option<usize>,
    /// Image height (pixels).
    #[arg(long)]
    pub height: Option<usize>,
    /// Camera altitude above the ground (m).
    #[arg(long, allow_hyphen_values = true)]
    pub altitude_m: Option<f64>,
    /// View heading (degrees clockwise from north).
    #[arg(long, allow_hyphen_values = true)]
    pub heading_deg: Option<f64>,
    /// View pitch (degrees above the horizon).
    #[arg(long, allow_hyphen_values = true)]
    pub pitch_deg: Option<f64>,
    /// Camera roll (degrees).
    #[arg(long, allow_hyphen_values = true)]
    pub roll_deg: Option<f64>,
    /// Vertical field of view (degrees).
    #[arg(long)]
    pub fov_deg: Option<f64>,
    /// Sun zenith angle (degrees; > 90 below the horizon).
    #[arg(long, allow_hyphen_values = true)]
    pub sun_zenith_deg: Option<f64>,
    /// Sun azimuth (degrees clockwise from north).
    #[arg(long, allow_hyphen_values = true)]
    pub sun_azimuth_deg: Option<f64>,
    /// Do not draw the solar disk.
    #[arg(long)]
    pub no_sun_disk: bool,
    /// A date and a place instead of the sun's angles.
    #[command(flatten)]
    pub astro: AstroArgs,
    /// Do not draw the moon's disk (its light stays).
    #[arg(long)]
    pub no_moon_disk: bool,
    /// No terrain: the planet's smooth sphere (the default scene has mountains).
    #[arg(long)]
    pub no_terrain: bool,
    /// No light shafts: the terrain's shadows stay on the ground, the air is lit throughout.
    #[arg(long)]
    pub no_light_shafts: bool,
    /// Without the terrain's change of the air's light: the tables' multiply scattered
    /// light as over a smooth planet (about 1 s faster a 1080p frame, less accurate).
    #[arg(long)]
    pub no_air_light: bool,
    /// A time-lapse: frames from --time to this instant (ISO 8601), every --every; each
    /// --out needs a frame number (`frames/sky_%04d.exr`).
    #[arg(long, value_name = "ISO8601", requires_all = ["time", "every"])]
    pub until: Option<String>,
    /// The time-lapse's step: `30s`, `10m`, `1h`, `1d`.
    #[arg(long, value_name = "STEP", requires = "until")]
    pub every: Option<String>,
    /// Skip the time-lapse's frames whose every output file exists (resume a stopped run).
    #[arg(long, requires = "until")]
    pub resume: bool,
    /// Embedded preset.
    #[arg(long, conflicts_with = "atmosphere")]
    pub preset: Option<String>,
    /// Atmosphere TOML file.
    #[arg(long, value_name = "FILE")]
    pub atmosphere: Option<PathBuf>,
    /// Wavelengths: rgb, spectral or NM,NM,...
    #[arg(long)]
    pub wavelengths: Option<String>,
    /// Precomputed tables from `firmament bake`.
    #[arg(long, value_name = "FILE")]
    pub tables: Option<PathBuf>,
    /// Table sizes when computing: default or small.
    #[arg(long, default_value = "default")]
    pub table_size: String,
    /// Exposure value at ISO 100 (PNG only); automatic when absent.
    #[arg(long, allow_hyphen_values = true)]
    pub ev100: Option<f64>,
    /// Automatic exposure from the log-average luminance (overrides the scene's ev100).
    #[arg(long)]
    pub auto_exposure: bool,
    /// Tone curve for PNG: aces (default), filmic, clamp.
    #[arg(long)]
    pub tonemap: Option<String>,
    /// White-balance to the sun's colour.
    #[arg(long)]
    pub white_balance: bool,
    /// Write OpenEXR as 16-bit half floats instead of 32-bit (values above the half range,
    /// 65 504, such as the sun's disk, are clamped there, with a warning).
    #[arg(long)]
    pub exr_half: bool,
    /// The colour space of OpenEXR output: rec709 (default; sRGB's primaries), rec2020 or
    /// acescg, named in the file's `chromaticities`. Colours outside it are mapped into it
    /// at their luminance: no file holds a negative component.
    #[arg(long, default_value = "rec709", value_name = "rec709|rec2020|acescg")]
    pub gamut: String,
    /// Round PNG output to the nearest code instead of dithering (triangular, ±1 code).
    #[arg(long)]
    pub no_dither: bool,
    /// Output file, repeatable; format from the extension (.png, .exr, .hdr).
    #[arg(long = "out", value_name = "FILE")]
    pub outputs: Vec<PathBuf>,
    /// Print nothing but errors.
    #[arg(long, short)]
    pub quiet: bool,
    /// Method: `lut` (precomputed tables, fast) or `reference` (Monte Carlo path tracer:
    /// a ground-truth image of the same scene, no tables).
    #[arg(long, default_value = "lut", value_name = "lut|reference")]
    pub method: String,
    /// Paths per wavelength and pixel for `--method reference`.
    #[arg(long, default_value_t = 1024)]
    pub samples: usize,
    /// Where tables are precomputed and frames rendered (`--method lut`): `cpu`, `gpu`
    /// (wgpu, any adapter; with --tables the file's tables are uploaded) or `auto` (a
    /// hardware GPU when wgpu finds one, else the CPU; never a software rasteriser such as
    /// lavapipe). `--method reference` runs on the CPU only.
    #[arg(long, value_enum, value_name = "cpu|gpu|auto", default_value_t = BackendChoice::Auto)]
    pub backend: BackendChoice,
}

fn parse_projection(s: &str) -> Result<Projection> {
    Ok(match s {
        "perspective" => Projection::Perspective,
        "fisheye" => Projection::Fisheye,
        "equirect" => Projection::Equirect,
        "cubemap" => Projection::Cubemap,
        "orbit" => Projection::Orbit,
        _ => anyhow::bail!("invalid value for `--camera`: {s} (accepted: perspective, fisheye, equirect, cubemap, orbit)"),
    })
}

/// The scene after applying flags.
pub fn scene_from_args(args: &RenderArgs) -> Result<Scene> {
    let mut scene = match &args.scene {
        Some(path) => Scene::from_file(path)?,
        None => Scene::default(),
    };
    if let Some(c) = &args.camera {
        scene.camera.projection = parse_projection(c)?;
        // Sensible shapes for the all-round projections unless sizes are given.
        if args.scene.is_none() {
            match scene.camera.projection {
                Projection::Fisheye => (scene.image.width, scene.image.height) = (1024, 1024),
                Projection::Equirect => (scene.image.width, scene.image.height) = (2048, 1024),
                Projection::Cubemap => (scene.image.width, scene.image.height) = (3072, 512),
                Projection::Orbit => {
                    (scene.image.width, scene.image.height) = (1024, 1024);
                    scene.camera.altitude_m = 20_000_000.0;
                }
                Projection::Perspective => {}
            }
        }
    }
    macro_rules! set {
        ($flag:expr, $field:expr) => {
            if let Some(v) = $flag {
                $field = v;
            }
        };
    }
    set!(args.width, scene.image.width);
    set!(args.height, scene.image.height);
    if args.width.is_some()
        && args.height.is_none()
        && scene.camera.projection == Projection::Cubemap
    {
        scene.image.height = scene.image.width / 6;
    }
    set!(args.altitude_m, scene.camera.altitude_m);
    set!(args.heading_deg, scene.camera.heading_deg);
    set!(args.pitch_deg, scene.camera.pitch_deg);
    set!(args.roll_deg, scene.camera.roll_deg);
    set!(args.fov_deg, scene.camera.fov_deg);
    if scene.camera.projection == Projection::Orbit
        && args.fov_deg.is_none()
        && args.scene.is_none()
    {
        scene.camera.fov_deg = firmament::scene::camera::orbit_fit_fov_deg(
            6_360_000.0 * 1.01,
            6_360_000.0 + scene.camera.altitude_m,
        );
    }
    if scene.time.is_some() && (args.sun_zenith_deg.is_some() || args.sun_azimuth_deg.is_some()) {
        anyhow::bail!(
            "--sun-zenith-deg/--sun-azimuth-deg cannot be used with the scene file's [time]: the sun follows from the date (use --time to change it)"
        );
    }
    set!(args.sun_zenith_deg, scene.sun.zenith_deg);
    set!(args.sun_azimuth_deg, scene.sun.azimuth_deg);
    if args.no_sun_disk {
        scene.sun.disk = false;
    }
    if let Some((instant, place, weather)) = args.astro.resolve()? {
        scene.time = Some(SceneTime {
            at: instant.utc.to_rfc3339(),
            moon_disk: true,
        });
        scene.location = Some(SceneLocation {
            lat_deg: place.lat_deg,
            lon_deg: place.lon_deg,
            elevation_m: place.elevation_m,
            pressure_hpa: weather.pressure_hpa,
            temperature_c: weather.temperature_c,
        });
    }
    if args.no_moon_disk {
        if let Some(t) = &mut scene.time {
            t.moon_disk = false;
        }
    }
    if let Some(p) = &args.preset {
        scene.atmosphere.preset = p.clone();
        scene.atmosphere.file = None;
    }
    if let Some(f) = &args.atmosphere {
        scene.atmosphere.file = Some(f.clone());
    }
    if let Some(w) = &args.wavelengths {
        scene.atmosphere.wavelengths = w.clone();
    }
    if let Some(ev) = args.ev100 {
        scene.output.ev100 = Some(ev);
    }
    if args.auto_exposure {
        scene.output.ev100 = None;
    }
    if let Some(t) = &args.tonemap {
        scene.output.tonemap = ToneCurve::parse(t).map_err(|_| {
            anyhow::anyhow!("invalid value for `--tonemap`: {t} (accepted: aces, filmic, clamp)")
        })?;
    }
    if args.white_balance {
        scene.output.white_balance = true;
    }
    if !args.outputs.is_empty() {
        scene.output.files = args.outputs.clone();
    }
    if args.no_terrain {
        scene.terrain = None;
    }
    if let Some(t) = &mut scene.terrain {
        t.light_shafts &= !args.no_light_shafts;
        t.air_light &= !args.no_air_light;
    }
    scene.validate()?;
    Ok(scene)
}

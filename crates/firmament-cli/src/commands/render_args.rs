//! `firmament render`'s flags and how they override the scene file, which overrides the
//! built-in default scene.

use crate::method::Method;
use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use firmament::render::ToneCurve;
use firmament::scene::file::{SceneLocation, SceneTime};
use firmament::scene::{Projection, SceneFile as Scene};

use crate::backend::BackendChoice;
use crate::commands::astro::AstroArgs;
use crate::common::OrderArgs;

/// Arguments of `firmament render`; flags override the scene file, which overrides the
/// built-in default scene.
#[derive(Args, Debug)]
pub struct RenderArgs {
    /// Scene file (TOML; see scenes/ for examples).
    #[arg(long, value_name = "FILE")]
    pub scene: Option<PathBuf>,
    // The help texts name the defaults of the built-in scene (`defaults()`), so that they
    // are defined once, in `SceneFile::default`.
    #[arg(long, value_name = "perspective|fisheye|equirect|cubemap|orbit", help = camera_help())]
    pub camera: Option<String>,
    #[arg(long, allow_hyphen_values = true, value_parser = pixels, help = size_help("width"))]
    pub width: Option<usize>,
    #[arg(long, allow_hyphen_values = true, value_parser = pixels, help = size_help("height"))]
    pub height: Option<usize>,
    /// A cube map's face edge (pixels): the map is 6·SIZE × SIZE.
    #[arg(long, allow_hyphen_values = true, value_parser = pixels, conflicts_with_all = ["width", "height"])]
    pub size: Option<usize>,
    #[arg(long, allow_hyphen_values = true, help = with_default(
        "Camera altitude above the ground, or above the terrain below the camera (m)",
        defaults().camera.altitude_m,
    ))]
    pub altitude_m: Option<f64>,
    #[arg(long, allow_hyphen_values = true, help = with_default(
        "View heading (degrees clockwise from north); an equirect map's centre column and a fisheye's top face it (north by default for them)",
        defaults().camera.heading_deg,
    ))]
    pub heading_deg: Option<f64>,
    #[arg(long, allow_hyphen_values = true, help = with_default(
        "View pitch (degrees above the horizon; perspective only)",
        defaults().camera.pitch_deg,
    ))]
    pub pitch_deg: Option<f64>,
    #[arg(long, allow_hyphen_values = true, help = with_default(
        "Camera roll (degrees, clockwise; perspective and orbit)",
        defaults().camera.roll_deg,
    ))]
    pub roll_deg: Option<f64>,
    #[arg(long, help = with_default(
        "Vertical field of view (degrees; perspective, and orbit where it fits the planet by default)",
        defaults().camera.fov_deg,
    ))]
    pub fov_deg: Option<f64>,
    #[arg(long, allow_hyphen_values = true, help = with_default(
        "Sun zenith angle (degrees; > 90 below the horizon)",
        defaults().sun.zenith_deg,
    ))]
    pub sun_zenith_deg: Option<f64>,
    #[arg(long, allow_hyphen_values = true, help = with_default(
        "Sun azimuth (degrees clockwise from north)",
        defaults().sun.azimuth_deg,
    ))]
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
    /// No clouds: the scene's `[[clouds]]` left out (the default scene has a few cumulus).
    #[arg(long)]
    pub no_clouds: bool,
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
    #[arg(long, conflicts_with = "atmosphere", help = with_default(
        "Embedded preset: earth, bruneton2008, frostbite2016, hazy, mars",
        defaults().atmosphere.preset,
    ))]
    pub preset: Option<String>,
    /// Atmosphere TOML file.
    #[arg(long, value_name = "FILE")]
    pub atmosphere: Option<PathBuf>,
    #[arg(long, value_name = "spectral|rgb|NM,NM,...", help = with_default(
        "Wavelengths: `spectral` (16 samples 365–815 nm), `rgb` (680, 550, 440 nm: fast, a sunset lavender and 5–16 % too bright) or NM,NM,...; with --tables and none given, the file's",
        firmament::scene::file::DEFAULT_WAVELENGTHS,
    ))]
    pub wavelengths: Option<String>,
    /// Changes to the atmosphere (over the scene's `[atmosphere.adjust]`, field by field).
    #[command(flatten)]
    pub adjust: crate::common::AdjustArgs,
    /// Precomputed tables from `firmament bake`.
    #[arg(long, value_name = "FILE")]
    pub tables: Option<PathBuf>,
    /// Neither read nor write the table cache (`$FIRMAMENT_CACHE_DIR`, else
    /// `$XDG_CACHE_HOME/firmament` or `~/.cache/firmament`): compute the tables and keep
    /// nothing.
    #[arg(long, conflicts_with = "tables")]
    pub no_cache: bool,
    /// Table sizes when computing: default or small.
    #[arg(long, default_value = "default", value_name = "default|small")]
    pub table_size: String,
    /// Scattering orders and their tail when computing (as `bake` and `query`).
    #[command(flatten)]
    pub order_args: OrderArgs,
    /// Exposure value at ISO 100 (PNG only) [default: automatic, as a camera's meter].
    #[arg(long, allow_hyphen_values = true, conflicts_with = "auto_exposure")]
    pub ev100: Option<f64>,
    /// Automatic exposure from the log-average luminance (overrides the scene's ev100).
    #[arg(long)]
    pub auto_exposure: bool,
    /// Tone curve for PNG: aces, filmic, clamp [default: the scene's, aces].
    #[arg(long, value_name = "aces|filmic|clamp")]
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
    /// A cube map's faces in the files: `firmament` (its own 6×1 strip, +Z up: +X east,
    /// −X west, +Y north, −Y south, +Z up, −Z down), `y-up` (the graphics APIs' faces
    /// +X −X +Y −Y +Z −Z in a 6×1 strip, +Y up, north on +Z), `cross` (those faces in a
    /// 4×3 horizontal cross) or `unreal` (the standard faces in Unreal's axes: +X north,
    /// +Y east, +Z up). A .dds or .ktx2 file holds the standard faces (y-up, or unreal's). See
    /// docs/conventions.md [default: firmament].
    #[arg(long, value_name = "firmament|y-up|cross|unreal")]
    pub layout: Option<String>,
    /// Round PNG output to the nearest code instead of dithering (triangular, ±1 code).
    #[arg(long)]
    pub no_dither: bool,
    #[arg(long = "out", value_name = "FILE", help = with_default(
        "Output file, repeatable; format from the extension (.png, .exr, .hdr; .dds and .ktx2 for cube maps)",
        defaults().output.files.iter().map(|f| f.display().to_string()).collect::<Vec<_>>().join(" and "),
    ))]
    pub outputs: Vec<PathBuf>,
    /// Print nothing but errors.
    #[arg(long, short)]
    pub quiet: bool,
    /// Method: `bruneton4d` (or `lut`: the precomputed 4D tables), `hillaire2020`
    /// (Hillaire 2020's small tables and ray march: fast to build; the terrain on the CPU
    /// only), `elek3d` (Frostbite's 3D table; the terrain on the CPU only) or `reference` (Monte Carlo
    /// path tracer: a ground-truth image of the same scene, no tables).
    #[arg(long, value_enum, default_value_t = Method::Bruneton4d, value_name = "bruneton4d|lut|hillaire2020|elek3d|reference")]
    pub method: Method,
    #[command(flatten)]
    pub hillaire: crate::method::HillaireArgs,
    /// Surfaces' aerial perspective from a camera-aligned froxel volume (32×32×32 over
    /// 32 km, Hillaire 2020 §5.4) per light instead of per pixel: faster with
    /// `--method hillaire2020`, within 0.5 % mean (docs/accuracy.md); rays with light
    /// shafts stay per pixel. CPU only so far.
    #[arg(long)]
    pub aerial_volume: bool,
    /// Paths per wavelength and pixel for `--method reference`.
    #[arg(long, default_value_t = 1024)]
    pub samples: usize,
    /// Where tables are precomputed and frames rendered (`--method bruneton4d`): `cpu`, `gpu`
    /// (wgpu, any adapter; with --tables the file's tables are uploaded) or `auto` (a
    /// hardware GPU when wgpu finds one, else the CPU; never a software rasteriser such as
    /// lavapipe). `--method reference` runs on the CPU only.
    #[arg(long, value_enum, value_name = "cpu|gpu|auto", default_value_t = BackendChoice::Auto)]
    pub backend: BackendChoice,
}

/// The built-in scene, whose values are the defaults of the flags.
fn defaults() -> Scene {
    Scene::default()
}

/// `text [default: value]`, as clap writes its own defaults.
fn with_default(text: &str, value: impl std::fmt::Display) -> String {
    format!("{text} [default: {value}]")
}

fn camera_help() -> String {
    with_default(
        "Camera: perspective, fisheye, equirect, cubemap, orbit",
        format!("{:?}", defaults().camera.projection).to_lowercase(),
    )
}

fn size_help(which: &str) -> String {
    let d = defaults();
    let v = if which == "width" {
        d.image.width
    } else {
        d.image.height
    };
    let all_round = [
        (Projection::Fisheye, "fisheye"),
        (Projection::Equirect, "equirect"),
        (Projection::Cubemap, "cubemap"),
        (Projection::Orbit, "orbit"),
    ]
    .iter()
    .map(|&(p, name)| {
        let (w, h) = default_size(p);
        format!("{name} {}", if which == "width" { w } else { h })
    })
    .collect::<Vec<_>>()
    .join(", ");
    format!(
        "Image {which} (pixels, 1 to 32768); given alone it keeps the image's aspect (an equirect map is 2:1 and a cube map 6:1) [default: {v}; {all_round}]"
    )
}

/// The image size a projection chosen by `--camera` gets without sizes.
fn default_size(p: Projection) -> (usize, usize) {
    match p {
        Projection::Fisheye | Projection::Orbit => (1024, 1024),
        Projection::Equirect => (2048, 1024),
        Projection::Cubemap => (3072, 512),
        Projection::Perspective => {
            let d = defaults();
            (d.image.width, d.image.height)
        }
    }
}

/// A `--width`/`--height`/`--size` value: our message for anything but a positive integer
/// (clap's for `-5` would be "unexpected argument").
fn pixels(s: &str) -> std::result::Result<usize, String> {
    match s.trim().parse::<i64>() {
        Ok(v) if (1..=32768).contains(&v) => Ok(v as usize),
        _ => Err("an image size in pixels, an integer in [1, 32768]".into()),
    }
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

/// Refuse the camera flags that `projection` would ignore: the all-round maps have no
/// pitch, roll or field of view (an equirect map's and a fisheye's heading turns them),
/// a cube map's faces face the world's axes, an orbit camera looks straight down.
fn refuse_ignored_flags(args: &RenderArgs, projection: Projection) -> Result<()> {
    let name = format!("{projection:?}").to_lowercase();
    if args.layout.is_some() && projection != Projection::Cubemap {
        anyhow::bail!(
            "--layout arranges a cube map's faces; the {name} camera has none (--camera cubemap)"
        );
    }
    if args.size.is_some() && projection != Projection::Cubemap {
        anyhow::bail!(
            "--size is a cube map's face edge; the {name} camera takes --width and --height"
        );
    }
    let given = [
        ("--heading-deg", args.heading_deg.is_some()),
        ("--pitch-deg", args.pitch_deg.is_some()),
        ("--roll-deg", args.roll_deg.is_some()),
        ("--fov-deg", args.fov_deg.is_some()),
    ];
    let (ignored, why): (&[&str], &str) = match projection {
        Projection::Perspective => (&[], ""),
        Projection::Fisheye | Projection::Equirect => (
            &["--pitch-deg", "--roll-deg", "--fov-deg"],
            "it sees the whole sky, level; --heading-deg turns it",
        ),
        Projection::Cubemap => (
            &["--heading-deg", "--pitch-deg", "--roll-deg", "--fov-deg"],
            "its faces face the world's axes; --layout arranges them",
        ),
        Projection::Orbit => (
            &["--pitch-deg"],
            "it looks straight down at the planet; --heading-deg turns it",
        ),
    };
    match given
        .iter()
        .find(|(flag, set)| *set && ignored.contains(flag))
    {
        Some((flag, _)) => anyhow::bail!("{flag} does not apply to the {name} camera: {why}"),
        None => Ok(()),
    }
}

/// The image size from --width, --height and --size: an equirect map is 2:1 and a cube
/// map 6:1, so one size gives the other and two that disagree are refused.
fn set_size(args: &RenderArgs, scene: &mut Scene) -> Result<()> {
    let ratio = match scene.camera.projection {
        Projection::Equirect => Some((2, "an equirect map is 2:1")),
        Projection::Cubemap => Some((6, "a cube map is six square faces side by side, 6:1")),
        _ => None,
    };
    let (width, height) = match (args.size, ratio) {
        (Some(s), Some((k, _))) => (Some(k * s), Some(s)),
        _ => (args.width, args.height),
    };
    match (width, height, ratio) {
        (Some(w), Some(h), Some((k, why))) if w != k * h => anyhow::bail!(
            "--width {w} and --height {h} disagree: {why} (--width {} or --height {}, or give one of them)",
            k * h,
            w / k
        ),
        (Some(w), None, Some((k, why))) => {
            if w % k != 0 {
                anyhow::bail!("--width {w} is not a multiple of {k}: {why}");
            }
            (scene.image.width, scene.image.height) = (w, w / k);
        }
        (None, Some(h), Some((k, _))) => (scene.image.width, scene.image.height) = (k * h, h),
        // One size alone keeps the image's aspect (a 1920×1080 view asked 480 wide is
        // 480×270, not 480×1080).
        (Some(w), None, None) => {
            let h = w as f64 * scene.image.height as f64 / scene.image.width as f64;
            (scene.image.width, scene.image.height) = (w, (h.round() as usize).max(1));
        }
        (None, Some(h), None) => {
            let w = h as f64 * scene.image.width as f64 / scene.image.height as f64;
            (scene.image.width, scene.image.height) = ((w.round() as usize).max(1), h);
        }
        _ => {
            if let Some(w) = width {
                scene.image.width = w;
            }
            if let Some(h) = height {
                scene.image.height = h;
            }
        }
    }
    Ok(())
}

/// The scene after applying flags.
pub fn scene_from_args(args: &RenderArgs) -> Result<Scene> {
    let mut scene = match &args.scene {
        Some(path) => Scene::from_file(path)?,
        None => Scene::default(),
    };
    if let Some(c) = &args.camera {
        scene.camera.projection = parse_projection(c)?;
        // The default scene's framing is a perspective view's: another projection from it
        // starts level, facing north, at its own size.
        if args.scene.is_none() {
            let p = scene.camera.projection;
            (scene.image.width, scene.image.height) = default_size(p);
            if p != Projection::Perspective {
                (scene.camera.heading_deg, scene.camera.pitch_deg) = (0.0, 0.0);
                scene.camera.roll_deg = 0.0;
            }
            if p == Projection::Orbit {
                scene.camera.altitude_m = 20_000_000.0;
            }
        }
    }
    let projection = scene.camera.projection;
    refuse_ignored_flags(args, projection)?;
    macro_rules! set {
        ($flag:expr, $field:expr) => {
            if let Some(v) = $flag {
                $field = v;
            }
        };
    }
    set_size(args, &mut scene)?;
    set!(args.altitude_m, scene.camera.altitude_m);
    set!(args.heading_deg, scene.camera.heading_deg);
    set!(args.pitch_deg, scene.camera.pitch_deg);
    set!(args.roll_deg, scene.camera.roll_deg);
    set!(args.fov_deg, scene.camera.fov_deg);
    if projection == Projection::Orbit && args.fov_deg.is_none() && args.scene.is_none() {
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
        scene.atmosphere.wavelengths = Some(w.clone());
    }
    // The flags given override the scene's adjustments one by one.
    let flags = args.adjust.adjustments();
    let a = &mut scene.atmosphere.adjust;
    for (flag, field) in [
        (flags.aerosol_optical_depth, &mut a.aerosol_optical_depth),
        (flags.ozone_du, &mut a.ozone_du),
        (flags.rayleigh_scale, &mut a.rayleigh_scale),
        (flags.ground_albedo, &mut a.ground_albedo),
        (flags.planet_radius_m, &mut a.planet_radius_m),
    ] {
        if flag.is_some() {
            *field = flag;
        }
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
    if args.no_clouds {
        scene.clouds.clear();
    }
    if let Some(t) = &mut scene.terrain {
        t.light_shafts &= !args.no_light_shafts;
        t.air_light &= !args.no_air_light;
    }
    scene.validate()?;
    Ok(scene)
}

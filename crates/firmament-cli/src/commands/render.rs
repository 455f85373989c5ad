//! `firmament render`: pictures of the sky from flags or a scene file.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, Result};
use clap::Args;
use firmament::atmosphere::Model;
use firmament::io::{self, ExrPrecision, OutputFormat};
use firmament::reference::{self, ReferenceSettings};
use firmament::render::{self, tonemap, RenderSettings, ToneCurve};
use firmament::scene::file::{SceneLocation, SceneTime};
use firmament::scene::sky_lights::{sources_of, SkySources};
use firmament::scene::terrain::Heightfield;
use firmament::scene::{sun_direction, Projection, SceneFile as Scene};
use firmament::spectrum::gamut::Gamut;

use crate::backend::{Backend, BackendChoice, RenderSky};
use crate::commands::astro::AstroArgs;
use crate::commands::timelapse;
use crate::common::{
    cancel_flag, check_output_dir, check_reference_samples, print_wavelengths, progress_bar,
    AtmosphereArgs,
};

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
    /// Wavelengths: `spectral` (16 samples 365–815 nm, the default: right colours and
    /// luminance), `rgb` (680, 550, 440 nm: fast, a sunset mauve) or `NM,NM,...`. With
    /// --tables: the file's.
    #[arg(long, value_name = "spectral|rgb|NM,NM,...")]
    pub wavelengths: Option<String>,
    /// Precomputed tables from `firmament bake`.
    #[arg(long, value_name = "FILE")]
    pub tables: Option<PathBuf>,
    /// Neither read nor write the table cache (`$FIRMAMENT_CACHE_DIR`, else
    /// `$XDG_CACHE_HOME/firmament` or `~/.cache/firmament`): compute the tables and keep
    /// nothing.
    #[arg(long, conflicts_with = "tables")]
    pub no_cache: bool,
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
fn scene_from_args(args: &RenderArgs) -> Result<Scene> {
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
        scene.atmosphere.wavelengths = Some(w.clone());
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

/// Atmosphere arguments equivalent to the scene's.
pub fn atmosphere_args(
    scene: &Scene,
    tables: Option<PathBuf>,
    table_size: &str,
    no_cache: bool,
) -> AtmosphereArgs {
    AtmosphereArgs {
        preset: if scene.atmosphere.file.is_none() {
            Some(scene.atmosphere.preset.clone())
        } else {
            None
        },
        atmosphere: scene.atmosphere.file.clone(),
        wavelengths: scene.atmosphere.wavelengths.clone(),
        tables,
        table_size: table_size.to_string(),
        no_cache,
        ..AtmosphereArgs::default()
    }
}

/// The render settings of the scene's camera and image.
fn render_settings(scene: &Scene) -> RenderSettings<'_> {
    RenderSettings {
        camera: &scene.camera,
        width: scene.image.width,
        height: scene.image.height,
        white_balance: scene.output.white_balance,
    }
}

/// The scene's lights, glow and stars: from `[time]` at `[location]` when given, else its
/// sun.
pub fn sources_of_scene(model: &Model, scene: &Scene) -> Result<SkySources> {
    Ok(match scene.astro()? {
        Some(sky) => {
            let moon_disk = scene.time.as_ref().is_none_or(|t| t.moon_disk);
            sources_of(model, &sky, scene.sun.disk, moon_disk)
        }
        None => SkySources::sun(
            model,
            sun_direction(scene.sun.zenith_deg, scene.sun.azimuth_deg),
            scene.sun.disk,
        ),
    })
}

/// A note when the date's sun is in the twilight the tables do not hold (below their lowest
/// sun, above −18°): that sky is missing from the picture.
fn twilight_note(model: &Model, scene: &Scene) -> Result<()> {
    if let Some(sky) = scene.astro()? {
        let elevation = 90.0 - sky.sun.apparent_zenith_deg;
        let lowest = 90.0 - model.mu_s_min.acos().to_degrees();
        if elevation < lowest && elevation > -18.0 {
            eprintln!(
                "note: the sun is {elevation:.1}° high, below the lowest sun of these tables ({lowest:.0}°): the last twilight is left out; an atmosphere with min_sun_elevation_deg = -18 keeps it (docs/accuracy.md)"
            );
        }
    }
    Ok(())
}

/// The scene's EV100, or the automatic exposure of the frame.
fn ev100(scene: &Scene, frame: &render::Frame) -> f64 {
    scene
        .output
        .ev100
        .unwrap_or_else(|| tonemap::auto_ev100(frame.log_average_luminance()))
}

/// The scene's terrain on `model`'s planet (`terrain: …` on stderr unless `quiet`).
pub fn build_terrain(model: &Model, scene: &Scene, quiet: bool) -> Result<Option<Heightfield>> {
    let t = Instant::now();
    let terrain = scene.build_terrain(model)?;
    if let (Some(h), false) = (&terrain, quiet) {
        eprintln!(
            "terrain: {}×{} vertices, {:.0} m spacing, up to {:.0} m, in {:.2} s",
            h.heights.nx,
            h.heights.ny,
            h.heights.spacing_m,
            h.max_height_m(),
            t.elapsed().as_secs_f64()
        );
    }
    Ok(terrain)
}

/// The scene's terrain and the atmosphere arguments of its tables. Without --tables the
/// tables' ground albedo is the terrain's mean, so the ground bounce in the sky's light
/// (its irradiance, the multiple scattering) is the terrain's and not the preset's grey;
/// with --tables theirs is kept, with a note. The planet's sphere around the terrain takes
/// the same albedo.
pub fn terrain_and_atmosphere(
    scene: &Scene,
    tables: Option<PathBuf>,
    table_size: &str,
    no_cache: bool,
    quiet: bool,
) -> Result<(Option<Heightfield>, AtmosphereArgs)> {
    let mut atmosphere = atmosphere_args(scene, tables, table_size, no_cache);
    if scene.terrain.is_none() {
        return Ok((None, atmosphere));
    }
    let model = atmosphere.model()?;
    let terrain = build_terrain(&model, scene, quiet)?;
    if let Some(t) = &terrain {
        let albedo = t.mean_albedo(model.channels());
        let k = model.channels() / 2;
        if atmosphere.tables.is_none() {
            if !quiet {
                eprintln!(
                    "terrain: the tables' ground albedo is the terrain's mean, {:.3} at {:.0} nm (the atmosphere's: {:.3})",
                    albedo[k], model.wavelengths.nm()[k], model.ground_albedo[k]
                );
            }
            atmosphere.ground_albedo = Some(albedo);
            let lift = t.floor_m();
            if !quiet && lift > 0.0 {
                eprintln!(
                    "terrain: the tables' ground is lifted to the terrain's floor, {lift:.0} m (the air below it is the terrain's)"
                );
            }
            atmosphere.ground_lift_m = Some(lift);
        } else if !quiet {
            eprintln!(
                "note: the tables' ground albedo ({:.3} at {:.0} nm) is kept; the terrain's mean is {:.3} (without --tables the tables take it)",
                model.ground_albedo[k], model.wavelengths.nm()[k], albedo[k]
            );
        }
    }
    Ok((terrain, atmosphere))
}

/// Render the scene with a sky on its backend over its terrain (built by
/// [`build_terrain`]); returns the frame and the EV100 used.
pub fn render_scene(
    sky: &RenderSky,
    scene: &Scene,
    terrain: Option<&Heightfield>,
    quiet: bool,
) -> Result<(render::Frame, f64)> {
    let sources = sources_of_scene(sky.model(), scene)?;
    let camera = scene.camera_over(terrain, sky.model().bottom_radius_m);
    let radius = terrain.map_or(sky.model().bottom_radius_m, |t| t.radius_m);
    let planet = scene.build_surface(radius, sky.model().wavelengths.nm())?;
    let settings = RenderSettings {
        camera: &camera,
        ..render_settings(scene)
    };
    let frame = sky
        .render(&settings, &sources, terrain, planet.as_ref(), quiet)
        .context("rendering")?;
    let ev100 = ev100(scene, &frame);
    Ok((frame, ev100))
}

/// How frames become files: EXR precision and colour space, PNG dither.
#[derive(Clone, Copy, Debug)]
pub struct FileOptions {
    /// 16-bit half-float EXR.
    pub half: bool,
    /// The EXR's colour space (PNG and Radiance HDR are Rec. 709).
    pub gamut: Gamut,
    /// Triangular dither in 8-bit PNG.
    pub dither: bool,
}

impl FileOptions {
    /// From `render`'s flags.
    pub fn from_args(args: &RenderArgs) -> Result<FileOptions> {
        let gamut = Gamut::parse(&args.gamut).ok_or_else(|| {
            anyhow::anyhow!(
                "invalid value for `--gamut`: {} (accepted: rec709, rec2020, acescg)",
                args.gamut
            )
        })?;
        Ok(FileOptions {
            half: args.exr_half,
            gamut,
            dither: !args.no_dither,
        })
    }
}

/// Write the frame to every output (each atomically).
pub fn write_outputs(
    frame: &render::Frame,
    scene: &Scene,
    ev100: f64,
    files: FileOptions,
    quiet: bool,
) -> Result<()> {
    for path in &scene.output.files {
        let t = Instant::now();
        match OutputFormat::from_path(path)? {
            OutputFormat::Png => {
                let exposure = tonemap::exposure_from_ev100(ev100);
                let rgb8 = if files.dither {
                    frame.to_srgb8_dithered(exposure, scene.output.tonemap)
                } else {
                    frame.to_srgb8(exposure, scene.output.tonemap)
                };
                io::write_png_srgb8(path, frame.image.width, frame.image.height, &rgb8)?;
            }
            OutputFormat::Exr => {
                let image = frame.in_gamut(files.gamut);
                let precision = if files.half {
                    let half_max = io::HALF_MAX;
                    let clamped = (image.data.iter())
                        .filter(|p| p.iter().any(|&v| v > half_max))
                        .count();
                    if clamped > 0 && !quiet {
                        eprintln!(
                            "warning: {clamped} pixels of {} exceed the half-float range (65 504: the sun's disk?) and are clamped there; a 32-bit EXR (without --exr-half) keeps them, --no-sun-disk leaves the disk out",
                            path.display()
                        );
                    }
                    ExrPrecision::F16
                } else {
                    ExrPrecision::F32
                };
                let chromaticities = files.gamut.chromaticities();
                io::write_exr_in(path, &image, precision, &[], Some(&chromaticities))?;
            }
            OutputFormat::Hdr => io::write_hdr(path, &frame.in_gamut(Gamut::Rec709))?,
        }
        if !quiet {
            eprintln!(
                "wrote {} ({:.2} s)",
                path.display(),
                t.elapsed().as_secs_f64()
            );
        }
    }
    Ok(())
}

/// Render the scene with the Monte Carlo reference (`reference::render_frame`); returns the
/// frame and the EV100 used. Ctrl-C stops it between batches of pixels.
fn render_scene_reference(
    model: &Model,
    scene: &Scene,
    terrain: Option<&Heightfield>,
    samples: usize,
    quiet: bool,
) -> Result<(render::Frame, f64)> {
    check_reference_samples(samples)?;
    let sources = sources_of_scene(model, scene)?;
    let lights = &sources.lights;
    if lights.len() > 1 || sources.background.is_some() {
        anyhow::bail!(
            "`--method reference` traces the sun's light only so far: a --time with the moon up or the sun down is not supported with it"
        );
    }
    let sun = &lights[0];
    let surfaces: Vec<Box<dyn firmament::scene::Surface + '_>> =
        terrain.iter().map(|t| Box::new(*t) as _).collect();
    let camera = scene.camera_over(terrain, model.bottom_radius_m);
    let bar = progress_bar(1000, quiet);
    bar.set_message(format!("reference, {samples} paths/λ"));
    let result = reference::render_frame(
        model,
        &[],
        &surfaces,
        &RenderSettings {
            camera: &camera,
            ..render_settings(scene)
        },
        sun,
        &ReferenceSettings::with_samples(samples),
        &|f| bar.set_position((f * 1000.0) as u64),
        Some(cancel_flag()),
    );
    bar.finish_and_clear();
    let (frame, mean_stderr) = result?;
    if !quiet && mean_stderr > 0.0 {
        eprintln!(
            "reference: mean relative standard error of pixel luminance {:.2}% ({samples} paths/λ)",
            100.0 * mean_stderr
        );
    }
    let ev100 = ev100(scene, &frame);
    Ok((frame, ev100))
}

/// Run `firmament render`.
pub fn run(args: &RenderArgs) -> Result<()> {
    let scene = scene_from_args(args)?;
    let files = FileOptions::from_args(args)?;
    let times = match (&args.until, &args.every, &scene.time) {
        (Some(until), Some(every), Some(t)) => {
            for f in &scene.output.files {
                OutputFormat::from_path(f)?;
                timelapse::numbered(f, 0)?;
            }
            Some(timelapse::instants(&t.at, until, every)?)
        }
        _ => {
            for f in &scene.output.files {
                check_output_dir(f, "--out")?;
                OutputFormat::from_path(f)?;
            }
            None
        }
    };
    if times.is_some() && args.method == "reference" {
        anyhow::bail!(
            "a time-lapse (--until) uses the tables: `--method reference` is not supported with it"
        );
    }
    match args.method.as_str() {
        // An empty `--method` is taken as the default.
        "lut" | "" => {}
        "reference" => {
            if args.tables.is_some() {
                anyhow::bail!("`--method reference` uses no tables: --tables makes no sense here");
            }
            if args.backend == BackendChoice::Gpu {
                anyhow::bail!(
                    "`--method reference` runs on the CPU only: `--backend gpu` is not supported with it (use `--backend cpu` or `auto`, or `--method lut` for the GPU)"
                );
            }
            if !args.quiet {
                eprintln!("backend: cpu (the reference path tracer runs on the CPU only)");
            }
            let (terrain, atmosphere) =
                terrain_and_atmosphere(&scene, None, &args.table_size, true, args.quiet)?;
            let model = atmosphere.unlifted().model()?;
            print_wavelengths(&model, args.quiet);
            let t = Instant::now();
            let (frame, ev100) =
                render_scene_reference(&model, &scene, terrain.as_ref(), args.samples, args.quiet)?;
            if !args.quiet {
                eprintln!(
                    "render (reference): {}×{} {:?} in {:.2} s (EV100 {:.1})",
                    scene.image.width,
                    scene.image.height,
                    scene.camera.projection,
                    t.elapsed().as_secs_f64(),
                    ev100
                );
            }
            return write_outputs(&frame, &scene, ev100, files, args.quiet);
        }
        other => anyhow::bail!("invalid value for `--method`: {other} (accepted: lut, reference)"),
    }
    let backend = match Backend::open(args.backend, args.quiet)? {
        Backend::Gpu(_) if scene.surface.is_some() && args.backend == BackendChoice::Gpu => {
            anyhow::bail!(
                "the planet's surface map ([surface]) renders on the CPU only so far: `--backend cpu` or `auto` render it"
            )
        }
        Backend::Gpu(_) if scene.surface.is_some() => {
            if !args.quiet {
                eprintln!(
                    "note: the planet's surface map renders on the CPU only so far: using the CPU"
                );
            }
            Backend::Cpu
        }
        backend => backend,
    };
    let (terrain, atmosphere) = terrain_and_atmosphere(
        &scene,
        args.tables.clone(),
        &args.table_size,
        args.no_cache,
        args.quiet,
    )?;
    print_wavelengths(&atmosphere.model()?, args.quiet);
    let t = Instant::now();
    let sky = RenderSky::new(&backend, &atmosphere, args.quiet)?;
    if !args.quiet && args.tables.is_some() {
        eprintln!(
            "tables: loaded{} in {:.2} s",
            if sky.on().is_empty() {
                ""
            } else {
                " and uploaded to the GPU (render shader compiled)"
            },
            t.elapsed().as_secs_f64()
        );
    }
    if !args.quiet && times.is_none() {
        twilight_note(sky.model(), &scene)?;
    }
    if let Some(times) = times {
        let t = Instant::now();
        let (rendered, _) = timelapse::run(
            &sky,
            &scene,
            terrain.as_ref(),
            &times,
            args.resume,
            files,
            args.quiet,
        )?;
        if !args.quiet && rendered > 0 {
            eprintln!(
                "time-lapse: {:.2} s per frame",
                t.elapsed().as_secs_f64() / rendered as f64
            );
        }
        return Ok(());
    }
    let t = Instant::now();
    let (frame, ev100) = render_scene(&sky, &scene, terrain.as_ref(), args.quiet)?;
    if !args.quiet {
        eprintln!(
            "render: {}×{} {:?}{} in {:.2} s (EV100 {:.1}{})",
            scene.image.width,
            scene.image.height,
            scene.camera.projection,
            sky.on(),
            t.elapsed().as_secs_f64(),
            ev100,
            if scene.output.ev100.is_none() {
                ", automatic"
            } else {
                ""
            }
        );
    }
    write_outputs(&frame, &scene, ev100, files, args.quiet)
}

//! `firmament gallery`: the canonical views (Bruneton & Neyret 2008 figures 8–9 and more)
//! as PNGs with an index.html contact sheet.

use std::fmt::Write as _;
use std::io::Write as _;
use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, Result};
use clap::Args;
use firmament::scene::camera::orbit_fit_fov_deg;
use firmament::scene::file::{SceneLocation, SceneTime};
use firmament::scene::{Camera, Projection, SceneFile as Scene};

use crate::backend::{Backend, BackendChoice, RenderSky};
use crate::commands::outputs::{write_outputs, FileNotes, FileOptions};
use crate::commands::render::{atmosphere_args, render_scene, terrain_and_atmosphere};
use crate::method::Method;

/// Arguments of `firmament gallery`.
#[derive(Args, Debug)]
pub struct GalleryArgs {
    /// Output directory (created if missing).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Embedded preset.
    #[arg(long, default_value = "earth")]
    pub preset: String,
    /// Precomputed tables (must match the preset; their wavelengths are used).
    #[arg(long, value_name = "FILE")]
    pub tables: Option<PathBuf>,
    /// Wavelengths: `spectral` (16 samples 365–815 nm, the default), `rgb` (680, 550, 440
    /// nm: fast, a sunset mauve) or `NM,NM,...`. With --tables: the file's.
    #[arg(long, value_name = "spectral|rgb|NM,NM,...")]
    pub wavelengths: Option<String>,
    /// Neither read nor write the table cache: compute the tables and keep nothing.
    #[arg(long, conflicts_with = "tables")]
    pub no_cache: bool,
    /// Width of the perspective views (height is 9/16 of it).
    #[arg(long, default_value_t = 960)]
    pub width: usize,
    /// Print nothing but errors.
    #[arg(long, short)]
    pub quiet: bool,
    /// Where tables are precomputed and views rendered: `cpu`, `gpu` (wgpu, any adapter) or
    /// `auto` (a hardware GPU when wgpu finds one, else the CPU).
    #[arg(long, value_enum, value_name = "cpu|gpu|auto", default_value_t = BackendChoice::Auto)]
    pub backend: BackendChoice,
}

struct View {
    name: &'static str,
    title: &'static str,
    camera: Camera,
    sun: (f64, f64),
    size: (usize, usize),
    /// Added to the automatic exposure (stops darker), for views whose bright part is small.
    ev_offset: f64,
    /// A date and a place (ISO 8601, latitude, longitude) instead of `sun`.
    when: Option<(&'static str, f64, f64)>,
    /// A time-lapse strip: this many frames side by side, this many minutes apart.
    strip: Option<(usize, i64)>,
    /// Over the default scene's terrain.
    terrain: bool,
    /// With the planet's procedural surface map (`[surface]`).
    surface: bool,
    /// With the default scene's clouds.
    clouds: bool,
}

fn views(width: usize) -> Vec<View> {
    let h = width * 9 / 16;
    let cam = |projection, altitude_m, heading_deg, pitch_deg, fov_deg| Camera {
        projection,
        altitude_m,
        heading_deg,
        pitch_deg,
        roll_deg: 0.0,
        fov_deg,
    };
    use Projection::*;
    vec![
        View { name: "noon", title: "Noon from the ground, looking north (sun 60° high in the south)", camera: cam(Perspective, 2.0, 0.0, 12.0, 80.0), sun: (30.0, 180.0), size: (width, h), ev_offset: 0.0, when: None, strip: None, terrain: false, surface: false, clouds: false },
        View { name: "afternoon", title: "Afternoon, facing the sun (30° high)", camera: cam(Perspective, 2.0, 240.0, 12.0, 80.0), sun: (60.0, 240.0), size: (width, h), ev_offset: 0.0, when: None, strip: None, terrain: false, surface: false, clouds: false },
        View { name: "sunset", title: "Sunset (sun 1° high in the west)", camera: cam(Perspective, 2.0, 270.0, 6.0, 80.0), sun: (89.0, 270.0), size: (width, h), ev_offset: 0.0, when: None, strip: None, terrain: false, surface: false, clouds: false },
        View { name: "twilight", title: "Twilight, facing east away from the sun 4° below the horizon: Earth's shadow and the Belt of Venus", camera: cam(Perspective, 2.0, 90.0, 8.0, 80.0), sun: (94.0, 270.0), size: (width, h), ev_offset: 0.0, when: None, strip: None, terrain: false, surface: false, clouds: false },
        View { name: "altitude-10km", title: "From 10 km, looking down the aerial perspective", camera: cam(Perspective, 10_000.0, 200.0, -8.0, 80.0), sun: (50.0, 160.0), size: (width, h), ev_offset: 0.0, when: None, strip: None, terrain: false, surface: false, clouds: false },
        View { name: "low-orbit", title: "From low orbit (400 km), the limb with the sun low", camera: cam(Perspective, 400_000.0, 90.0, -17.0, 60.0), sun: (75.0, 90.0), size: (width, h), ev_offset: 0.0, when: None, strip: None, terrain: false, surface: true, clouds: false },
        View { ev_offset: 2.5, name: "planet", title: "The whole planet from 30 000 km: oceans, continents and ice of the procedural surface map, the sun's glint on the sea, limb, terminator, night side", camera: cam(Orbit, 30_000_000.0, 0.0, 0.0, orbit_fit_fov_deg(6_424_000.0, 36_360_000.0)), sun: (75.0, 90.0), size: (width * 2 / 3, width * 2 / 3), when: None, strip: None, terrain: false, surface: true, clouds: false },
        View { name: "fisheye", title: "All-sky fisheye (equidistant, north up, east left), sun 45° high in the south-east", camera: cam(Fisheye, 2.0, 0.0, 0.0, 60.0), sun: (45.0, 135.0), size: (width * 2 / 3, width * 2 / 3), ev_offset: 0.0, when: None, strip: None, terrain: false, surface: false, clouds: false },
        View { name: "moonlit", title: "Full-moon night over the Alps (46.5° N, 8° E), 2026-01-03 21:00 CET, facing the moon 38° high in the east", camera: cam(Perspective, 2.0, 92.0, 14.0, 70.0), sun: (0.0, 0.0), size: (width, h), ev_offset: 0.0, when: Some(("2026-01-03T20:00:00Z", 46.5, 8.0)), strip: None, terrain: false, surface: false, clouds: false },
        View { name: "starry-twilight", title: "Nautical twilight with a 4 % crescent moon in the west-south-west and the first stars, 2026-01-20 18:20 CET (46.5° N, 8° E), fisheye", camera: cam(Fisheye, 2.0, 0.0, 0.0, 60.0), sun: (0.0, 0.0), size: (width * 2 / 3, width * 2 / 3), ev_offset: 1.0, when: Some(("2026-01-20T17:20:00Z", 46.5, 8.0)), strip: None, terrain: false, surface: false, clouds: false },
        View { name: "sunrise-strip", title: "Sunrise time-lapse, 21 June 2026 at 46.5° N, 8° E, facing north-east: 02:40 to 04:20 UTC every 20 min (sunrise 03:35)", camera: cam(Perspective, 2.0, 50.0, 8.0, 60.0), sun: (0.0, 0.0), size: (width / 3, width / 3), ev_offset: 0.0, when: Some(("2026-06-21T02:40:00Z", 46.5, 8.0)), strip: Some((6, 20)), terrain: false, surface: false, clouds: false },
        View { name: "valley-sunset", title: "Golden hour in the valley (the default scene): the sun 5.5° high behind a peak, its shadow a shaft through the air, a few cumulus over the ridges", camera: cam(Perspective, 25.0, 250.0, 6.0, 55.0), sun: (84.5, 237.0), size: (width, h), ev_offset: 0.0, when: None, strip: None, terrain: true, surface: false, clouds: true },
        View { name: "valley-noon", title: "The valley at noon (sun 62° high in the south), looking north up the slopes", camera: cam(Perspective, 25.0, 20.0, 4.0, 60.0), sun: (28.0, 175.0), size: (width, h), ev_offset: 0.0, when: None, strip: None, terrain: true, surface: false, clouds: false },
        View { name: "valley-10km", title: "The mountains from 10 km, afternoon sun in the west-south-west", camera: cam(Perspective, 10_000.0, 30.0, -28.0, 70.0), sun: (70.0, 240.0), size: (width, h), ev_offset: 0.0, when: None, strip: None, terrain: true, surface: false, clouds: false },
        View { name: "equirect", title: "Equirectangular environment map (north at the centre column), sun 20° high in the east-south-east", camera: cam(Equirect, 2.0, 0.0, 0.0, 60.0), sun: (70.0, 120.0), size: (width, width / 2), ev_offset: 0.0, when: None, strip: None, terrain: false, surface: false, clouds: false },
    ]
}

/// `frames` frames of `scene` from its `[time]`, `minutes` apart, each with its own
/// automatic exposure (as a camera would), side by side in one PNG at `path`.
fn write_strip(
    sky: &RenderSky,
    scene: &Scene,
    frames: usize,
    minutes: i64,
    path: &std::path::Path,
    no_cache: bool,
) -> Result<()> {
    let start = firmament::astro::Instant::parse(
        &scene.time.as_ref().context("a strip needs a time")?.at,
        "time",
    )?;
    let (w, h) = (scene.image.width, scene.image.height);
    let mut strip = vec![[0u8; 3]; w * frames * h];
    for i in 0..frames {
        let mut s = scene.clone();
        let at = start.utc + chrono::Duration::minutes(minutes * i as i64);
        if let Some(t) = &mut s.time {
            t.at = at.to_rfc3339();
        }
        let (frame, ev100) = render_scene(sky, &s, None, no_cache, true)?;
        let rgb = frame.to_srgb8_dithered(
            firmament::render::tonemap::exposure_from_ev100(ev100, s.output.tonemap),
            s.output.tonemap,
        );
        for y in 0..h {
            let at = y * w * frames + i * w;
            strip[at..at + w].copy_from_slice(&rgb[y * w..(y + 1) * w]);
        }
    }
    firmament::io::write_png_srgb8(path, w * frames, h, &strip)?;
    Ok(())
}

/// Run the gallery.
pub fn run(args: &GalleryArgs) -> Result<()> {
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("creating {}", args.out.display()))?;
    let mut base = Scene::default();
    base.atmosphere.preset = args.preset.clone();
    base.atmosphere.wavelengths = args.wavelengths.clone();
    let terrain_config = base.terrain.take();
    // The default scene's cumulus, for its own view only.
    let clouds = std::mem::take(&mut base.clouds);
    let backend = Backend::open(args.backend, args.quiet)?;
    let atmosphere = atmosphere_args(&base, args.tables.clone(), "default", args.no_cache);
    let wavelengths = atmosphere.wavelengths()?;
    if !args.quiet {
        eprintln!("wavelengths: {}", wavelengths.describe());
    }
    let t = Instant::now();
    let sky = RenderSky::new(&backend, &atmosphere, Method::Bruneton4d, args.quiet)?;
    if !args.quiet {
        eprintln!("tables ready in {:.2} s", t.elapsed().as_secs_f64());
    }
    // The terrain views have tables of their own whose ground albedo is the terrain's and
    // whose ground is lifted to its floor (as `render` computes them), unless --tables are
    // given.
    let (terrain, terrain_sky) = match terrain_config.clone() {
        Some(config) => {
            let with = Scene {
                terrain: Some(config),
                ..base.clone()
            };
            let (terrain, atmosphere) = terrain_and_atmosphere(
                &with,
                args.tables.clone(),
                "default",
                args.no_cache,
                args.quiet,
            )?;
            let terrain_sky = match args.tables {
                Some(_) => None,
                None => Some(RenderSky::new(
                    &backend,
                    &atmosphere,
                    Method::Bruneton4d,
                    args.quiet,
                )?),
            };
            (terrain, terrain_sky)
        }
        None => (None, None),
    };
    let mut html = String::from(
        "<!doctype html><meta charset=utf-8><title>firmament gallery</title>\n<style>body{background:#111;color:#ddd;font-family:sans-serif}figure{display:inline-block;margin:8px;vertical-align:top;max-width:480px}img{max-width:480px}figcaption{font-size:13px}</style>\n<h1>firmament gallery</h1>\n",
    );
    let _ = writeln!(
        html,
        "<p>Preset <code>{}</code>, wavelengths {}, default tables, automatic exposure, ACES tone curve.</p>",
        args.preset,
        wavelengths.describe()
    );
    for v in views(args.width) {
        if v.terrain && terrain.is_none() {
            continue;
        }
        let mut scene = base.clone();
        if v.terrain {
            scene.terrain = terrain_config.clone();
        }
        if v.clouds {
            scene.clouds = clouds.clone();
        }
        let terrain = terrain.as_ref().filter(|_| v.terrain);
        let sky = match (&terrain_sky, v.terrain) {
            (Some(terrain_sky), true) => terrain_sky,
            _ => &sky,
        };
        scene.surface = v
            .surface
            .then(firmament::scene::planet_config::SurfaceConfig::default);
        scene.camera = v.camera.clone();
        scene.sun.zenith_deg = v.sun.0;
        scene.sun.azimuth_deg = v.sun.1;
        if let Some((at, lat, lon)) = v.when {
            scene.time = Some(SceneTime {
                at: at.into(),
                moon_disk: true,
            });
            scene.location = Some(SceneLocation {
                lat_deg: lat,
                lon_deg: lon,
                elevation_m: 0.0,
                pressure_hpa: 1013.25,
                temperature_c: 15.0,
            });
        }
        (scene.image.width, scene.image.height) = v.size;
        let file = format!("{}.png", v.name);
        scene.output.files = vec![args.out.join(&file)];
        scene.validate()?;
        let t = Instant::now();
        let ev100 = match v.strip {
            None => {
                let (frame, ev100) = render_scene(sky, &scene, terrain, args.no_cache, true)?;
                let ev100 = ev100 + v.ev_offset;
                let files = FileOptions {
                    half: false,
                    gamut: firmament::spectrum::gamut::Gamut::Rec709,
                    dither: true,
                    layout: firmament::render::cube_layout::CubeLayout::Firmament,
                };
                write_outputs(&frame, &scene, ev100, files, &FileNotes::default(), true)?;
                ev100
            }
            Some((frames, minutes)) => {
                write_strip(
                    sky,
                    &scene,
                    frames,
                    minutes,
                    &args.out.join(&file),
                    args.no_cache,
                )?;
                f64::NAN
            }
        };
        if !args.quiet {
            eprintln!(
                "{:14} {}×{}{} in {:.2} s",
                v.name,
                v.size.0 * v.strip.map_or(1, |s| s.0),
                v.size.1,
                sky.on(),
                t.elapsed().as_secs_f64()
            );
        }
        let c = &v.camera;
        let sun = match v.when {
            Some((at, lat, lon)) => format!("--time {at} --lat-deg {lat} --lon-deg {lon}"),
            None => format!("--sun-zenith-deg {} --sun-azimuth-deg {}", v.sun.0, v.sun.1),
        };
        let exposure = if ev100.is_nan() {
            "automatic exposure per frame".to_string()
        } else {
            format!("EV100 {ev100:.1}")
        };
        let _ = writeln!(
            html,
            "<figure><img src=\"{file}\"><figcaption><b>{}</b><br>{:?}, altitude {} m, heading {}°, pitch {}°, fov {:.1}°; {exposure}<br><code>firmament render --camera {} --altitude-m {} --heading-deg {} --pitch-deg {} --fov-deg {:.1} {sun} --width {} --height {}</code></figcaption></figure>",
            v.title, c.projection, c.altitude_m, c.heading_deg, c.pitch_deg, c.fov_deg,
            format!("{:?}", c.projection).to_lowercase(), c.altitude_m, c.heading_deg, c.pitch_deg, c.fov_deg, v.size.0, v.size.1
        );
    }
    let index = args.out.join("index.html");
    firmament::io::write_atomic(&index, |out| Ok(out.write_all(html.as_bytes())?))
        .with_context(|| format!("writing {}", index.display()))?;
    if !args.quiet {
        eprintln!("wrote {}", index.display());
    }
    Ok(())
}

//! `firmament view`: the scene drawn live by the GPU backend in a window, with a panel to
//! move the sun or the clock, fly the camera, switch the sky method, change the atmosphere
//! and the exposure, and capture the view (PNG as shown, EXR in cd/m², the scene as TOML for
//! `firmament render`). `--offscreen` draws the same frame path without a window.
//!
//! - `state.rs`: what is shown (a scene file, the method, the viewer's settings);
//! - `controls.rs`, `presets.rs`: the camera under the keys and the mouse, named views;
//! - `frame_path.rs`: the sky into an HDR texture, the display pass into the target (its
//!   sky in `frame_sky.rs`, the reference beside it in `frame_reference.rs`);
//! - `panel.rs`: the egui panel; `window.rs`: winit, the surface, egui; `capture.rs`: files.

pub mod capture;
pub mod controls;
pub mod difference;
pub mod frame_path;
pub mod panel;
pub mod presets;
pub mod progressive;
pub mod state;
pub mod window;

use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Args;
use firmament::scene::SceneFile;

use crate::backend::{Backend, Gpu};
use crate::method::Method;
use capture::CaptureKind;
use frame_path::{display_settings, FramePath};
use state::ViewState;

/// Arguments of `firmament view`.
#[derive(Args, Debug, Clone)]
pub struct ViewArgs {
    /// Scene file (TOML, as `firmament render --scene` reads it). Without one: the default
    /// scene (golden hour in the valley).
    #[arg(long, value_name = "FILE")]
    pub scene: Option<PathBuf>,
    /// The sky method drawing the view: bruneton4d (`lut`), hillaire2020, elek3d.
    #[arg(long, value_enum, default_value_t = Method::Bruneton4d)]
    pub method: Method,
    /// Window width (pixels).
    #[arg(long, default_value_t = 1280)]
    pub width: u32,
    /// Window height (pixels).
    #[arg(long, default_value_t = 720)]
    pub height: u32,
    /// The fraction of the window's size the sky is drawn at, 0.1–1 (default: 1 on a GPU,
    /// 0.5 on a software rasteriser).
    #[arg(long, value_name = "0.1-1")]
    pub render_scale: Option<f64>,
    /// Under clouds or over a terrain, march one pixel of each N×N block a frame and take
    /// the others from the previous frames (reprojected as the camera turns or climbs) or,
    /// where they do not match, from this frame's pixels around them: 1 marches every pixel
    /// every frame, 2 a quarter, 4 a sixteenth; a still view is the full frame after N²
    /// frames.
    #[arg(long, default_value_t = state::DEFAULT_MARCH_STEP, value_name = "1|2|4")]
    pub march_step: u32,
    /// Draw this many frames, write `--screenshot`, and exit.
    #[arg(long, value_name = "N")]
    pub frames: Option<u32>,
    /// With --frames: write the last frame to this file, `.png` (what the window shows) or
    /// `.exr` (linear, Y in cd/m²); may be given twice.
    #[arg(long, value_name = "OUT.png|OUT.exr")]
    pub screenshot: Vec<PathBuf>,
    /// Draw without a window (the same frame path; no panel): needs --frames.
    #[arg(long)]
    pub offscreen: bool,
    /// With --frames: also write the view's scene (TOML) here, as Ctrl+S does:
    /// `firmament render --scene FILE` draws it offline.
    #[arg(long, value_name = "FILE.toml")]
    pub save_scene: Option<PathBuf>,
    /// Precomputed 4D tables from `firmament bake` for the scene's atmosphere (must match
    /// it); without them the tables are computed (on the CPU through the table cache on a
    /// software rasteriser, on the GPU otherwise).
    #[arg(long, value_name = "FILE")]
    pub tables: Option<PathBuf>,
    /// Table sizes when no --tables are given: `default` or `small` (fast, coarse).
    #[arg(long, default_value = "default", value_name = "default|small")]
    pub table_size: String,
    /// Where F12's captures and Ctrl+S's scenes are written.
    #[arg(long, default_value = ".", value_name = "DIR")]
    pub capture_dir: PathBuf,
    /// The reference path tracer beside the method (`split`: the right half) or instead of
    /// it (`whole`), or the method against it in false colour (`difference`: red where the
    /// method is brighter, blue where darker, full at ±10 %), traced progressively on the
    /// CPU; `off` by default.
    #[arg(long, default_value = "off", value_name = "off|split|whole|difference")]
    pub reference: String,
    /// With --frames and --reference: the last frame waits for this many of the
    /// reference's passes (2 paths per wavelength each).
    #[arg(long, default_value_t = 1, value_name = "N")]
    pub reference_passes: usize,
    /// Print nothing but errors.
    #[arg(long, short)]
    pub quiet: bool,
}

/// The scene the viewer starts from, and what of it the viewer does not draw yet.
pub fn load_scene(path: Option<&PathBuf>) -> Result<(SceneFile, Vec<String>)> {
    let scene = match path {
        Some(p) => SceneFile::from_file(p)?,
        None => SceneFile::default(),
    };
    let mut not_drawn = Vec::new();
    if scene.terrain.is_some() {
        not_drawn.push(
            "the terrain: drawn with bruneton4d only (hillaire2020 and elek3d draw it in `firmament render` on the CPU)"
                .into(),
        );
    }
    if !scene.clouds.is_empty() {
        not_drawn.push(
            "the scene's clouds: drawn with bruneton4d only (hillaire2020 and elek3d draw them in `firmament render` on the CPU)"
                .into(),
        );
    }
    Ok((scene, not_drawn))
}

fn check(args: &ViewArgs) -> Result<()> {
    if args.method == Method::Reference {
        anyhow::bail!("invalid value for `--method`: reference (accepted in the viewer: bruneton4d, hillaire2020, elek3d; the reference is `--reference split|whole` beside one of them)");
    }
    if let Some(s) = args.render_scale {
        if !(0.1..=1.0).contains(&s) {
            anyhow::bail!("invalid value for `--render-scale`: {s} (accepted: 0.1 to 1)");
        }
    }
    for (name, v) in [("--width", args.width), ("--height", args.height)] {
        if !(16..=8192).contains(&v) {
            anyhow::bail!("invalid value for `{name}`: {v} (accepted: 16 to 8192)");
        }
    }
    if !firmament_gpu::render::temporal::STEPS.contains(&args.march_step) {
        anyhow::bail!(
            "invalid value for `--march-step`: {} (accepted: 1, 2, 4)",
            args.march_step
        );
    }
    if args.frames == Some(0) {
        anyhow::bail!("invalid value for `--frames`: 0 (accepted: 1 or more)");
    }
    if !args.screenshot.is_empty() && args.frames.is_none() {
        anyhow::bail!("`--screenshot` is written after `--frames N`: give both");
    }
    if args.save_scene.is_some() && args.frames.is_none() {
        anyhow::bail!(
            "`--save-scene` is written after `--frames N`: give both (in the window, Ctrl+S saves)"
        );
    }
    if !matches!(args.table_size.as_str(), "default" | "small") {
        anyhow::bail!(
            "invalid value for `--table-size`: {} (accepted: default, small)",
            args.table_size
        );
    }
    compare_of(&args.reference)?;
    if !(1..=10_000).contains(&args.reference_passes) {
        anyhow::bail!(
            "invalid value for `--reference-passes`: {} (accepted: 1 to 10000)",
            args.reference_passes
        );
    }
    if args.offscreen && args.frames.is_none() {
        anyhow::bail!("`--offscreen` draws `--frames N` and exits: give --frames");
    }
    for p in &args.screenshot {
        CaptureKind::of(p)?;
        crate::common::check_output_dir(p, "--screenshot")?;
    }
    if let Some(p) = &args.save_scene {
        crate::common::check_output_dir(p, "--save-scene")?;
    }
    Ok(())
}

/// `--reference`'s value.
fn compare_of(text: &str) -> Result<progressive::Compare> {
    use progressive::Compare;
    Ok(match text {
        "off" => Compare::Off,
        "split" => Compare::Split,
        "whole" => Compare::Whole,
        "difference" => Compare::Difference,
        other => {
            anyhow::bail!(
                "invalid value for `--reference`: {other} (accepted: off, split, whole, difference)"
            )
        }
    })
}

/// Run `firmament view`.
pub fn run(args: &ViewArgs) -> Result<()> {
    check(args)?;
    let (scene, not_drawn) = load_scene(args.scene.as_ref())?;
    if !args.quiet {
        for line in &not_drawn {
            eprintln!("note: {line}");
        }
    }
    let mut state = ViewState::new(scene, args.method, false);
    state.compare = compare_of(&args.reference)?;
    state.march_step = args.march_step;
    if let Some(s) = args.render_scale {
        state.render_scale = s;
    }
    if args.offscreen {
        return run_offscreen(args, state);
    }
    window::run(args.clone(), state, not_drawn)
}

/// `--offscreen`: the window's frame path without a window.
fn run_offscreen(args: &ViewArgs, mut state: ViewState) -> Result<()> {
    let gpu = Gpu::open().context("`firmament view`")?;
    if !args.quiet {
        eprintln!("backend: gpu ({}), offscreen", gpu.describe());
    }
    if args.render_scale.is_none() && gpu.ctx.is_software() {
        state.render_scale = 0.5;
    }
    let backend: &'static Backend = Box::leak(Box::new(Backend::Gpu(Box::new(gpu))));
    let mut path = FramePath::new(backend, &state, args.tables.clone(), &args.table_size)?;
    let frames = args.frames.unwrap_or(1);
    let size = (args.width, args.height);
    let mut last = None;
    let started = std::time::Instant::now();
    for i in 0..frames {
        let display = display_settings(&state, 1.0 / 60.0, i == 0);
        last = Some(path.draw_offscreen(&state, size, display)?);
    }
    if !args.quiet {
        eprintln!(
            "view: {frames} frame(s) of {}×{} ({} drawn at {}×{}) in {:.2} s",
            size.0,
            size.1,
            state.method.name(),
            frame_path::render_size(&state, size).0,
            frame_path::render_size(&state, size).1,
            started.elapsed().as_secs_f64()
        );
    }
    if let Some(line) = path.march_line(&state) {
        if !args.quiet {
            eprintln!("view: {line}");
        }
    }
    if let Some(t) = path.pass_times() {
        if !args.quiet {
            eprintln!(
                "view: GPU times of a frame (timestamp queries): sky {:.3} ms, display {:.3} ms",
                t.sky_ms, t.display_ms
            );
        }
    }
    if state.compare != progressive::Compare::Off {
        // The tracer runs beside the frames: the last one waits for its passes.
        path.wait_for_reference(args.reference_passes)?;
        let display = display_settings(&state, 1.0 / 60.0, false);
        last = Some(path.draw_offscreen(&state, size, display)?);
        if state.compare == progressive::Compare::Difference {
            // The false colour of a pass is made once the frame that compared it is read
            // back: it shows from the next frame on.
            last = Some(path.draw_offscreen(&state, size, display)?);
        }
        if !args.quiet {
            if let Some(line) = path.reference_line() {
                eprintln!("view: {line}");
            }
            if let Some((bias, mean_abs)) = path.reference_difference() {
                eprintln!(
                    "view: {} against the reference over the frame: mean luminance {:+.2} %, mean |ΔL|/L {:.2} % (the reference's noise included)",
                    state.method.name(),
                    100.0 * bias,
                    100.0 * mean_abs
                );
            }
        }
    }
    let (hdr, shown) = last.expect("at least one frame");
    let ev100 = path.shown_ev100()?;
    for p in &args.screenshot {
        match CaptureKind::of(p)? {
            CaptureKind::Png => capture::write_png(p, size, &shown)?,
            CaptureKind::Exr => capture::write_exr(p, &hdr, &state, ev100)?,
        }
        if !args.quiet {
            eprintln!("wrote {}", p.display());
        }
    }
    if let Some(p) = &args.save_scene {
        capture::write_scene(p, &state, size)?;
        if !args.quiet {
            eprintln!(
                "wrote {}: {}",
                p.display(),
                state.render_command(&p.display().to_string())
            );
        }
    }
    Ok(())
}

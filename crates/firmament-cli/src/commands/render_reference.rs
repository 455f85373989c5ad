//! `render --method reference`: the Monte Carlo path tracer's picture of the scene, with an
//! estimate of its time before it starts (from a pilot of a few pixels), a progress bar
//! with the time left and the noise reached so far, and the noise at the end.

use std::time::Instant;

use anyhow::Result;
use firmament::atmosphere::Model;
use firmament::reference::{self, Progress, ReferenceSettings};
use firmament::render::{self, RenderSettings};
use firmament::scene::terrain::Heightfield;
use firmament::scene::{Light, SceneFile as Scene, Surface, Volume};

use super::render::{ev100, render_settings, sources_of_scene};
use crate::common::{cancel_flag, check_reference_samples, drawn_bar};

/// Pixels across the pilot frame that times the tracer before the real one.
const PILOT_WIDTH: usize = 12;

/// The pilot's estimate of the whole frame's time (s): a PILOT_WIDTH-wide frame of the same
/// view (the same mix of sky, ground and terrain), its time per pixel times the pixels.
fn estimate_s(
    model: &Model,
    volumes: &[Box<dyn Volume + '_>],
    surfaces: &[Box<dyn Surface + '_>],
    settings: &RenderSettings,
    sun: &Light,
    reference: &ReferenceSettings,
) -> Result<f64> {
    let (w, h) = (settings.width, settings.height);
    let pw = PILOT_WIDTH.min(w);
    let ph = ((pw * h) as f64 / w as f64).round().max(1.0) as usize;
    let pilot = RenderSettings {
        width: pw,
        height: ph,
        ..*settings
    };
    let t = Instant::now();
    let (frame, _) = reference::render_frame(
        model,
        volumes,
        surfaces,
        &pilot,
        sun,
        reference,
        &|_| {},
        None,
    )?;
    let traced = frame.mask.iter().filter(|&&m| m).count().max(1);
    let per_pixel = t.elapsed().as_secs_f64() / traced as f64;
    let full = w * h * traced / (pw * ph);
    Ok(per_pixel * full as f64)
}

/// Render the scene with the Monte Carlo reference (`reference::render_frame`); returns the
/// frame and the EV100 used. Ctrl-C stops it between batches of pixels.
pub fn render_scene_reference(
    model: &Model,
    scene: &Scene,
    terrain: Option<&Heightfield>,
    samples: usize,
    no_cache: bool,
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
    let surfaces: Vec<Box<dyn Surface + '_>> = terrain.iter().map(|t| Box::new(*t) as _).collect();
    let radius = terrain.map_or(model.bottom_radius_m, |t| t.radius_m);
    let clouds = crate::common::scene_clouds(scene, radius, no_cache, quiet)?;
    let volumes: Vec<Box<dyn Volume + '_>> = clouds.iter().map(|c| Box::new(c) as _).collect();
    let camera = scene.camera_over(terrain, model.bottom_radius_m);
    let settings = RenderSettings {
        camera: &camera,
        ..render_settings(scene)
    };
    let reference = ReferenceSettings::with_samples(samples);
    if !quiet {
        let estimate = estimate_s(model, &volumes, &surfaces, &settings, sun, &reference)?;
        eprintln!(
            "reference: {}×{} at {samples} paths/λ, about {} (estimated from a {PILOT_WIDTH}-pixel-wide pilot); Ctrl-C stops it",
            settings.width,
            settings.height,
            duration(estimate)
        );
    }
    let bar = drawn_bar(
        1000,
        quiet,
        "{spinner} [{elapsed_precise}] {wide_bar} {percent:>3}% {eta} left, {msg}",
    );
    bar.set_message(format!("{samples} paths/λ"));
    let result = reference::render_frame(
        model,
        &volumes,
        &surfaces,
        &settings,
        sun,
        &reference,
        &|p: Progress| {
            bar.set_position((p.fraction * 1000.0) as u64);
            if p.mean_relative_stderr.is_finite() {
                bar.set_message(format!(
                    "noise {:.2} % ({samples} paths/λ)",
                    100.0 * p.mean_relative_stderr
                ));
            }
        },
        Some(cancel_flag()),
    );
    bar.finish_and_clear();
    let (frame, mean_stderr) = result?;
    if !quiet && mean_stderr > 0.0 {
        eprintln!(
            "reference: mean relative standard error of pixel luminance {:.2}% ({samples} paths/λ; it falls as 1/√samples)",
            100.0 * mean_stderr
        );
    }
    let ev100 = ev100(scene, &frame);
    Ok((frame, ev100))
}

/// `12 s`, `3 min 20 s`, `1 h 05 min`.
fn duration(s: f64) -> String {
    let s = s.round() as u64;
    match s {
        0..60 => format!("{s} s"),
        60..3600 => format!("{} min {:02} s", s / 60, s % 60),
        _ => format!("{} h {:02} min", s / 3600, (s % 3600) / 60),
    }
}

//! `firmament render --time START --until END --every STEP`: a numbered sequence of frames
//! from one set of tables, with a progress bar, stopped cleanly by Ctrl-C and resumed with
//! `--resume` (frames whose every output exists are skipped).

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use chrono::Duration;
use firmament::astro::time::parse_duration_s;
use firmament::astro::Instant;
use firmament::scene::SceneFile as Scene;
use serde_json::json;

use crate::backend::RenderSky;
use crate::commands::outputs::{write_outputs, FileOptions};
use crate::commands::render::{file_notes, render_scene};
use crate::common::{cancel_flag, progress_bar};
use firmament::scene::terrain::Heightfield;

/// The most frames one sequence may have.
const MAX_FRAMES: usize = 100_000;

/// The instants from `start` to `until` (inclusive) every `every`.
pub fn instants(start: &str, until: &str, every: &str) -> Result<Vec<Instant>> {
    let a = Instant::parse(start, "--time")?;
    let b = Instant::parse(until, "--until")?;
    let step = parse_duration_s(every, "--every")?;
    if b.utc < a.utc {
        anyhow::bail!(
            "invalid value for `--until`: {until} (accepted: an instant not before --time {start})"
        );
    }
    let span = (b.utc - a.utc).num_milliseconds() as f64 / 1000.0;
    let count = (span / step + 1e-9).floor() as usize + 1;
    if count > MAX_FRAMES {
        anyhow::bail!("invalid value for `--every`: {every} gives {count} frames (accepted: at most {MAX_FRAMES})");
    }
    Ok((0..count)
        .map(|i| {
            let utc = a.utc + Duration::milliseconds((i as f64 * step * 1000.0).round() as i64);
            Instant::from_utc(utc).unwrap_or(Instant::with_delta_t(utc, a.delta_t_s))
        })
        .collect())
}

/// `pattern` with its printf-style `%d` / `%0Nd` replaced by `index`.
pub fn numbered(pattern: &Path, index: usize) -> Result<PathBuf> {
    let text = pattern.to_string_lossy();
    let Some(at) = text.find('%') else {
        anyhow::bail!(
            "invalid value for `--out`: {text} (a time-lapse needs a frame number in each file name, e.g. frames/sky_%04d.png)"
        );
    };
    let rest = &text[at + 1..];
    let digits: String = rest.chars().take_while(|c| c.is_ascii_digit()).collect();
    if !rest[digits.len()..].starts_with('d') {
        anyhow::bail!("invalid value for `--out`: {text} (accepted frame numbers: %d or %0Nd)");
    }
    let width: usize = digits.trim_start_matches('0').parse().unwrap_or(0);
    let number = format!("{index:0width$}");
    Ok(PathBuf::from(format!(
        "{}{number}{}",
        &text[..at],
        &rest[digits.len() + 1..]
    )))
}

/// Render the sequence of `scene` at `times` on `sky`; returns how many frames were
/// rendered and skipped. Writes `frames.json` (index, time, sun) beside the first output.
pub fn run(
    sky: &RenderSky,
    scene: &Scene,
    terrain: Option<&Heightfield>,
    times: &[Instant],
    resume: bool,
    options: FileOptions,
    no_cache: bool,
    quiet: bool,
) -> Result<(usize, usize)> {
    let patterns = scene.output.files.clone();
    for p in &patterns {
        if let Some(dir) = p.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
        }
    }
    let bar = progress_bar(times.len() as u64, quiet);
    bar.set_message("time-lapse");
    let (mut rendered, mut skipped) = (0, 0);
    let mut index = Vec::new();
    for (i, instant) in times.iter().enumerate() {
        if cancel_flag().load(std::sync::atomic::Ordering::Relaxed) {
            bar.abandon();
            anyhow::bail!("interrupted after {rendered} frames; run again with --resume to go on");
        }
        let files: Vec<PathBuf> = patterns
            .iter()
            .map(|p| numbered(p, i))
            .collect::<Result<_>>()?;
        let mut frame_scene = scene.clone();
        if let Some(t) = &mut frame_scene.time {
            t.at = instant.utc.to_rfc3339();
        }
        let astro = frame_scene
            .astro()?
            .context("a time-lapse needs --time and a place")?;
        index.push(json!({
            "index": i,
            "time_utc": instant.iso(),
            "files": files,
            "sun": { "apparent_zenith_deg": astro.sun.apparent_zenith_deg, "azimuth_deg": astro.sun.azimuth_deg },
            "moon": { "apparent_zenith_deg": astro.moon.apparent_zenith_deg, "azimuth_deg": astro.moon.azimuth_deg },
        }));
        if resume && files.iter().all(|f| f.exists()) {
            skipped += 1;
            bar.inc(1);
            continue;
        }
        frame_scene.output.files = files;
        let (frame, ev100) = render_scene(sky, &frame_scene, terrain, no_cache, true)?;
        // Each frame's files carry its provenance and, for maps, its lamps.
        let notes = file_notes(sky, &frame_scene, terrain, &options, ev100)?;
        write_outputs(&frame, &frame_scene, ev100, options, &notes, true)?;
        rendered += 1;
        bar.inc(1);
    }
    bar.finish_and_clear();
    let dir = patterns[0]
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let list = dir.join("frames.json");
    let text = serde_json::to_string_pretty(&index)?;
    firmament::io::write_atomic(&list, |w| {
        use std::io::Write;
        w.write_all(text.as_bytes())
            .map_err(|e| firmament::Error::File {
                path: list.display().to_string(),
                reason: e.to_string(),
            })
    })?;
    if !quiet {
        eprintln!(
            "time-lapse: {rendered} frames rendered, {skipped} skipped (existing); list in {}",
            list.display()
        );
    }
    Ok((rendered, skipped))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_names_and_instants() {
        assert_eq!(
            numbered(Path::new("f/sky_%04d.exr"), 7).unwrap(),
            PathBuf::from("f/sky_0007.exr")
        );
        assert_eq!(
            numbered(Path::new("a%db.png"), 12).unwrap(),
            PathBuf::from("a12b.png")
        );
        assert!(numbered(Path::new("sky.png"), 1).is_err());
        let t = instants("2026-06-21T04:00:00Z", "2026-06-21T06:00:00Z", "10m").unwrap();
        assert_eq!(t.len(), 13);
        assert_eq!(t[12].iso(), "2026-06-21T06:00:00Z");
        assert!(instants("2026-06-21T06:00:00Z", "2026-06-21T04:00:00Z", "10m").is_err());
    }
}

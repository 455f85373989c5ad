//! Captures: what the window shows as an 8-bit sRGB PNG (the display pass's own pixels,
//! read back), the frame under it as a linear EXR (linear sRGB, Y in cd/m², 32-bit floats,
//! the view's method, camera, sun and exposure as attributes), and the scene as TOML.
//! Every file is written to a temporary name and renamed (`firmament::io`).

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use firmament::io::{exr, png, ExrPrecision};
use firmament::render::Frame;

use super::state::ViewState;

/// Which capture a path asks for, by its extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CaptureKind {
    Png,
    Exr,
}

impl CaptureKind {
    /// The kind of `path`, or an error naming the accepted extensions.
    pub fn of(path: &Path) -> Result<CaptureKind> {
        match path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
        {
            Some(e) if e == "png" => Ok(CaptureKind::Png),
            Some(e) if e == "exr" => Ok(CaptureKind::Exr),
            _ => anyhow::bail!(
                "invalid value for `--screenshot`: {} (accepted: a .png or .exr file)",
                path.display()
            ),
        }
    }
}

/// Write the displayed pixels (RGBA, `size`) as a PNG.
pub fn write_png(path: &Path, size: (u32, u32), rgba: &[[u8; 4]]) -> Result<()> {
    let rgb: Vec<[u8; 3]> = rgba.iter().map(|p| [p[0], p[1], p[2]]).collect();
    png::write_png_srgb8(path, size.0 as usize, size.1 as usize, &rgb)
        .with_context(|| format!("writing {}", path.display()))
}

/// Write the HDR frame as an EXR with the view's description.
pub fn write_exr(path: &Path, frame: &Frame, state: &ViewState, ev100: f64) -> Result<()> {
    let c = &state.scene.camera;
    let attributes = [
        (
            "firmament:method".to_string(),
            state.method.name().to_string(),
        ),
        (
            "firmament:camera".to_string(),
            format!(
                "altitude {:.1} m, heading {:.2} deg, pitch {:.2} deg, fov {:.2} deg",
                c.altitude_m, c.heading_deg, c.pitch_deg, c.fov_deg
            ),
        ),
        (
            "firmament:sun".to_string(),
            match &state.scene.time {
                Some(t) if state.dated() => format!("time {}", t.at),
                _ => format!(
                    "zenith {:.3} deg, azimuth {:.3} deg",
                    state.scene.sun.zenith_deg, state.scene.sun.azimuth_deg
                ),
            },
        ),
        (
            "firmament:exposure".to_string(),
            format!("EV100 {ev100:.3} (PNG captures only; the EXR is linear, Y in cd/m2)"),
        ),
    ];
    let attrs: Vec<(&str, &str)> = attributes
        .iter()
        .map(|(k, v)| (k.as_str(), v.as_str()))
        .collect();
    exr::write_exr_with_attributes(path, &frame.image, ExrPrecision::F32, &attrs)
        .with_context(|| format!("writing {}", path.display()))
}

/// The next free numbered name `firmament-view-NNNN.EXT` in `dir`.
pub fn next_name(dir: &Path, ext: &str) -> PathBuf {
    (1..)
        .map(|i| dir.join(format!("firmament-view-{i:04}.{ext}")))
        .find(|p| !p.exists())
        .expect("a free name")
}

/// Write the scene TOML for "save scene" (to a temporary file, renamed).
pub fn write_scene(path: &Path, state: &ViewState, size: (u32, u32)) -> Result<()> {
    let text = state.scene_toml(size.0 as usize, size.1 as usize)?;
    firmament::io::atomic::write_atomic(path, |f| {
        use std::io::Write;
        f.write_all(text.as_bytes())
            .map_err(|e| firmament::Error::File {
                path: path.display().to_string(),
                reason: e.to_string(),
            })
    })
    .with_context(|| format!("writing {}", path.display()))
}

//! Frames to files: PNG (exposed, tone-mapped, dithered), OpenEXR (linear, in a chosen
//! gamut, half or single floats) and Radiance HDR, each written atomically.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Result;
use firmament::io::{self, ExrPrecision, OutputFormat};
use firmament::render::cube_layout::CubeLayout;
use firmament::render::{self, tonemap};
use firmament::scene::{Projection, SceneFile as Scene};
use firmament::spectrum::gamut::Gamut;

use super::render_args::RenderArgs;

/// How frames become files: EXR precision and colour space, PNG dither, cube layout.
#[derive(Clone, Copy, Debug)]
pub struct FileOptions {
    /// 16-bit half-float EXR (and DDS, KTX2).
    pub half: bool,
    /// The EXR's colour space (PNG, Radiance HDR and DDS are Rec. 709).
    pub gamut: Gamut,
    /// Triangular dither in 8-bit PNG.
    pub dither: bool,
    /// A cube map's layout in PNG, EXR and HDR files; DDS and KTX2 files hold its standard
    /// faces.
    pub layout: CubeLayout,
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
        let layout = match &args.layout {
            None => CubeLayout::Firmament,
            Some(l) => CubeLayout::parse(l).ok_or_else(|| {
                let names: Vec<_> = CubeLayout::ALL.iter().map(|(_, n)| *n).collect();
                anyhow::anyhow!(
                    "invalid value for `--layout`: {l} (accepted: {})",
                    names.join(", ")
                )
            })?,
        };
        Ok(FileOptions {
            half: args.exr_half,
            gamut,
            dither: !args.no_dither,
            layout,
        })
    }
}

/// What goes with the pixels: `firmament:*` attributes for EXR headers (provenance) and
/// the lamps of an environment map (`NAME.lights.json` next to each of its files).
#[derive(Clone, Debug, Default)]
pub struct FileNotes {
    /// EXR text attributes.
    pub attributes: Vec<(String, String)>,
    /// The lamps' JSON ([`super::lamps::lamps`]), for equirect and cube maps.
    pub lamps: Option<serde_json::Value>,
}

/// `DIR/NAME.lights.json` for `DIR/NAME.EXT`.
pub fn lamps_path(path: &Path) -> PathBuf {
    let stem = path.file_stem().map(|s| s.to_string_lossy().into_owned());
    path.with_file_name(format!("{}.lights.json", stem.unwrap_or_default()))
}

/// The frame in `layout` (a cube map's pixels rearranged; other frames as they are).
fn arranged(frame: &render::Frame, scene: &Scene, layout: CubeLayout) -> Option<render::Frame> {
    if scene.camera.projection != Projection::Cubemap || layout == CubeLayout::Firmament {
        return None;
    }
    let image = layout.arrange(&frame.image);
    let face = frame.image.height;
    let mask = (0..image.width * image.height)
        .map(|i| {
            let (x, y) = (i % image.width, i / image.width);
            layout
                .direction(face, x as f64 + 0.5, y as f64 + 0.5)
                .is_some()
        })
        .collect();
    Some(render::Frame { image, mask })
}

/// A warning for the pixels a half-float file clamps at 65 504.
fn warn_half_clamps(image: &io::ImageRgbF32, path: &Path, quiet: bool) {
    let clamped = (image.data.iter())
        .filter(|p| p.iter().any(|&v| v > io::HALF_MAX))
        .count();
    if clamped > 0 && !quiet {
        eprintln!(
            "warning: {clamped} pixels of {} exceed the half-float range (65 504: the sun's disk?) and are clamped there; a 32-bit file (without --exr-half) keeps them, --no-sun-disk leaves the disk out (its light is in the .lights.json lamp of an environment map)",
            path.display()
        );
    }
}

/// Write the frame to every output (each atomically), and the lamps' JSON next to them.
pub fn write_outputs(
    frame: &render::Frame,
    scene: &Scene,
    ev100: f64,
    files: FileOptions,
    notes: &FileNotes,
    quiet: bool,
) -> Result<()> {
    let native = frame;
    let laid_out = arranged(frame, scene, files.layout);
    let frame = laid_out.as_ref().unwrap_or(frame);
    let attributes: Vec<(&str, &str)> = (notes.attributes.iter())
        .map(|(k, v)| (k.as_str(), v.as_str()))
        .collect();
    let precision = if files.half {
        ExrPrecision::F16
    } else {
        ExrPrecision::F32
    };
    let mut lamp_files = Vec::new();
    for path in &scene.output.files {
        let t = Instant::now();
        match OutputFormat::from_path(path)? {
            OutputFormat::Png => {
                let exposure = tonemap::exposure_from_ev100(ev100, scene.output.tonemap);
                let rgb8 = if files.dither {
                    frame.to_srgb8_dithered(exposure, scene.output.tonemap)
                } else {
                    frame.to_srgb8(exposure, scene.output.tonemap)
                };
                io::write_png_srgb8(path, frame.image.width, frame.image.height, &rgb8)?;
            }
            OutputFormat::Exr => {
                let image = frame.in_gamut(files.gamut);
                if files.half {
                    warn_half_clamps(&image, path, quiet);
                }
                let chromaticities = files.gamut.chromaticities();
                io::write_exr_in(path, &image, precision, &attributes, Some(&chromaticities))?;
            }
            OutputFormat::Hdr => io::write_hdr(path, &frame.in_gamut(Gamut::Rec709))?,
            format @ (OutputFormat::Dds | OutputFormat::Ktx2) => {
                // Standard faces: the layout's own, y-up for firmament's and the cross.
                let layout = match files.layout {
                    CubeLayout::Unreal => CubeLayout::Unreal,
                    _ => CubeLayout::YUp,
                };
                let faces = layout.faces(&native.in_gamut(Gamut::Rec709));
                if files.half {
                    faces.iter().for_each(|f| warn_half_clamps(f, path, quiet));
                }
                if format == OutputFormat::Dds {
                    io::write_dds_cube(path, &faces, precision)?;
                } else {
                    io::write_ktx2_cube(path, &faces, precision)?;
                }
            }
        }
        if let Some(l) = &notes.lamps {
            let json = lamps_path(path);
            if !lamp_files.contains(&json) {
                let text = serde_json::to_string_pretty(l)? + "\n";
                io::write_atomic(&json, |w| {
                    use std::io::Write;
                    w.write_all(text.as_bytes())
                        .map_err(|e| firmament::Error::File {
                            path: json.display().to_string(),
                            reason: format!("cannot write: {e}"),
                        })
                })?;
                lamp_files.push(json);
            }
        }
        if !quiet {
            eprintln!(
                "wrote {} ({:.2} s)",
                path.display(),
                t.elapsed().as_secs_f64()
            );
        }
    }
    for json in lamp_files {
        if !quiet {
            eprintln!(
                "wrote {} (the lamps: sun direction, illuminance, colour)",
                json.display()
            );
        }
    }
    Ok(())
}

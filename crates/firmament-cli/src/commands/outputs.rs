//! Frames to files: PNG (exposed, tone-mapped, dithered), OpenEXR (linear, in a chosen
//! gamut, half or single floats) and Radiance HDR, each written atomically.

use std::time::Instant;

use anyhow::Result;
use firmament::io::{self, ExrPrecision, OutputFormat};
use firmament::render::{self, tonemap};
use firmament::scene::SceneFile as Scene;
use firmament::spectrum::gamut::Gamut;

use super::render_args::RenderArgs;

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

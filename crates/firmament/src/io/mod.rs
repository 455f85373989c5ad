//! Image input and output: PNG (8-bit sRGB, [`png`]), OpenEXR (half or single float,
//! [`exr`]) and Radiance RGBE (`.hdr`, [`hdr`]), all written atomically ([`atomic`]).
//!
//! Every writer goes through a temporary file in the destination's directory
//! (`.<name>.tmp-<pid>`) that is renamed over the destination only once it has been
//! written completely and synced, and removed on any failure (including a panic), so
//! a failed or interrupted write never leaves a partial output file.

pub mod atomic;
mod cube_faces;
pub mod dds;
pub mod exr;
pub mod hdr;
pub mod ktx;
pub mod png;

use std::path::{Path, PathBuf};

pub use self::exr::{
    read_exr, read_exr_chromaticities, read_exr_text_attributes, write_exr, write_exr_in,
    write_exr_with_attributes, HALF_MAX,
};
pub use self::hdr::{read_hdr, rgbe_decode, rgbe_encode, write_hdr, write_hdr_uncompressed};
pub use self::png::{read_png_srgb8, write_png_srgb8};
pub use atomic::write_atomic;
pub use dds::{read_dds_cube, write_dds_cube};
pub use ktx::{read_ktx2_cube, write_ktx2_cube};

use crate::{Error, Result};

/// A linear RGB image in physical units (radiance, or luminance-scaled; the caller
/// decides), row-major with the top row first.
#[derive(Debug, Clone, PartialEq)]
pub struct ImageRgbF32 {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// `width * height` pixels, row-major, top row first.
    pub data: Vec<[f32; 3]>,
}

impl ImageRgbF32 {
    /// A black image.
    pub fn new(width: usize, height: usize) -> Self {
        ImageRgbF32 {
            width,
            height,
            data: vec![[0.0; 3]; width * height],
        }
    }

    /// The pixel at column `x`, row `y` (row 0 is the top). Panics when out of range.
    pub fn get(&self, x: usize, y: usize) -> [f32; 3] {
        assert!(
            x < self.width && y < self.height,
            "pixel ({x}, {y}) outside {}x{}",
            self.width,
            self.height
        );
        self.data[y * self.width + x]
    }

    /// Sets the pixel at column `x`, row `y` (row 0 is the top). Panics when out of range.
    pub fn set(&mut self, x: usize, y: usize, rgb: [f32; 3]) {
        assert!(
            x < self.width && y < self.height,
            "pixel ({x}, {y}) outside {}x{}",
            self.width,
            self.height
        );
        self.data[y * self.width + x] = rgb;
    }

    fn check(&self, path: &Path) -> Result<()> {
        if self.width == 0 || self.height == 0 {
            return Err(file_error(
                path,
                format!(
                    "cannot write an empty image ({}x{})",
                    self.width, self.height
                ),
            ));
        }
        if self.data.len() != self.width * self.height {
            return Err(file_error(
                path,
                format!(
                    "image data holds {} pixels, but {}x{} needs {}",
                    self.data.len(),
                    self.width,
                    self.height,
                    self.width * self.height
                ),
            ));
        }
        Ok(())
    }
}

/// An output file format, chosen by the file name's extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OutputFormat {
    /// 8-bit sRGB PNG (tone-mapped).
    Png,
    /// OpenEXR, linear float RGB.
    Exr,
    /// Radiance RGBE, linear.
    Hdr,
    /// DirectDraw Surface cube map, linear float (cube-map cameras only).
    Dds,
    /// KTX 2.0 cube map, linear float (cube-map cameras only).
    Ktx2,
}

impl OutputFormat {
    /// The format named by `path`'s extension (`.png`, `.exr`, `.hdr`, `.dds`, `.ktx2`, any case).
    pub fn from_path(path: impl AsRef<Path>) -> Result<OutputFormat> {
        let path = path.as_ref();
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(|e| e.to_ascii_lowercase());
        match ext.as_deref() {
            Some("png") => Ok(OutputFormat::Png),
            Some("exr") => Ok(OutputFormat::Exr),
            Some("hdr") => Ok(OutputFormat::Hdr),
            Some("dds") => Ok(OutputFormat::Dds),
            Some("ktx2") => Ok(OutputFormat::Ktx2),
            _ => Err(Error::invalid(
                "out",
                path.display(),
                "a file name ending in .png, .exr, .hdr, .dds or .ktx2",
            )),
        }
    }

    /// The canonical extension, without the dot.
    pub fn extension(self) -> &'static str {
        match self {
            OutputFormat::Png => "png",
            OutputFormat::Exr => "exr",
            OutputFormat::Hdr => "hdr",
            OutputFormat::Dds => "dds",
            OutputFormat::Ktx2 => "ktx2",
        }
    }

    /// Whether the format stores linear high-dynamic-range values (EXR, HDR) rather
    /// than tone-mapped 8-bit sRGB (PNG).
    pub fn is_hdr(self) -> bool {
        !matches!(self, OutputFormat::Png)
    }
}

/// Sample precision of an EXR file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ExrPrecision {
    /// 32-bit float samples (lossless for `f32` data).
    #[default]
    F32,
    /// 16-bit half float samples (11 significant bits, range about 6e-5 .. 65504; brighter
    /// samples, such as the sun's disk, are clamped to 65504).
    F16,
}

pub(crate) fn file_error(path: &Path, reason: impl Into<String>) -> Error {
    Error::File {
        path: path.display().to_string(),
        reason: reason.into(),
    }
}

pub(crate) fn parent_dir(path: &Path) -> PathBuf {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// A clear reason for an I/O failure on `path`; `writing` selects the wording.
fn io_reason(path: &Path, e: &std::io::Error, writing: bool) -> String {
    use std::io::ErrorKind;
    let dir = parent_dir(path);
    match e.kind() {
        ErrorKind::NotFound if writing && !dir.is_dir() => {
            format!("cannot write: directory {} does not exist", dir.display())
        }
        ErrorKind::NotFound if writing => format!("cannot write: {e}"),
        ErrorKind::NotFound => "cannot read: file does not exist".to_string(),
        ErrorKind::PermissionDenied if writing => {
            format!(
                "cannot write: permission denied (in directory {})",
                dir.display()
            )
        }
        ErrorKind::PermissionDenied => "cannot read: permission denied".to_string(),
        ErrorKind::UnexpectedEof => "cannot read: file is truncated".to_string(),
        _ if writing => format!("cannot write: {e}"),
        _ => format!("cannot read: {e}"),
    }
}

pub(crate) fn io_error(path: &Path, e: &std::io::Error, writing: bool) -> Error {
    file_error(path, io_reason(path, e, writing))
}

#[cfg(test)]
mod tests;

//! 8-bit sRGB PNG files (the tone-mapped output).

use std::fs::File;
use std::path::Path;

use super::atomic::write_atomic;
use super::{file_error, io_error};
use crate::{Error, Result};

fn image_error(path: &Path, e: image::ImageError, writing: bool) -> Error {
    match e {
        image::ImageError::IoError(io) => io_error(path, &io, writing),
        other if writing => file_error(path, format!("cannot write PNG: {other}")),
        other => file_error(path, format!("cannot read PNG: {other}")),
    }
}

/// Writes an 8-bit sRGB PNG (`rgb8`: `width * height` pixels, row-major, top row
/// first, already tone-mapped and encoded by the caller).
pub fn write_png_srgb8(
    path: impl AsRef<Path>,
    width: usize,
    height: usize,
    rgb8: &[[u8; 3]],
) -> Result<()> {
    use image::ImageEncoder;
    let path = path.as_ref();
    if width == 0 || height == 0 || width > u32::MAX as usize || height > u32::MAX as usize {
        return Err(file_error(
            path,
            format!("cannot write a {width}x{height} PNG"),
        ));
    }
    if rgb8.len() != width * height {
        return Err(file_error(
            path,
            format!(
                "image data holds {} pixels, but {width}x{height} needs {}",
                rgb8.len(),
                width * height
            ),
        ));
    }
    let bytes: &[u8] = rgb8.as_flattened();
    write_atomic(path, |w| {
        image::codecs::png::PngEncoder::new(w)
            .write_image(
                bytes,
                width as u32,
                height as u32,
                image::ExtendedColorType::Rgb8,
            )
            .map_err(|e| image_error(path, e, true))
    })
}

/// Reads a PNG as 8-bit sRGB (converted to RGB8 if it is grey, has alpha or 16-bit
/// samples): `(width, height, pixels)`, row-major, top row first.
pub fn read_png_srgb8(path: impl AsRef<Path>) -> Result<(usize, usize, Vec<[u8; 3]>)> {
    let path = path.as_ref();
    let file = File::open(path).map_err(|e| io_error(path, &e, false))?;
    let img = image::load(std::io::BufReader::new(file), image::ImageFormat::Png)
        .map_err(|e| image_error(path, e, false))?
        .into_rgb8();
    let (w, h) = (img.width() as usize, img.height() as usize);
    let data = img
        .into_raw()
        .chunks_exact(3)
        .map(|c| [c[0], c[1], c[2]])
        .collect();
    Ok((w, h, data))
}

/// Decodes the PNG an input field names (a heightmap, a surface map): errors name `field`
/// and say what it must be (`wanted`, e.g. "a 16-bit greyscale PNG file") when the file is
/// not a PNG.
pub fn decode_png_input(path: &Path, field: &str, wanted: &str) -> Result<image::DynamicImage> {
    let file_error = |reason: String| Error::File {
        path: path.display().to_string(),
        reason: format!("{field}: {reason}"),
    };
    let reader = image::ImageReader::open(path)
        .map_err(|e| file_error(e.to_string()))?
        .with_guessed_format()
        .map_err(|e| file_error(e.to_string()))?;
    if reader.format() != Some(image::ImageFormat::Png) {
        return Err(Error::invalid(field, path.display(), wanted));
    }
    reader.decode().map_err(|e| file_error(e.to_string()))
}

//! What the cube-map files (DDS, KTX2) share: six square faces of one size, their texels as
//! little-endian float RGBA with alpha 1 (32-bit, or 16-bit half floats clamped at 65 504
//! rather than written as infinity), and the way back.

use std::path::Path;

use half::f16;

use super::exr::HALF_MAX;
use super::{file_error, ExrPrecision, ImageRgbF32};
use crate::Result;

/// The faces' edge (pixels) when there are six square faces of one size with finite,
/// non-negative values; an error naming `format` otherwise.
pub(crate) fn face_size(path: &Path, faces: &[ImageRgbF32], format: &str) -> Result<usize> {
    let n = faces.first().map_or(0, |f| f.width);
    if faces.len() != 6 || n == 0 || faces.iter().any(|f| f.width != n || f.height != n) {
        return Err(file_error(
            path,
            format!("cannot write {format} cube map: six square faces of one size are needed"),
        ));
    }
    for f in faces {
        f.check(path)?;
    }
    Ok(n)
}

/// Bytes per channel.
pub(crate) fn channel_bytes(precision: ExrPrecision) -> usize {
    match precision {
        ExrPrecision::F32 => 4,
        ExrPrecision::F16 => 2,
    }
}

/// A face's texels, row by row from the top, as RGBA.
pub(crate) fn rgba_bytes(face: &ImageRgbF32, precision: ExrPrecision) -> Vec<u8> {
    let mut bytes = Vec::with_capacity(face.data.len() * 4 * channel_bytes(precision));
    for p in &face.data {
        for v in [p[0], p[1], p[2], 1.0] {
            match precision {
                ExrPrecision::F32 => bytes.extend_from_slice(&v.to_le_bytes()),
                // Half floats end at 65504: brighter samples are clamped there.
                ExrPrecision::F16 => {
                    bytes.extend_from_slice(&f16::from_f32(v.min(HALF_MAX)).to_le_bytes())
                }
            }
        }
    }
    bytes
}

/// An `n`×`n` face back from its RGBA bytes (alpha dropped).
pub(crate) fn face_from_rgba(bytes: &[u8], n: usize, precision: ExrPrecision) -> ImageRgbF32 {
    let size = channel_bytes(precision);
    let mut face = ImageRgbF32::new(n, n);
    for (k, p) in face.data.iter_mut().enumerate() {
        for (c, v) in p.iter_mut().enumerate() {
            let at = (4 * k + c) * size;
            *v = match precision {
                ExrPrecision::F16 => f16::from_le_bytes([bytes[at], bytes[at + 1]]).to_f32(),
                ExrPrecision::F32 => f32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()),
            };
        }
    }
    face
}

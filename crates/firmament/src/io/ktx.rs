//! KTX 2.0 cube maps (Khronos KTX File Format Specification 2.0): one mip level of six faces
//! +X, −X, +Y, −Y, +Z, −Z, linear float RGBA (alpha 1), `VK_FORMAT_R32G32B32A32_SFLOAT` or
//! `VK_FORMAT_R16G16B16A16_SFLOAT`, no supercompression, the Basic Data Format Descriptor of
//! the format (linear transfer, BT.709 primaries) and a `KTXwriter` key. The faces'
//! orientation is the caller's (`render::cube_layout`: the spec's left-handed, +Y-up cube
//! with top-left origin, its default `KTXorientation` "rd"). The header, level index and
//! descriptor come from the `ktx2` crate; the layout is written here.

use std::io::Write;
use std::path::Path;

use ::ktx2::dfd::{Basic, Block};
use ::ktx2::{Format, Header, Index, LevelIndex};

use super::cube_faces::{channel_bytes, face_from_rgba, face_size, rgba_bytes};
use super::{file_error, write_atomic, ExrPrecision, ImageRgbF32};
use crate::Result;

/// Round `n` up to a multiple of `to`.
fn align(n: usize, to: usize) -> usize {
    n.div_ceil(to) * to
}

/// The key/value data: `KTXwriter` (KTX 2.0 §5.6.3), each entry its u32 length, the key
/// and value NUL-terminated, padded to 4 bytes.
fn key_values() -> Vec<u8> {
    let mut entry = b"KTXwriter\0".to_vec();
    entry.extend_from_slice(format!("firmament {}\0", env!("CARGO_PKG_VERSION")).as_bytes());
    let mut out = (entry.len() as u32).to_le_bytes().to_vec();
    out.extend_from_slice(&entry);
    out.resize(align(out.len(), 4), 0);
    out
}

/// Write six square faces (+X, −X, +Y, −Y, +Z, −Z) as a KTX2 cube map, atomically.
pub fn write_ktx2_cube(
    path: impl AsRef<Path>,
    faces: &[ImageRgbF32],
    precision: ExrPrecision,
) -> Result<()> {
    let path = path.as_ref();
    let n = face_size(path, faces, "KTX2")?;
    let format = match precision {
        ExrPrecision::F32 => Format::R32G32B32A32_SFLOAT,
        ExrPrecision::F16 => Format::R16G16B16A16_SFLOAT,
    };
    let (basic, type_size) = Basic::from_format(format)
        .map_err(|e| file_error(path, format!("cannot write KTX2: {e:?}")))?;
    let block = Block::Basic(basic).to_vec();
    // The descriptor: its total size (u32) then its blocks.
    let mut dfd = ((4 + block.len()) as u32).to_le_bytes().to_vec();
    dfd.extend_from_slice(&block);
    let kvd = key_values();
    // The level's texels: each face's rows, top first, RGBA.
    let data: Vec<u8> = faces
        .iter()
        .flat_map(|f| rgba_bytes(f, precision))
        .collect();
    let dfd_offset = Header::LENGTH + LevelIndex::LENGTH;
    let kvd_offset = dfd_offset + dfd.len();
    // Level data aligned to lcm(texel size, 4) (§3.9.7): the texel size, 8 or 16 bytes.
    let texel = 4 * type_size as usize;
    let data_offset = align(kvd_offset + kvd.len(), texel);
    let header = Header {
        format: Some(format),
        type_size,
        pixel_width: n as u32,
        pixel_height: n as u32,
        pixel_depth: 0,
        layer_count: 0,
        face_count: 6,
        level_count: 1,
        supercompression_scheme: None,
        index: Index {
            dfd_byte_offset: dfd_offset as u32,
            dfd_byte_length: dfd.len() as u32,
            kvd_byte_offset: kvd_offset as u32,
            kvd_byte_length: kvd.len() as u32,
            sgd_byte_offset: 0,
            sgd_byte_length: 0,
        },
    };
    let level = LevelIndex {
        byte_offset: data_offset as u64,
        byte_length: data.len() as u64,
        uncompressed_byte_length: data.len() as u64,
    };
    let mut bytes = header.as_bytes().to_vec();
    bytes.extend_from_slice(&level.as_bytes());
    bytes.extend_from_slice(&dfd);
    bytes.extend_from_slice(&kvd);
    bytes.resize(data_offset, 0);
    bytes.extend_from_slice(&data);
    write_atomic(path, |out| {
        out.write_all(&bytes)
            .map_err(|e| super::io_error(path, &e, true))
    })
}

/// Read a KTX2 cube map written by [`write_ktx2_cube`]: its six faces' RGB, in file order.
pub fn read_ktx2_cube(path: impl AsRef<Path>) -> Result<Vec<ImageRgbF32>> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(|e| super::io_error(path, &e, false))?;
    let bad = |why: String| file_error(path, format!("cannot read KTX2: {why}"));
    let reader = ::ktx2::Reader::new(&bytes[..]).map_err(|e| bad(format!("{e:?}")))?;
    let header = reader.header();
    let precision = match header.format {
        Some(Format::R32G32B32A32_SFLOAT) => ExrPrecision::F32,
        Some(Format::R16G16B16A16_SFLOAT) => ExrPrecision::F16,
        other => return Err(bad(format!("format {other:?}"))),
    };
    if header.face_count != 6 || header.supercompression_scheme.is_some() {
        return Err(bad("not an uncompressed cube map".into()));
    }
    let n = header.pixel_width as usize;
    let level = reader
        .levels()
        .next()
        .ok_or_else(|| bad("no level".into()))?;
    let face_bytes = n * n * 4 * channel_bytes(precision);
    if level.data.len() != 6 * face_bytes {
        return Err(bad("unexpected level size".into()));
    }
    Ok(level
        .data
        .chunks(face_bytes)
        .map(|d| face_from_rgba(d, n, precision))
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::HALF_MAX;

    #[test]
    fn a_cube_round_trips_through_the_ktx2_reader() {
        let dir = std::env::temp_dir().join(format!("firmament-ktx-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let faces: Vec<ImageRgbF32> = (0..6)
            .map(|f| {
                let mut img = ImageRgbF32::new(3, 3);
                for (i, p) in img.data.iter_mut().enumerate() {
                    *p = [f as f32, i as f32 * 0.5, 1e5];
                }
                img
            })
            .collect();
        for precision in [ExrPrecision::F32, ExrPrecision::F16] {
            let path = dir.join("cube.ktx2");
            write_ktx2_cube(&path, &faces, precision).unwrap();
            let bytes = std::fs::read(&path).unwrap();
            let reader = ::ktx2::Reader::new(&bytes[..]).unwrap();
            let h = reader.header();
            assert_eq!((h.face_count, h.level_count, h.layer_count), (6, 1, 0));
            assert!(!reader.dfd_blocks().is_empty(), "a data format descriptor");
            let writer = reader
                .key_value_data()
                .find(|(k, _)| *k == "KTXwriter")
                .map(|(_, v)| String::from_utf8_lossy(v).into_owned());
            assert!(writer.is_some_and(|w| w.starts_with("firmament")));
            let back = read_ktx2_cube(&path).unwrap();
            for (a, b) in back.iter().zip(&faces) {
                for (p, q) in a.data.iter().zip(&b.data) {
                    // Half floats clamp the 1e5 at 65504.
                    let blue = match precision {
                        ExrPrecision::F32 => q[2],
                        ExrPrecision::F16 => q[2].min(HALF_MAX),
                    };
                    assert_eq!(*p, [q[0], q[1], blue]);
                }
            }
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

//! DirectDraw Surface cube maps: six faces +X, −X, +Y, −Y, +Z, −Z of linear float RGBA
//! (alpha 1) with the DX10 header (`DXGI_FORMAT_R32G32B32A32_FLOAT` or
//! `R16G16B16A16_FLOAT`, `DDS_RESOURCE_MISC_TEXTURECUBE`, array size 1) and the cube-map
//! caps (`DDSCAPS2_CUBEMAP` and all six faces), as Microsoft's "DDS file layout for cubic
//! environment maps" describes and engines (Bevy, Unity, Unreal, DirectXTex) read. The faces'
//! orientation is the caller's (`render::cube_layout`). Written with the `ddsfile` crate.

use std::path::Path;

use ddsfile::{AlphaMode, Caps2, D3D10ResourceDimension, Dds, DxgiFormat, NewDxgiParams};
use half::f16;

use super::exr::HALF_MAX;
use super::{file_error, write_atomic, ExrPrecision, ImageRgbF32};
use crate::Result;

/// Write six square faces (+X, −X, +Y, −Y, +Z, −Z) as a DDS cube map, atomically.
pub fn write_dds_cube(
    path: impl AsRef<Path>,
    faces: &[ImageRgbF32],
    precision: ExrPrecision,
) -> Result<()> {
    let path = path.as_ref();
    let n = faces.first().map_or(0, |f| f.width);
    if faces.len() != 6 || n == 0 || faces.iter().any(|f| f.width != n || f.height != n) {
        return Err(file_error(
            path,
            "cannot write DDS cube map: six square faces of one size are needed",
        ));
    }
    for f in faces {
        f.check(path)?;
    }
    let dds_error = |e: ddsfile::Error| file_error(path, format!("cannot write DDS: {e}"));
    let mut dds = Dds::new_dxgi(NewDxgiParams {
        height: n as u32,
        width: n as u32,
        depth: None,
        format: match precision {
            ExrPrecision::F32 => DxgiFormat::R32G32B32A32_Float,
            ExrPrecision::F16 => DxgiFormat::R16G16B16A16_Float,
        },
        mipmap_levels: None,
        array_layers: Some(6),
        // `new_dxgi` leaves the legacy header's caps2 to the caller: without the cube
        // flags loaders (Bevy's among them) take the file for a texture array.
        caps2: Some(Caps2::CUBEMAP | Caps2::CUBEMAP_ALLFACES),
        is_cubemap: true,
        resource_dimension: D3D10ResourceDimension::Texture2D,
        alpha_mode: AlphaMode::Unknown,
    })
    .map_err(dds_error)?;
    for (i, face) in faces.iter().enumerate() {
        let data = dds.get_mut_data(i as u32).map_err(dds_error)?;
        let mut bytes = Vec::with_capacity(data.len());
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
        if bytes.len() != data.len() {
            return Err(file_error(path, "cannot write DDS: unexpected face size"));
        }
        data.copy_from_slice(&bytes);
    }
    write_atomic(path, |out| dds.write(out).map_err(dds_error))
}

/// Read a DDS cube map written by [`write_dds_cube`]: its six faces' RGB, in file order.
pub fn read_dds_cube(path: impl AsRef<Path>) -> Result<Vec<ImageRgbF32>> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(|e| super::io_error(path, &e, false))?;
    let dds =
        Dds::read(&bytes[..]).map_err(|e| file_error(path, format!("cannot read DDS: {e}")))?;
    let n = dds.get_width() as usize;
    if !dds
        .header
        .caps2
        .contains(Caps2::CUBEMAP | Caps2::CUBEMAP_ALLFACES)
        || dds.get_num_array_layers() != 6
    {
        return Err(file_error(
            path,
            "cannot read DDS: not a cube map with six faces",
        ));
    }
    let half = match dds.get_dxgi_format() {
        Some(DxgiFormat::R32G32B32A32_Float) => false,
        Some(DxgiFormat::R16G16B16A16_Float) => true,
        other => {
            return Err(file_error(
                path,
                format!("cannot read DDS: format {other:?}"),
            ));
        }
    };
    (0..6)
        .map(|i| {
            let data = dds
                .get_data(i)
                .map_err(|e| file_error(path, format!("cannot read DDS: {e}")))?;
            let mut face = ImageRgbF32::new(n, n);
            let size = if half { 2 } else { 4 };
            for (k, p) in face.data.iter_mut().enumerate() {
                for (c, v) in p.iter_mut().enumerate() {
                    let at = (4 * k + c) * size;
                    *v = if half {
                        f16::from_le_bytes([data[at], data[at + 1]]).to_f32()
                    } else {
                        f32::from_le_bytes(data[at..at + 4].try_into().unwrap())
                    };
                }
            }
            Ok(face)
        })
        .collect()
}

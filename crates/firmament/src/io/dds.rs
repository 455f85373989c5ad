//! DirectDraw Surface cube maps: six faces +X, −X, +Y, −Y, +Z, −Z of linear float RGBA
//! (alpha 1) with the DX10 header (`DXGI_FORMAT_R32G32B32A32_FLOAT` or
//! `R16G16B16A16_FLOAT`, `DDS_RESOURCE_MISC_TEXTURECUBE`, array size 1) and the cube-map
//! caps (`DDSCAPS2_CUBEMAP` and all six faces), as Microsoft's "DDS file layout for cubic
//! environment maps" describes and engines (Bevy, Unity, Unreal, DirectXTex) read. The faces'
//! orientation is the caller's (`render::cube_layout`). Written with the `ddsfile` crate.

use std::path::Path;

use super::cube_faces::{channel_bytes, face_from_rgba, face_size, rgba_bytes};
use super::{file_error, write_atomic, ExrPrecision, ImageRgbF32};
use crate::Result;
use ddsfile::{AlphaMode, Caps2, D3D10ResourceDimension, Dds, DxgiFormat, NewDxgiParams};

/// Write six square faces (+X, −X, +Y, −Y, +Z, −Z) as a DDS cube map, atomically.
pub fn write_dds_cube(
    path: impl AsRef<Path>,
    faces: &[ImageRgbF32],
    precision: ExrPrecision,
) -> Result<()> {
    let path = path.as_ref();
    let n = face_size(path, faces, "DDS")?;
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
        let bytes = rgba_bytes(face, precision);
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
    let precision = match dds.get_dxgi_format() {
        Some(DxgiFormat::R32G32B32A32_Float) => ExrPrecision::F32,
        Some(DxgiFormat::R16G16B16A16_Float) => ExrPrecision::F16,
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
            if data.len() < n * n * 4 * channel_bytes(precision) {
                return Err(file_error(path, "cannot read DDS: face too short"));
            }
            let face = face_from_rgba(data, n, precision);
            Ok(face)
        })
        .collect()
}

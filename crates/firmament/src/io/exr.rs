//! OpenEXR files: linear float RGB, 32-bit or 16-bit samples, with text attributes.

use std::fs::File;
use std::path::Path;

use super::atomic::write_atomic;
use super::{file_error, io_error, ExrPrecision, ImageRgbF32};
use crate::spectrum::gamut::Chromaticities;
use crate::{Error, Result};

/// The largest finite half float (IEEE 754 binary16): brighter samples of a 16-bit file are
/// clamped to it.
pub const HALF_MAX: f32 = 65504.0;

fn exr_error(path: &Path, e: exr::error::Error, writing: bool) -> Error {
    use exr::error::Error as E;
    let verb = if writing {
        "cannot write EXR"
    } else {
        "cannot read EXR"
    };
    match e {
        E::Io(io) => io_error(path, &io, writing),
        E::NotSupported(s) => file_error(path, format!("{verb}: not supported: {s}")),
        E::Invalid(s) => file_error(path, format!("{verb}: invalid: {s}")),
        E::Aborted => file_error(path, format!("{verb}: aborted")),
    }
}

/// Writes an OpenEXR file with R, G, B channels at `precision` (ZIP-compressed
/// scanlines, lossless for the chosen precision).
pub fn write_exr(
    path: impl AsRef<Path>,
    image: &ImageRgbF32,
    precision: ExrPrecision,
) -> Result<()> {
    write_exr_with_attributes(path, image, precision, &[])
}

/// As [`write_exr`], also storing `attributes` as string (`text`) attributes of the
/// layer header (e.g. `("firmament:preset", "clear")`). Names and values must be
/// Latin-1 text.
pub fn write_exr_with_attributes(
    path: impl AsRef<Path>,
    image: &ImageRgbF32,
    precision: ExrPrecision,
    attributes: &[(&str, &str)],
) -> Result<()> {
    write_exr_in(path, image, precision, attributes, None)
}

/// As [`write_exr_with_attributes`], with the image's primaries and white in the header's
/// standard `chromaticities` attribute when given (the colour space of the samples:
/// Rec. 2020, ACEScg; readers take Rec. 709 without it).
pub fn write_exr_in(
    path: impl AsRef<Path>,
    image: &ImageRgbF32,
    precision: ExrPrecision,
    attributes: &[(&str, &str)],
    chromaticities: Option<&Chromaticities>,
) -> Result<()> {
    use exr::prelude::*;
    let path = path.as_ref();
    image.check(path)?;
    let mut layer_attributes = LayerAttributes::default();
    for &(name, value) in attributes {
        let (Some(n), Some(v)) = (Text::new_or_none(name), Text::new_or_none(value)) else {
            return Err(file_error(
                path,
                format!("cannot write EXR attribute `{name}`: not Latin-1 text"),
            ));
        };
        if name.is_empty() {
            return Err(file_error(
                path,
                "cannot write EXR attribute with an empty name",
            ));
        }
        layer_attributes.other.insert(n, AttributeValue::Text(v));
    }
    let size = (image.width, image.height);
    let w = image.width;
    let px = |p: Vec2<usize>| image.data[p.y() * w + p.x()];
    let mut image_attributes = ImageAttributes::new(IntegerBounds::from_dimensions(size));
    image_attributes.chromaticities = chromaticities.map(|c| {
        let v = |[x, y]: [f64; 2]| Vec2(x as f32, y as f32);
        exr::meta::attribute::Chromaticities {
            red: v(c.red),
            green: v(c.green),
            blue: v(c.blue),
            white: v(c.white),
        }
    });
    write_atomic(path, |out| {
        let result = match precision {
            ExrPrecision::F32 => {
                let channels = SpecificChannels::rgb(|p: Vec2<usize>| {
                    let [r, g, b] = px(p);
                    (r, g, b)
                });
                Image::new(
                    image_attributes.clone(),
                    Layer::new(
                        size,
                        layer_attributes.clone(),
                        Encoding::SMALL_LOSSLESS,
                        channels,
                    ),
                )
                .write()
                .to_buffered(out)
            }
            ExrPrecision::F16 => {
                // Half floats end at 65504: brighter samples (the sun's disk, a star's
                // pixel) are clamped there rather than written as infinity.
                let half = |v: f32| f16::from_f32(v.min(HALF_MAX));
                let channels = SpecificChannels::rgb(|p: Vec2<usize>| {
                    let [r, g, b] = px(p);
                    (half(r), half(g), half(b))
                });
                Image::new(
                    image_attributes.clone(),
                    Layer::new(
                        size,
                        layer_attributes.clone(),
                        Encoding::SMALL_LOSSLESS,
                        channels,
                    ),
                )
                .write()
                .to_buffered(out)
            }
        };
        result.map_err(|e| exr_error(path, e, true))
    })
}

/// Reads the R, G, B channels of the first RGB(A) layer of an OpenEXR file (half,
/// float or uint samples, converted to `f32`; alpha is ignored).
pub fn read_exr(path: impl AsRef<Path>) -> Result<ImageRgbF32> {
    use exr::prelude::*;
    let path = path.as_ref();
    // Open ourselves first for a clear "does not exist" message.
    File::open(path).map_err(|e| io_error(path, &e, false))?;
    let image = read_first_rgba_layer_from_file(
        path,
        |resolution: Vec2<usize>, _| ImageRgbF32::new(resolution.width(), resolution.height()),
        |img: &mut ImageRgbF32, p: Vec2<usize>, (r, g, b, _a): (f32, f32, f32, f32)| {
            let w = img.width;
            img.data[p.y() * w + p.x()] = [r, g, b];
        },
    )
    .map_err(|e| exr_error(path, e, false))?;
    Ok(image.layer_data.channel_data.pixels)
}

/// The `chromaticities` attribute of an OpenEXR file's first header, if it has one.
pub fn read_exr_chromaticities(path: impl AsRef<Path>) -> Result<Option<Chromaticities>> {
    let path = path.as_ref();
    File::open(path).map_err(|e| io_error(path, &e, false))?;
    let meta =
        exr::meta::MetaData::read_from_file(path, false).map_err(|e| exr_error(path, e, false))?;
    Ok(meta.headers.first().and_then(|h| {
        h.shared_attributes.chromaticities.map(|c| {
            let v = |p: exr::math::Vec2<f32>| [p.0 as f64, p.1 as f64];
            Chromaticities {
                red: v(c.red),
                green: v(c.green),
                blue: v(c.blue),
                white: v(c.white),
            }
        })
    }))
}

/// Reads the string (`text`) attributes of an OpenEXR file's first header (layer and
/// image attributes other than the standard ones), sorted by name.
pub fn read_exr_text_attributes(path: impl AsRef<Path>) -> Result<Vec<(String, String)>> {
    use exr::meta::attribute::AttributeValue;
    let path = path.as_ref();
    File::open(path).map_err(|e| io_error(path, &e, false))?;
    let meta =
        exr::meta::MetaData::read_from_file(path, false).map_err(|e| exr_error(path, e, false))?;
    let mut out = Vec::new();
    if let Some(header) = meta.headers.first() {
        for (k, v) in header
            .own_attributes
            .other
            .iter()
            .chain(header.shared_attributes.other.iter())
        {
            if let AttributeValue::Text(t) = v {
                out.push((k.to_string(), t.to_string()));
            }
        }
    }
    out.sort();
    Ok(out)
}

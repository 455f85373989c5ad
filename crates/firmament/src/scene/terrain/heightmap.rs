//! Heights from a user's 16-bit greyscale PNG: 0 is the lowest height of the range given,
//! 65535 the highest; the image's top row is north, its left column west, pixels square.

use std::path::Path;

use super::grid::Grid;
use crate::{Error, Result};

/// The heights of the PNG at `path`, `extent_m` wide (west to east) and centred at
/// `centre_m` (east, north of the observer), from `range_m[0]` (black) to `range_m[1]`
/// (white). Errors name the field `terrain.heightmap`.
pub fn read_heightmap(
    path: &Path,
    extent_m: f64,
    range_m: [f64; 2],
    centre_m: [f64; 2],
) -> Result<Grid> {
    let img =
        crate::io::png::decode_png_input(path, "terrain.heightmap", "a 16-bit greyscale PNG file")?;
    let image::DynamicImage::ImageLuma16(img) = img else {
        return Err(Error::invalid(
            "terrain.heightmap",
            format!("{} ({:?})", path.display(), img.color()),
            "a 16-bit greyscale PNG (colour type L16)",
        ));
    };
    let (w, h) = (img.width() as usize, img.height() as usize);
    if w < 2 || h < 2 {
        return Err(Error::invalid(
            "terrain.heightmap",
            format!("{w}×{h} pixels"),
            "at least 2×2 pixels",
        ));
    }
    let spacing = extent_m / (w - 1) as f64;
    let depth = spacing * (h - 1) as f64;
    let mut values = vec![0.0f32; w * h];
    for (j, row) in values.chunks_mut(w).enumerate() {
        // Grid row 0 is the south edge: the image's bottom row.
        let y = (h - 1 - j) as u32;
        for (i, v) in row.iter_mut().enumerate() {
            let p = img.get_pixel(i as u32, y).0[0] as f64 / 65535.0;
            *v = (range_m[0] + p * (range_m[1] - range_m[0])) as f32;
        }
    }
    Ok(Grid {
        nx: w,
        ny: h,
        origin: [centre_m[0] - 0.5 * extent_m, centre_m[1] - 0.5 * depth],
        spacing_m: spacing,
        axis: [1.0, 0.0],
        values,
    })
}

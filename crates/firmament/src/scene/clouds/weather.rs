//! The weather map: a world-space texture that tiles over the planet (Hillaire 2016, seed
//! "Cloud distribution and density"; Schneider 2015) and says, at each place, how likely
//! cloud is (the weather value w ∈ [0, 1], red), which type it is (t ∈ [0, 1], green: 0
//! stratus … 1 cumulus) and how dark with precipitation (p ∈ [0, 1], blue).
//!
//! The procedural map is tileable gradient-noise fBm, histogram-equalised so that w is
//! uniform on [0, 1] (its mean ½ leaves a layer's mean coverage as set). A user's PNG gives
//! the three channels directly (8 or 16 bits; grey: w only).
//!
//! Every map also carries a smooth warp (two more channels, procedural): an offset of the
//! 3D noise's coordinates, up to [`WARP_TILES`] of the noise's tile, varying over a third
//! of the weather's tile, so that the noise's repetition never lines up (a domain warp,
//! Perlin 1985 §5 "turbulence" used as a displacement).

use std::path::Path;

use super::noise::perlin2;
use super::profile::CloudKind;
use crate::math::fast::floor;
use crate::{Error, Result};

/// Texels per side of the procedural map's tile.
const PROCEDURAL_TEXELS: usize = 256;
/// Lattice cells of the procedural coverage's lowest octave across a tile.
const COVERAGE_CELLS: u32 = 4;
/// Octaves of the procedural coverage.
const COVERAGE_OCTAVES: u32 = 5;
/// The warp's amplitude in tiles of the 3D noise.
pub const WARP_TILES: f64 = 0.35;
/// Lattice cells of the warp across the weather's tile.
const WARP_CELLS: u32 = 3;

/// One tile of weather, bilinearly sampled and repeated every `tile_m` metres.
///
/// Warp: see the module's notes.
#[derive(Clone, Debug)]
pub struct WeatherMap {
    /// Texels per side (x) and (y).
    pub width: usize,
    /// Texels in y.
    pub height: usize,
    /// [w, t, p, warp x, warp y] per texel (the warp in tiles of the 3D noise), row-major
    /// from the tile's south-west corner.
    pub texels: Vec<[f32; 5]>,
    /// The tile's side, m.
    pub tile_m: f64,
}

impl WeatherMap {
    /// The procedural map of `kind` with `seed`: w equalised to uniform, t around the kind's
    /// default type, p = 0.
    pub fn procedural(kind: CloudKind, seed: u32, tile_m: f64) -> WeatherMap {
        let n = PROCEDURAL_TEXELS;
        let (t_mean, t_spread) = kind.default_type();
        let mut raw = Vec::with_capacity(n * n);
        let mut types = Vec::with_capacity(n * n);
        for j in 0..n {
            for i in 0..n {
                let (x, y) = ((i as f64 + 0.5) / n as f64, (j as f64 + 0.5) / n as f64);
                let (mut v, mut a, mut norm) = (0.0, 1.0, 0.0);
                for o in 0..COVERAGE_OCTAVES {
                    let f = (COVERAGE_CELLS << o) as f64;
                    v += a * perlin2(x * f, y * f, COVERAGE_CELLS << o, seed.wrapping_add(o));
                    norm += a;
                    a *= 0.55;
                }
                raw.push(v / norm);
                let t = perlin2(x * 2.0, y * 2.0, 2, seed ^ 0x68e3_1da4);
                types.push((t_mean + t_spread * 1.5 * t).clamp(0.0, 1.0));
            }
        }
        // Histogram equalisation: each texel's w is its rank among all.
        let mut order: Vec<usize> = (0..raw.len()).collect();
        order.sort_by(|&a, &b| raw[a].total_cmp(&raw[b]));
        let mut texels = vec![[0.0f32; 5]; raw.len()];
        for (rank, &idx) in order.iter().enumerate() {
            texels[idx][..3].copy_from_slice(&[
                ((rank as f64 + 0.5) / raw.len() as f64) as f32,
                types[idx] as f32,
                0.0,
            ]);
        }
        let mut map = WeatherMap {
            width: n,
            height: n,
            texels,
            tile_m,
        };
        map.add_warp(seed);
        map
    }

    /// A map from a PNG at `path` (red w, green t, blue p; a grey image gives w and leaves t
    /// to the kind's default), tiling every `tile_m` metres. `field` names the setting in
    /// errors.
    pub fn from_png(path: &Path, kind: CloudKind, tile_m: f64, field: &str) -> Result<WeatherMap> {
        let bad = |why: String| Error::invalid(field, path.display(), why);
        let is_png = path
            .extension()
            .and_then(|e| e.to_str())
            .is_some_and(|e| e.eq_ignore_ascii_case("png"));
        if !is_png {
            return Err(bad(
                "a PNG file (.png): red coverage, green type, blue precipitation".into(),
            ));
        }
        let image = image::ImageReader::open(path)
            .map_err(|e| bad(format!("a readable PNG file ({e})")))?
            .with_guessed_format()
            .map_err(|e| bad(format!("a readable PNG file ({e})")))?;
        if image.format() != Some(image::ImageFormat::Png) {
            return Err(bad("a PNG file (the contents are not PNG)".into()));
        }
        let image = image
            .decode()
            .map_err(|e| bad(format!("a decodable PNG file ({e})")))?;
        let (width, height) = (image.width() as usize, image.height() as usize);
        if width < 2 || height < 2 {
            return Err(bad(format!(
                "a PNG of at least 2×2 texels, not {width}×{height}"
            )));
        }
        let grey = !image.color().has_color();
        let rgb = image.to_rgb32f();
        let seed = 0;
        let t_default = kind.default_type().0 as f32;
        // PNG rows run top to bottom; the map's from south to north.
        let mut texels = Vec::with_capacity(width * height);
        for j in (0..height).rev() {
            for i in 0..width {
                let px = rgb.get_pixel(i as u32, j as u32).0;
                texels.push(if grey {
                    [px[0], t_default, 0.0, 0.0, 0.0]
                } else {
                    [px[0], px[1], px[2], 0.0, 0.0]
                });
            }
        }
        let mut map = WeatherMap {
            width,
            height,
            texels,
            tile_m,
        };
        map.add_warp(seed);
        Ok(map)
    }

    /// Fill the warp channels: two tileable gradient noises of [`WARP_CELLS`] cells (two
    /// octaves), scaled to ±[`WARP_TILES`].
    fn add_warp(&mut self, seed: u32) {
        let (w, h) = (self.width, self.height);
        for j in 0..h {
            for i in 0..w {
                let (x, y) = ((i as f64 + 0.5) / w as f64, (j as f64 + 0.5) / h as f64);
                let c = WARP_CELLS as f64;
                let field = |salt: u32| {
                    let a = perlin2(x * c, y * c, WARP_CELLS, salt);
                    let b = perlin2(2.0 * x * c, 2.0 * y * c, 2 * WARP_CELLS, salt ^ 1);
                    (WARP_TILES * 1.4 * (a + 0.5 * b) / 1.5).clamp(-WARP_TILES, WARP_TILES)
                };
                let t = &mut self.texels[j * w + i];
                t[3] = field(seed ^ 0x7761_7270) as f32;
                t[4] = field(seed ^ 0x7761_7271) as f32;
            }
        }
    }

    /// [w, t, p, warp x, warp y] at planar coordinates (x, y) (m), bilinear, repeating.
    #[inline]
    pub fn sample(&self, x: f64, y: f64) -> [f64; 5] {
        let cell = self.cell(x, y);
        std::array::from_fn(|k| self.channel(&cell, k))
    }

    /// The four texels around planar coordinates (x, y) (m) and the bilinear weights, for
    /// [`WeatherMap::channel`]: a sample's channels read one at a time, so that a caller
    /// that finds no room for cloud from w and t reads no more.
    #[inline]
    pub fn cell(&self, x: f64, y: f64) -> WeatherCell {
        let (w, h) = (self.width, self.height);
        let u = x / self.tile_m;
        let v = y / self.tile_m;
        // Into [0, 1) tiles, then texels (centres at ½).
        let fx = (u - floor(u)) * w as f64 - 0.5;
        let fy = (v - floor(v)) * h as f64 - 0.5;
        let (cx, cy) = (floor(fx), floor(fy));
        let (tx, ty) = (fx - cx, fy - cy);
        let i0 = if cx < 0.0 { w - 1 } else { cx as usize };
        let j0 = if cy < 0.0 { h - 1 } else { cy as usize };
        let i1 = if i0 + 1 == w { 0 } else { i0 + 1 };
        let j1 = if j0 + 1 == h { 0 } else { j0 + 1 };
        WeatherCell {
            texels: [j0 * w + i0, j0 * w + i1, j1 * w + i0, j1 * w + i1],
            tx,
            ty,
        }
    }

    /// Channel `k` (0 w, 1 t, 2 p, 3–4 the warp) of the bilinear sample at `cell`.
    #[inline]
    pub fn channel(&self, cell: &WeatherCell, k: usize) -> f64 {
        let [i, j, m, n] = cell.texels;
        let (a, b) = (self.texels[i][k] as f64, self.texels[j][k] as f64);
        let (c, d) = (self.texels[m][k] as f64, self.texels[n][k] as f64);
        let lo = a + (b - a) * cell.tx;
        let hi = c + (d - c) * cell.tx;
        lo + (hi - lo) * cell.ty
    }
}

/// Where a bilinear sample of a [`WeatherMap`] falls: its four texels' indices (south-west,
/// south-east, north-west, north-east) and the weights along x and y.
#[derive(Clone, Copy, Debug)]
pub struct WeatherCell {
    texels: [usize; 4],
    tx: f64,
    ty: f64,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn procedural_weather_is_uniform_and_tiles() {
        let map = WeatherMap::procedural(CloudKind::Cumulus, 1, 10_000.0);
        // Equalised: the fraction of texels above 1 − c is c.
        for c in [0.1, 0.3, 0.5, 0.8] {
            let above = map.texels.iter().filter(|t| t[0] as f64 > 1.0 - c).count();
            let fraction = above as f64 / map.texels.len() as f64;
            assert!((fraction - c).abs() < 0.005, "{c}: {fraction}");
        }
        // Tiles: one tile over is the same, and across the seam it continues smoothly.
        let a = map.sample(1234.0, 5678.0);
        let b = map.sample(1234.0 + 10_000.0, 5678.0 - 20_000.0);
        assert!(
            a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-9),
            "{a:?} {b:?}"
        );
        let step = 10_000.0 / 256.0;
        let seam = (map.sample(-0.5 * step, 3000.0)[0] - map.sample(0.5 * step, 3000.0)[0]).abs();
        assert!(seam < 0.1, "seam {seam}");
        assert!(map.texels.iter().all(|t| (0.0..=1.0).contains(&t[1])));
    }

    #[test]
    fn weather_png_of_the_wrong_format_is_refused() {
        let dir = std::env::temp_dir().join(format!("firmament-weather-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let not_png = dir.join("weather.png");
        std::fs::write(&not_png, b"not an image").unwrap();
        let err = WeatherMap::from_png(&not_png, CloudKind::Cumulus, 1e4, "clouds[0].weather")
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("clouds[0].weather") && err.contains("PNG"),
            "{err}"
        );
        let jpeg_name = dir.join("weather.jpg");
        std::fs::write(&jpeg_name, b"x").unwrap();
        assert!(WeatherMap::from_png(&jpeg_name, CloudKind::Cumulus, 1e4, "w").is_err());
        // A real 3×2 RGB PNG reads, rows flipped to south-first.
        let good = dir.join("good.png");
        let img = image::RgbImage::from_fn(3, 2, |x, y| {
            image::Rgb([(x * 100) as u8, (y * 255) as u8, 0])
        });
        img.save(&good).unwrap();
        let map = WeatherMap::from_png(&good, CloudKind::Cumulus, 1e4, "w").unwrap();
        assert_eq!((map.width, map.height), (3, 2));
        assert_eq!(map.texels[0][1], 1.0); // the bottom row (y = 1 in the PNG) is south
        assert_eq!(map.texels[3][1], 0.0);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

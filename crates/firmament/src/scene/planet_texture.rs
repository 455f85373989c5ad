//! The planet's surface map as a texture: [`PlanetSurface::weights`] at the centres of an
//! equirectangular grid (what the GPU samples bilinearly, `firmament_gpu::planet`), and a
//! disk cache of a procedural map's grid beside the tables (`planet-<key>.firmplanet`; the
//! weights depend on the map alone, not on the observer's place or the wavelengths).

use std::io::Write;
use std::path::Path;

use super::planet::{PlanetSurface, SurfaceMap};
use crate::atmosphere::model::fnv1a;
use crate::io::write_atomic;
use crate::math::Vec3;
use crate::Result;

/// Width of a procedural map's texture ([`PlanetSurface::texture_size`]).
pub const PROCEDURAL_TEXTURE_WIDTH: usize = 2048;

/// The cache file's first bytes; the key's version (a change to the procedural map's code
/// must change it).
const MAGIC: &[u8; 8] = b"FIRMPLW1";
const GENERATOR_VERSION: u32 = 1;

impl PlanetSurface {
    /// The size (width, height) of the equirectangular grid [`PlanetSurface::weight_texture`]
    /// fills by default: an image's own; for a procedural map 2048 × 1024 (20 km per texel at
    /// the equator of an Earth-sized planet, finer than the continents' smallest noise cells,
    /// about 30 km).
    pub fn texture_size(&self) -> (usize, usize) {
        match &self.map {
            SurfaceMap::Procedural { .. } => {
                (PROCEDURAL_TEXTURE_WIDTH, PROCEDURAL_TEXTURE_WIDTH / 2)
            }
            SurfaceMap::Image { width, height, .. } => (*width, *height),
        }
    }

    /// The first four of [`PlanetSurface::weights`] at the centres of a `width` × `height`
    /// equirectangular grid (row 0 at 90° N, column 0 at 180° W, as an image map), row-major;
    /// the fifth weight is 1 minus their sum for a procedural map and 0 for an image. At an
    /// image's own size the texels are its pixels.
    pub fn weight_texture(&self, width: usize, height: usize) -> Vec<[f32; 4]> {
        use rayon::prelude::*;
        let mut texels = vec![[0.0f32; 4]; width * height];
        texels
            .par_chunks_mut(width.max(1))
            .enumerate()
            .for_each(|(y, row)| {
                let lat = (0.5 - (y as f64 + 0.5) / height as f64) * std::f64::consts::PI;
                for (x, t) in row.iter_mut().enumerate() {
                    let lon = ((x as f64 + 0.5) / width as f64 - 0.5) * std::f64::consts::TAU;
                    let d = Vec3::new(lat.cos() * lon.cos(), lat.cos() * lon.sin(), lat.sin());
                    let w = self.weights(d);
                    *t = [w[0] as f32, w[1] as f32, w[2] as f32, w[3] as f32];
                }
            });
        texels
    }

    /// [`PlanetSurface::weight_texture`] at [`PlanetSurface::texture_size`], a procedural
    /// map's read from the cache directory `dir` when there (or computed and written there:
    /// 1.6 s on 2 cores against a few tens of ms to read); the texels and whether they came
    /// from the cache. Texels pass through half floats (what the GPU's texture holds).
    pub fn cached_weight_texture(&self, dir: Option<&Path>) -> Result<(Vec<[f32; 4]>, bool)> {
        let (w, h) = self.texture_size();
        let (Some(dir), SurfaceMap::Procedural { seed, .. }) = (dir, &self.map) else {
            return Ok((self.weight_texture(w, h), false));
        };
        let key = fnv1a(
            format!(
                "{GENERATOR_VERSION} procedural {seed} {:016x} {w} {h}",
                self.sea_level.to_bits()
            )
            .as_bytes(),
        );
        let path = dir.join(format!("planet-{key:016x}.firmplanet"));
        if let Some(texels) = read(&path, w, h) {
            return Ok((texels, true));
        }
        let halves: Vec<u16> = (self.weight_texture(w, h).iter())
            .flat_map(|t| t.map(|v| half::f16::from_f32(v).to_bits()))
            .collect();
        std::fs::create_dir_all(dir)?;
        write_atomic(&path, |f| {
            f.write_all(MAGIC)?;
            f.write_all(&(w as u64).to_le_bytes())?;
            f.write_all(&(h as u64).to_le_bytes())?;
            let bytes: Vec<u8> = halves.iter().flat_map(|v| v.to_le_bytes()).collect();
            f.write_all(&bytes)?;
            Ok(())
        })?;
        Ok((texels_of(&halves), false))
    }
}

/// Texels from half-float bits, four a texel.
fn texels_of(halves: &[u16]) -> Vec<[f32; 4]> {
    halves
        .chunks_exact(4)
        .map(|c| [0, 1, 2, 3].map(|k| half::f16::from_bits(c[k]).to_f32()))
        .collect()
}

/// A whole cached texture of `w` × `h`, or None (missing, short, another size).
fn read(path: &Path, w: usize, h: usize) -> Option<Vec<[f32; 4]>> {
    let bytes = std::fs::read(path).ok()?;
    if bytes.len() != 24 + 8 * w * h || &bytes[..8] != MAGIC {
        return None;
    }
    let size = |at: usize| u64::from_le_bytes(bytes[at..at + 8].try_into().expect("8 bytes"));
    if (size(8), size(16)) != (w as u64, h as u64) {
        return None;
    }
    let halves: Vec<u16> = bytes[24..]
        .chunks_exact(2)
        .map(|c| u16::from_le_bytes([c[0], c[1]]))
        .collect();
    Some(texels_of(&halves))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::lattice::sphere_directions;
    use crate::scene::planet::tests::earth;
    use crate::scene::planet::BASIS;

    /// The GPU's surface map: the procedural Earth's weights baked at the default texture
    /// size and interpolated bilinearly between texel centres (as render/planet.wgsl does),
    /// against the albedo evaluated at the point, over 20 000 evenly spread points. Coasts
    /// inside a texel blend sea and land; elsewhere the weights are smooth.
    #[test]
    fn the_baked_procedural_map_interpolates_the_albedo() {
        let p = earth();
        let (w, h) = p.texture_size();
        let started = std::time::Instant::now();
        let texels = p.weight_texture(w, h);
        eprintln!("baked in {:.2} s", started.elapsed().as_secs_f64());
        let basis = p.basis();
        let k = 1; // 550 nm
        let (mut errors, mut over) = (Vec::new(), 0);
        let points = sphere_directions(20_000);
        for &d in &points {
            let lat = d.z.asin();
            let lon = d.y.atan2(d.x);
            let x = (lon / std::f64::consts::TAU + 0.5) * w as f64 - 0.5;
            let y =
                ((0.5 - lat / std::f64::consts::PI) * h as f64 - 0.5).clamp(0.0, (h - 1) as f64);
            let (x0, y0) = (x.floor(), y.floor());
            let (fx, fy) = (x - x0, y - y0);
            let xi = |dx: i64| ((x0 as i64 + dx).rem_euclid(w as i64)) as usize;
            let yi = |dy: usize| (y0 as usize + dy).min(h - 1);
            let mut wt = [0.0; 4];
            for (dx, dy, f) in [
                (0, 0, (1.0 - fx) * (1.0 - fy)),
                (1, 0, fx * (1.0 - fy)),
                (0, 1, (1.0 - fx) * fy),
                (1, 1, fx * fy),
            ] {
                let t = texels[yi(dy) * w + xi(dx)];
                for j in 0..4 {
                    wt[j] += f * t[j] as f64;
                }
            }
            let fifth = 1.0 - wt.iter().sum::<f64>();
            let baked = (0..4).map(|j| wt[j] * basis[j][k]).sum::<f64>() + fifth * basis[4][k];
            let exact: f64 = (0..BASIS).map(|j| p.weights(d)[j] * basis[j][k]).sum();
            let e = (baked / exact - 1.0).abs();
            over += usize::from(e > 0.05);
            errors.push(e);
        }
        errors.sort_by(f64::total_cmp);
        let mean = errors.iter().sum::<f64>() / errors.len() as f64;
        let median = errors[errors.len() / 2];
        let p95 = errors[errors.len() * 95 / 100];
        eprintln!(
            "procedural map at {w}×{h}, albedo at 550 nm, 20 000 points: mean |e| {:.2} %, median {:.3} %, p95 {:.2} %, {:.1} % of points over 5 %",
            100.0 * mean,
            100.0 * median,
            100.0 * p95,
            100.0 * over as f64 / errors.len() as f64
        );
        assert!(
            mean < 0.02 && over * 100 < 3 * errors.len(),
            "mean {mean}, {over} points over 5 %"
        );
    }

    #[test]
    fn the_cache_returns_the_baked_texture_in_half_floats() {
        let dir = std::env::temp_dir().join(format!("firmament-planet-{}", std::process::id()));
        let p = earth();
        let (a, hit_a) = p.cached_weight_texture(Some(&dir)).unwrap();
        let (b, hit_b) = p.cached_weight_texture(Some(&dir)).unwrap();
        assert!(!hit_a && hit_b);
        assert_eq!(a, b);
        let (w, h) = p.texture_size();
        let fresh = p.weight_texture(w, h);
        let worst = (a.iter().zip(&fresh))
            .flat_map(|(x, y)| (0..4).map(move |k| (x[k] - y[k]).abs()))
            .fold(0.0f32, f32::max);
        assert!(worst <= 2.5e-4, "half floats of weights in [0, 1]: {worst}");
        // Another ocean fraction is another file.
        let other = PlanetSurface::new(
            6_360_000.0,
            SurfaceMap::Procedural {
                seed: 3,
                ocean_fraction: 0.5,
            },
            0.0,
            0.0,
            &[550.0],
            None,
        );
        assert!(!other.cached_weight_texture(Some(&dir)).unwrap().1);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

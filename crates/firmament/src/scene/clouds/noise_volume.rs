//! The clouds' two tileable 3D noise textures (Schneider 2015; Hillaire 2016 §5.4): the base
//! shape (Perlin–Worley, 128³ by default) and the erosion detail (Worley fBm, 32³), made by
//! the program from [`super::noise`], sampled trilinearly with wrap-around, and kept on disk
//! beside the tables (`noise-<key>.firmnoise`, the key over everything that determines the
//! texels) so that a second run reads them instead of computing them again.

use std::io::Write;
use std::path::{Path, PathBuf};

use rayon::prelude::*;

use super::noise;
use crate::atmosphere::model::fnv1a;
use crate::io::write_atomic;
use crate::math::fast::floor;
use crate::Result;

/// Which texture.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum NoiseKind {
    /// Perlin–Worley ([`noise::perlin_worley`]), 8 lattice cells across the tile,
    /// histogram-equalised to uniform on [0, 1], so that the fraction of texels above 1 − c
    /// is c (a layer's coverage).
    BaseShape,
    /// Worley fBm ([`noise::worley_fbm`], frequencies 1, 2, 4), 4 cells across the tile.
    Erosion,
}

impl NoiseKind {
    /// The lattice cells of the lowest octave across one tile: 8 puffs across the base
    /// shape's tile so that its repetition is less plain, 4 for the erosion detail.
    fn cells_per_tile(self) -> u32 {
        match self {
            NoiseKind::BaseShape => 8,
            NoiseKind::Erosion => 4,
        }
    }
}
/// Bumped whenever the generator changes what it writes (part of the cache key).
const GENERATOR_VERSION: u32 = 3;
/// File magic.
const MAGIC: &[u8; 8] = b"FIRMNOI1";

/// A cube of `size`³ texels, one tile of a periodic noise; texel (i, j, k) sits at
/// ((i + ½)/size, (j + ½)/size, (k + ½)/size) of the tile.
#[derive(Clone, Debug, PartialEq)]
pub struct NoiseVolume {
    /// Texels per side.
    pub size: usize,
    /// The texels, x fastest, in [0, 1].
    pub data: Vec<f32>,
}

impl NoiseVolume {
    /// Compute the texture (all cores).
    pub fn generate(kind: NoiseKind, size: usize, salt: u32) -> NoiseVolume {
        let f = match kind {
            NoiseKind::BaseShape => noise::perlin_worley,
            NoiseKind::Erosion => noise::worley_fbm,
        };
        let cells = kind.cells_per_tile();
        let scale = cells as f64 / size as f64;
        let mut data = vec![0.0f32; size * size * size];
        data.par_chunks_mut(size * size)
            .enumerate()
            .for_each(|(k, slab)| {
                for (idx, texel) in slab.iter_mut().enumerate() {
                    let (i, j) = (idx % size, idx / size);
                    let p = [i, j, k].map(|c| (c as f64 + 0.5) * scale);
                    *texel = f(p, cells, salt) as f32;
                }
            });
        if kind == NoiseKind::BaseShape {
            equalise(&mut data);
        }
        NoiseVolume { size, data }
    }

    /// The texture from the cache directory `dir` if a whole file holds it, else computed and
    /// (when `dir` is given) written there atomically; the bool says whether it was read.
    pub fn cached(
        kind: NoiseKind,
        size: usize,
        salt: u32,
        dir: Option<&Path>,
    ) -> Result<(NoiseVolume, bool)> {
        let Some(dir) = dir else {
            return Ok((NoiseVolume::generate(kind, size, salt), false));
        };
        let path = cache_path(dir, kind, size, salt);
        if let Some(v) = read(&path, size) {
            return Ok((v, true));
        }
        let v = NoiseVolume::generate(kind, size, salt);
        std::fs::create_dir_all(dir)?;
        let mut bytes = Vec::with_capacity(16 + 4 * v.data.len());
        bytes.extend_from_slice(MAGIC);
        bytes.extend_from_slice(&(size as u64).to_le_bytes());
        for t in &v.data {
            bytes.extend_from_slice(&t.to_le_bytes());
        }
        write_atomic(&path, |w| {
            w.write_all(&bytes)?;
            Ok(())
        })?;
        Ok((v, false))
    }

    /// The texel (i, j, k).
    #[cfg(test)]
    fn texel(&self, i: usize, j: usize, k: usize) -> f64 {
        self.data[(k * self.size + j) * self.size + i] as f64
    }

    /// Trilinear sample at `p` in tiles (1 tile = the whole texture), repeating.
    #[inline]
    pub fn sample(&self, p: [f64; 3]) -> f64 {
        let n = self.size;
        let mut i0 = [0usize; 3];
        let mut i1 = [0usize; 3];
        let mut f = [0.0f64; 3];
        for a in 0..3 {
            let x = (p[a] - floor(p[a])) * n as f64 - 0.5;
            let c = floor(x);
            f[a] = x - c;
            let c = if c < 0.0 { n - 1 } else { c as usize };
            i0[a] = c;
            i1[a] = if c + 1 == n { 0 } else { c + 1 };
        }
        let (row00, row10) = ((i0[2] * n + i0[1]) * n, (i0[2] * n + i1[1]) * n);
        let (row01, row11) = ((i1[2] * n + i0[1]) * n, (i1[2] * n + i1[1]) * n);
        let d = &self.data;
        let lerp = |a: f32, b: f32, t: f64| a as f64 + (b as f64 - a as f64) * t;
        let x00 = lerp(d[row00 + i0[0]], d[row00 + i1[0]], f[0]);
        let x10 = lerp(d[row10 + i0[0]], d[row10 + i1[0]], f[0]);
        let x01 = lerp(d[row01 + i0[0]], d[row01 + i1[0]], f[0]);
        let x11 = lerp(d[row11 + i0[0]], d[row11 + i1[0]], f[0]);
        let y0 = x00 + (x10 - x00) * f[1];
        let y1 = x01 + (x11 - x01) * f[1];
        y0 + (y1 - y0) * f[2]
    }

    /// Mean and standard deviation of the texels.
    pub fn statistics(&self) -> (f64, f64) {
        let n = self.data.len() as f64;
        let mean = self.data.iter().map(|&v| v as f64).sum::<f64>() / n;
        let var = self
            .data
            .iter()
            .map(|&v| (v as f64 - mean).powi(2))
            .sum::<f64>()
            / n;
        (mean, var.sqrt())
    }
}

/// Replace each value by its rank among all, scaled to (0, 1): uniform on [0, 1].
fn equalise(data: &mut [f32]) {
    let mut order: Vec<u32> = (0..data.len() as u32).collect();
    order.par_sort_unstable_by(|&a, &b| data[a as usize].total_cmp(&data[b as usize]));
    let n = data.len() as f64;
    for (rank, &i) in order.iter().enumerate() {
        data[i as usize] = ((rank as f64 + 0.5) / n) as f32;
    }
}

/// The cache file of a texture.
fn cache_path(dir: &Path, kind: NoiseKind, size: usize, salt: u32) -> PathBuf {
    let key = fnv1a(
        format!(
            "{GENERATOR_VERSION} {kind:?} {size} {salt} {}",
            kind.cells_per_tile()
        )
        .as_bytes(),
    );
    dir.join(format!("noise-{key:016x}.firmnoise"))
}

/// A whole cached texture of `size`, or None (missing, short, other size).
fn read(path: &Path, size: usize) -> Option<NoiseVolume> {
    let bytes = std::fs::read(path).ok()?;
    let count = size * size * size;
    if bytes.len() != 16 + 4 * count || &bytes[..8] != MAGIC {
        return None;
    }
    if u64::from_le_bytes(bytes[8..16].try_into().ok()?) != size as u64 {
        return None;
    }
    let data = bytes[16..]
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect();
    Some(NoiseVolume { size, data })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn volumes_tile_exactly_and_have_the_documented_statistics() {
        for (kind, size, mean_range, min_std) in [
            (NoiseKind::BaseShape, 24, 0.499..0.501, 0.28),
            (NoiseKind::Erosion, 16, 0.25..0.65, 0.08),
        ] {
            let v = NoiseVolume::generate(kind, size, 3);
            // Opposite faces of the tile continue each other: sampling across the seam equals
            // sampling the same point one tile over, and a face's texels are as close to the
            // opposite face's as neighbouring texels inside are to each other.
            for &(x, y, z) in &[(0.999, 0.2, 0.7), (0.01, 0.5, 0.995), (0.4, 0.0, 0.3)] {
                let a = v.sample([x, y, z]);
                let b = v.sample([x + 1.0, y - 1.0, z + 3.0]);
                assert!((a - b).abs() < 1e-12);
            }
            let n = size;
            let (mut seam, mut inside) = (0.0, 0.0);
            for k in 0..n {
                for j in 0..n {
                    seam += (v.texel(n - 1, j, k) - v.texel(0, j, k)).abs();
                    inside += (v.texel(n / 2, j, k) - v.texel(n / 2 - 1, j, k)).abs();
                }
            }
            assert!(seam < 1.5 * inside, "{kind:?}: seam {seam} inside {inside}");
            let (mean, std) = v.statistics();
            assert!(mean_range.contains(&mean), "{kind:?}: mean {mean}");
            assert!(std > min_std, "{kind:?}: std {std}");
            assert!(v.data.iter().all(|t| (0.0..=1.0).contains(t)));
        }
    }

    #[test]
    fn the_cache_returns_what_was_computed() {
        let dir = std::env::temp_dir().join(format!("firmament-noise-{}", std::process::id()));
        let (a, hit_a) = NoiseVolume::cached(NoiseKind::Erosion, 8, 5, Some(&dir)).unwrap();
        let (b, hit_b) = NoiseVolume::cached(NoiseKind::Erosion, 8, 5, Some(&dir)).unwrap();
        assert!(!hit_a && hit_b);
        assert_eq!(a, b);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

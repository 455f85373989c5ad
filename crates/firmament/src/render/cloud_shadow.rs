//! The clouds' shadow below them: the volumes' optical depth towards a light, tabulated over
//! the sphere of their lowest base (a 2D transmittance map, as engines bake their clouds'
//! shadow, Hillaire 2016 §5.7 "Other interactions"), so that any point below it finds its
//! transmittance from where its ray to the light enters that sphere. It shadows the ground
//! and terrain ([`super::volumes::dim_surface_light`]) and the air under the clouds: a view
//! ray's stretches in shadow (transmittance below ½) are passed to the sky method as
//! unlit, so the air beneath an overcast loses its single scattering and sunbeams fall
//! through the gaps of a cumulus field (the terrain's light-shaft machinery).
//!
//! The map covers a square of half side [`map_half_extent_m`] (40–80 km) around the
//! observer's place in the layers' planar coordinates (the gnomonic projection of the +z
//! cube face, as the clouds' weather); beyond it, and for points at or above the base, the
//! caller marches towards the light (the air's shadow far along a view ray takes a coarse
//! map's mean, which extends beyond).

use rayon::prelude::*;

use crate::math::sphere::ray_sphere;
use crate::math::Vec3;
use crate::scene::{Light, Ray, Scene, Volume};

/// The smallest half side of the mapped square (m): under a high sun, 40 km around the
/// observer at 125 m a texel.
pub const MIN_HALF_EXTENT_M: f64 = 40_000.0;
/// The largest half side of the mapped square (m), under a low sun ([`map_half_extent_m`]).
pub const HALF_EXTENT_M: f64 = 80_000.0;

/// The mapped square's half side (m) for a light in `light` (the observer's frame, z up)
/// over a base `base_height_m` above the sky method's ground (lifted to a terrain's floor
/// where the tables are): [`MIN_HALF_EXTENT_M`] + S, at most [`HALF_EXTENT_M`], S = h_b /
/// tan(elevation). A point at height h below the base finds its
/// shadow where its ray to the light meets the base, (h_b − h) / tan(elevation) towards the
/// light: under a low sun tens of km (a 3.2 km base and the sun 5.5° high, the default
/// scene: 33 km), and the terrain the views reach lies tens of km away. With 40 km whatever
/// fell beyond stayed lit: the default scene's golden-hour views with its cumulus read
/// 8.2 % median / 31.7 % p95 against the reference, 5.6 / 23.4 % with this square (73 km
/// there); under a high sun it keeps its 125 m texels (a fixed 80 km at 250 m took the
/// noon cumulus field's gaps from −18 to −24 % bias). Shared with the GPU (`map_half_extent` in `cloud_shadow.wgsl`).
pub fn map_half_extent_m(light: Vec3, base_height_m: f64) -> f64 {
    if light.z <= 0.0 {
        return HALF_EXTENT_M;
    }
    let horizontal = (light.x * light.x + light.y * light.y).sqrt();
    (MIN_HALF_EXTENT_M + base_height_m * horizontal / light.z).min(HALF_EXTENT_M)
}

/// Texels per side.
pub const TEXELS: usize = 640;
/// The most reads of the map across a light's disk ([`CloudShadow::disk_optical_depth`]).
pub const PENUMBRA_TAPS: usize = 16;
/// Quadrature step through the volumes along the light (m).
const MAP_STEP_M: f64 = 80.0;
/// A step of the air whose transmittance towards the light is within this of 0 or 1 is
/// taken as wholly shadowed or lit ([`CloudShadow::shadowed_intervals`]).
pub const SHADOW_SNAP: f64 = 0.05;
/// Shadowed stretches whose lit gap is under this fraction of its distance are merged into
/// one, so that a ray across a field of cumulus asks the sky method for fewer intervals;
/// the merge keeps the lit length (the shadow shrunk by half the gap at each end,
/// [`merge_close`]), near the observer (gaps of 250 m kept within 6 km) none. Merging every
/// gap under 800 m into shadow drew dark blotches in the haze above the horizon of a
/// cumulus field (the many short gaps along a grazing ray taken for shadow).
pub const MERGE_FRACTION: f64 = 0.04;
/// The farthest along a view ray the air's shadow is looked for in the map's texels (m):
/// beyond, the steps (250 m, then t/50) would alias the cumulus' shadows into streaks and
/// the stretches would be many (30 km before; the same golden-hour figures), and the air is in
/// shadow over the fraction of each far piece that the light's mean transmittance over
/// [`COARSE_TEXELS`]² blocks leaves unlit ([`CloudShadow::shadowed_intervals`]), the blocks
/// at the map's edge standing for the clouds beyond it.
pub const MAX_SHADOW_DISTANCE_M: f64 = 10_000.0;
/// The ratio of a far piece's end to its start (beyond [`MAX_SHADOW_DISTANCE_M`], where the
/// air's shadow is the fraction of each piece that the blocks' mean leaves unlit): from 10
/// km to a 1.5 km base's horizon (138 km) four pieces (each adds up to two boundaries for
/// the sky method to look up).
pub const FAR_PIECE_RATIO: f64 = 2.0;
/// Blocks per side of the coarse map (of `TEXELS / COARSE_TEXELS` texels each).
pub const COARSE_TEXELS: usize = 64;

/// The volumes' optical depth towards one light over their base sphere.
pub struct CloudShadow {
    /// The light's direction.
    light: Vec3,
    /// The light's angular radius (rad): the penumbra's ([`CloudShadow::disk_optical_depth`]).
    angular_radius_rad: f64,
    /// The base sphere's radius (m).
    base_radius_m: f64,
    /// The planet's radius (m): planar coordinates are gnomonic at this radius.
    planet_radius_m: f64,
    /// The mapped square's half side (m, [`map_half_extent_m`]).
    half_m: f64,
    /// τ per texel, row-major from (−half, −half).
    tau: Vec<f32>,
    /// The mean transmittance e^{−τ} per block of the coarse map, row-major.
    coarse: Vec<f32>,
    /// Whether the map's edge stands for the volumes beyond it ([`Volume::alike_everywhere`]).
    extends: bool,
}

impl CloudShadow {
    /// The map of `scene`'s volumes towards a light in `light` (None when no volume is a
    /// shell around the planet or the light is below the horizon of the map's centre).
    pub fn new(scene: &Scene, light: &Light) -> Option<CloudShadow> {
        let (angular_radius_rad, light) = (light.angular_radius_rad, light.direction);
        let base = scene
            .volumes
            .iter()
            .filter_map(|v| v.radii_m())
            .map(|[b, _]| b)
            .reduce(f64::min)?;
        if light.z <= 0.0 {
            return None;
        }
        let planet = scene.sky.model().bottom_radius_m;
        let half = map_half_extent_m(light, base - planet);
        let step = 2.0 * half / TEXELS as f64;
        let mut tau = vec![0.0f32; TEXELS * TEXELS];
        tau.par_chunks_mut(TEXELS).enumerate().for_each(|(j, row)| {
            for (i, t) in row.iter_mut().enumerate() {
                let x = -half + (i as f64 + 0.5) * step;
                let y = -half + (j as f64 + 0.5) * step;
                let entry = Vec3::new(x, y, planet).normalize() * base;
                let ray = Ray {
                    origin: entry,
                    dir: light,
                };
                *t = scene
                    .volumes
                    .iter()
                    .map(|v| optical_depth_coarse(v.as_ref(), &ray))
                    .sum::<f64>() as f32;
            }
        });
        let block = TEXELS / COARSE_TEXELS;
        let coarse = (0..COARSE_TEXELS * COARSE_TEXELS)
            .map(|b| {
                let (bi, bj) = (b % COARSE_TEXELS, b / COARSE_TEXELS);
                let sum: f64 = (0..block * block)
                    .map(|t| {
                        let (i, j) = (bi * block + t % block, bj * block + t / block);
                        (-(tau[j * TEXELS + i] as f64)).exp()
                    })
                    .sum();
                (sum / (block * block) as f64) as f32
            })
            .collect();
        Some(CloudShadow {
            light,
            angular_radius_rad,
            base_radius_m: base,
            planet_radius_m: planet,
            half_m: half,
            tau,
            coarse,
            extends: scene.volumes.iter().all(|v| v.alike_everywhere()),
        })
    }

    /// The base sphere's radius (m).
    pub fn base_radius_m(&self) -> f64 {
        self.base_radius_m
    }

    /// τ per texel, [`TEXELS`]² row-major from (−half, −half) ([`map_half_extent_m`]).
    pub fn texels(&self) -> &[f32] {
        &self.tau
    }

    /// The mean transmittance per block, [`COARSE_TEXELS`]² row-major.
    pub fn coarse_texels(&self) -> &[f32] {
        &self.coarse
    }

    /// Where `x`'s ray to the light enters the base sphere, in map texels of `size` per
    /// side (fractional, centred), when `x` lies below the sphere.
    fn entry_texel(&self, x: Vec3, size: usize) -> Option<(f64, f64)> {
        self.entry_texel_along(x, self.light, size)
    }

    /// As [`CloudShadow::entry_texel`] for the ray from `x` along `dir` (a direction in
    /// the light's disk).
    fn entry_texel_along(&self, x: Vec3, dir: Vec3, size: usize) -> Option<(f64, f64)> {
        let (_, far) = ray_sphere(x, dir, self.base_radius_m)?;
        if far <= 0.0 || x.length_squared() >= self.base_radius_m * self.base_radius_m {
            return None;
        }
        let e = x + far * dir;
        if e.z <= 0.0 {
            return None;
        }
        let s = self.planet_radius_m / e.z;
        let step = 2.0 * self.half_m / size as f64;
        Some((
            (e.x * s + self.half_m) / step - 0.5,
            (e.y * s + self.half_m) / step - 0.5,
        ))
    }

    /// The mean transmittance towards the light of the block `x`'s ray enters (bilinear
    /// between blocks; beyond the map, its edge, unless the volumes differ there: None),
    /// when `x` lies below the base sphere.
    pub fn mean_transmittance(&self, x: Vec3) -> Option<f64> {
        let (fx, fy) = self.entry_texel(x, COARSE_TEXELS)?;
        let max = (COARSE_TEXELS - 1) as f64;
        let inside = (0.0..=max).contains(&fx) && (0.0..=max).contains(&fy);
        if !(self.extends || inside) {
            return None;
        }
        let (fx, fy) = (fx.clamp(0.0, max), fy.clamp(0.0, max));
        let last = COARSE_TEXELS - 2;
        let (i, j) = ((fx as usize).min(last), (fy as usize).min(last));
        Some(bilinear(
            &self.coarse,
            COARSE_TEXELS,
            i,
            j,
            fx - i as f64,
            fy - j as f64,
        ))
    }

    /// The volumes' optical depth from `x` towards the light, when `x` lies below the base
    /// sphere and its ray enters the sphere inside the map.
    pub fn optical_depth(&self, x: Vec3) -> Option<f64> {
        self.texel_depth(self.entry_texel(x, TEXELS)?)
    }

    /// The volumes' optical depth from a surface at `x` towards the light's whole disk,
    /// −ln of their transmittance averaged over it (the penumbra), when `x` lies below the
    /// base sphere and its ray to the disk's centre enters the sphere inside the map.
    ///
    /// The disk's directions tilted towards the zenith by δ meet the base at points spread
    /// along the light's azimuth by h·α / sin²e either side (h the base's height above
    /// `x`, e the light's elevation, α its angular radius): 1.4 km for the default scene's
    /// 2.8 km base over the valley under a 5.5° sun, under a texel under a 30° sun (then
    /// the centre's read alone). So the map is read at points along that line, one more
    /// than the texels it spans (at most [`PENUMBRA_TAPS`]), by the midpoint rule in
    /// u = δ/α weighted by √(1 − u²), a uniform disk's chord (limb darkening left out),
    /// each where its ray enters the base (quadratic through the entries at δ = −α, 0, α;
    /// the map's depth along the disk's centre there); the spread across the azimuth,
    /// h·α / sin e (135 m there), stays under a texel and is left to the bilinear read.
    pub fn disk_optical_depth(&self, x: Vec3) -> Option<f64> {
        let c = self.entry_texel(x, TEXELS)?;
        let up = x.normalize_or_zero();
        // The spread h·α/sin²e·2 (flat), under a texel: the centre alone.
        let (sin_e, texel) = (self.light.dot(up), 2.0 * self.half_m / TEXELS as f64);
        let h = self.base_radius_m - x.length();
        if sin_e > 0.0 && 2.0 * h * self.angular_radius_rad < 0.5 * texel * sin_e * sin_e {
            return self.texel_depth(c);
        }
        let towards_up = (up - self.light * sin_e).normalize_or_zero();
        let alpha = self.angular_radius_rad;
        let tilted = |delta: f64| self.light * delta.cos() + towards_up * delta.sin();
        let (Some(a), Some(b)) = (
            self.entry_texel_along(x, tilted(alpha), TEXELS),
            self.entry_texel_along(x, tilted(-alpha), TEXELS),
        ) else {
            return self.texel_depth(c);
        };
        let spread = (a.0 - b.0).hypot(a.1 - b.1);
        if spread < 1.0 {
            return self.texel_depth(c);
        }
        let taps = (spread.ceil() as usize + 1).min(PENUMBRA_TAPS);
        // The entry at tilt u·α, quadratic through the three computed (its error is
        // α·cot e of the spread's third-order term: ≈ 0.2 % under a 5.5° sun).
        let at =
            |u: f64, c: f64, a: f64, b: f64| c + 0.5 * u * (a - b) + u * u * (0.5 * (a + b) - c);
        let (mut sum, mut weights) = (0.0, 0.0);
        for i in 0..taps {
            let u = -1.0 + (2 * i + 1) as f64 / taps as f64;
            if let Some(tau) = self.texel_depth((at(u, c.0, a.0, b.0), at(u, c.1, a.1, b.1))) {
                let w = (1.0 - u * u).sqrt();
                sum += w * (-tau).exp();
                weights += w;
            }
        }
        if weights <= 0.0 {
            return self.texel_depth(c);
        }
        Some(-(sum / weights).max(1e-30).ln())
    }

    /// The map's depth at fractional texel `f` (bilinear), None outside the map.
    fn texel_depth(&self, (fx, fy): (f64, f64)) -> Option<f64> {
        let max = (TEXELS - 1) as f64;
        if !(0.0..max).contains(&fx) || !(0.0..max).contains(&fy) {
            return None;
        }
        let (i, j) = (fx as usize, fy as usize);
        Some(bilinear(
            &self.tau,
            TEXELS,
            i,
            j,
            fx - i as f64,
            fy - j as f64,
        ))
    }

    /// Append the stretches of `ray` before `end` (and below the base) that the map puts
    /// in shadow to `out`: to [`MAX_SHADOW_DISTANCE_M`] in steps of max(250 m, t/50), the
    /// first 1 − T of each in shadow, T the texels' transmittance at its middle (snapped to
    /// 0 or 1 within [`SHADOW_SNAP`]): the air's expected single scattering over the step,
    /// a cloud's shadow fading over its edge (a shadow wherever T < ½ drew the stretches'
    /// ends as hard steps in the air before a low sun); beyond, in pieces
    /// [a, [`FAR_PIECE_RATIO`]·a], each in shadow over the fraction 1 − T̄ of its length, T̄
    /// the blocks' mean transmittance averaged along it (sampled as near), the shadow at
    /// both ends and the lit part in the middle: the expected single scattering of air
    /// that sees the clouds' shadows too small to resolve (a broken field's far air partly
    /// lit, an overcast's shadowed), with no blotches where T̄ hovers about ½.
    pub fn shadowed_intervals(&self, ray: &Ray, end: f64, out: &mut Vec<(f64, f64)>) {
        // Where the ray is below the base sphere.
        let limit = match ray_sphere(ray.origin, ray.dir, self.base_radius_m) {
            Some((_, far)) if far > 0.0 => far.min(end),
            _ => return,
        };
        let first = out.len();
        let step = |t: f64| (0.02 * t).max(250.0);
        let near = limit.min(MAX_SHADOW_DISTANCE_M);
        let mut t = 0.0;
        // A shadowed stretch reaching t.
        let mut open: Option<f64> = None;
        while t < near {
            let dt = step(t).min(near - t);
            let x = ray.origin + (t + 0.5 * dt) * ray.dir;
            let lit = self.optical_depth(x).map_or(1.0, |tau| (-tau).exp());
            let dark = match lit {
                l if l < SHADOW_SNAP => dt,
                l if l > 1.0 - SHADOW_SNAP => 0.0,
                l => (1.0 - l) * dt,
            };
            if dark >= dt {
                open.get_or_insert(t);
            } else if dark > 0.0 {
                out.push((open.take().unwrap_or(t), t + dark));
            } else if let Some(s) = open.take() {
                out.push((s, t));
            }
            t += dt;
        }
        if let Some(s) = open {
            out.push((s, near));
        }
        let mut a = near;
        while a < limit {
            let b = far_piece_end(a, limit);
            // The mean transmittance along the piece (beyond the map and not extended: lit).
            let (mut t, mut sum) = (a, 0.0);
            while t < b {
                let dt = step(t).min(b - t);
                let x = ray.origin + (t + 0.5 * dt) * ray.dir;
                sum += self.mean_transmittance(x).unwrap_or(1.0).clamp(0.0, 1.0) * dt;
                t += dt;
            }
            let shade = 0.5 * (b - a - sum);
            if shade > 0.0 {
                out.push((a, a + shade));
                out.push((b - shade, b));
            }
            a = b;
        }
        merge_close(out, first, MERGE_FRACTION);
    }
}

/// The end of the far piece that starts at `a` (≥ [`MAX_SHADOW_DISTANCE_M`]) on a ray
/// below the base to `limit`: [`FAR_PIECE_RATIO`]·a, or `limit` when less than half a
/// piece would remain after it.
pub fn far_piece_end(a: f64, limit: f64) -> f64 {
    let b = a * FAR_PIECE_RATIO;
    if b + 0.5 * (b - a) >= limit {
        limit
    } else {
        b
    }
}

/// Bilinear interpolation in a row-major grid of `size` per side at texel (i, j) + (tx, ty).
fn bilinear(grid: &[f32], size: usize, i: usize, j: usize, tx: f64, ty: f64) -> f64 {
    let at = |i: usize, j: usize| grid[j * size + i] as f64;
    let lo = at(i, j) + (at(i + 1, j) - at(i, j)) * tx;
    let hi = at(i, j + 1) + (at(i + 1, j + 1) - at(i, j + 1)) * tx;
    lo + (hi - lo) * ty
}

/// Merge the intervals of `out[first..]` (increasing) whose gaps are under `fraction` of
/// their distance, keeping the lit length: two stretches [a₁, b₁], [a₂, b₂] with gap
/// g = a₂ − b₁ become [a₁ + g/2, b₂ − g/2] (lit g/2 on either side).
pub fn merge_close(out: &mut Vec<(f64, f64)>, first: usize, fraction: f64) {
    let mut w = first;
    for r in first..out.len() {
        let iv = out[r];
        let gap = iv.0 - if w > first { out[w - 1].1 } else { 0.0 };
        if w > first && gap <= fraction * iv.0 {
            let g = gap.max(0.0);
            out[w - 1] = (out[w - 1].0 + 0.5 * g, iv.1 - 0.5 * g);
        } else {
            out[w] = iv;
            w += 1;
        }
    }
    out.truncate(w);
}

/// A volume's optical depth along `ray` (to infinity) by the midpoint rule at
/// [`MAP_STEP_M`], through the stretch its bounds give.
fn optical_depth_coarse(volume: &dyn Volume, ray: &Ray) -> f64 {
    let Some((a, b)) = volume.bounds(ray) else {
        return 0.0;
    };
    let steps = ((b - a) / MAP_STEP_M).ceil().max(1.0) as usize;
    let dt = (b - a) / steps as f64;
    let (mut e, mut s) = ([0.0f64; 1], [0.0f64; 1]);
    let mut tau = 0.0;
    for i in 0..steps {
        volume.coefficients(
            ray.origin + (a + (i as f64 + 0.5) * dt) * ray.dir,
            &mut e,
            &mut s,
        );
        tau += e[0] * dt;
        if tau > 30.0 {
            break;
        }
    }
    tau
}

#[cfg(test)]
mod tests;

//! The clouds' density filtered over a pixel's footprint: where a pixel covers many cells of
//! the noise (a cumulus field seen from orbit: 10 km per pixel for 1.25 km cells), a march
//! through the noise aliases into grain and moiré. There the density is the noise's mean
//! given the weather, E[density | h, c_loc, t], tabulated per kind from the textures'
//! own value distributions (the base shape and the erosion are independent noises, sampled
//! trilinearly at random points), and blended with the noise's density as the footprint
//! grows past the cells ([`filter_weight`]): a density mip chain's top level, the way
//! engines filter a volume far away (Schneider 2015's low-detail samples).
//!
//! What it approximates: a field of unresolved cells becomes a horizontally homogeneous
//! medium of the same mean extinction. A homogeneous cloud reflects more than a patchy one
//! of the same mean optical depth (the plane-parallel albedo bias, Cahalan et al. 1994,
//! J. Atmos. Sci. 51, "The albedo of fractal stratocumulus clouds"); the bias is measured
//! against the resolved field in docs/accuracy.md ("Clouds from orbit").

use std::sync::{Arc, OnceLock};

use rayon::prelude::*;

use super::noise::remap;
use super::noise_volume::NoiseVolume;
use super::profile::CloudKind;
use crate::math::hash::{lowbias32, unit};
use crate::math::smoothstep;

/// Normalised heights of the table (0 … 1).
pub const HEIGHTS: usize = 32;
/// Local coverages of the table (0 … 1).
pub const COVERAGES: usize = 33;
/// Weather types of the table (0 … 1).
pub const TYPES: usize = 9;
/// Quantiles of the base shape's values the expectation runs over (its upper tail, above
/// 1 − c over the profile, makes the cloud: many, so that a thin tail is resolved).
const BASE_QUANTILES: usize = 256;
/// Quantiles of the erosion's values.
const DETAIL_QUANTILES: usize = 32;
/// Random points each texture is sampled at for its quantiles.
const DRAWS: usize = 8192;

/// The filter's start and end in the noise's cell size: no filtering below a quarter of a
/// cell per pixel, the mean alone from two cells per pixel.
pub const FILTER_START_CELLS: f64 = 0.25;
/// See [`FILTER_START_CELLS`].
pub const FILTER_END_CELLS: f64 = 2.0;

/// How much of the mean density replaces the noise's at a footprint of `footprint_m` (m)
/// over cells of `cell_m` (m): 0 … 1.
#[inline]
pub fn filter_weight(footprint_m: f64, cell_m: f64) -> f64 {
    smoothstep(
        FILTER_START_CELLS * cell_m,
        FILTER_END_CELLS * cell_m,
        footprint_m,
    )
}

/// E[density | h, c, t] of a kind over its noise, without precipitation's gain, and the
/// effective-thickness factor χ(c, t) of its columns.
#[derive(Clone, Debug)]
pub struct MeanDensity {
    /// Row-major [type][coverage][height].
    pub table: Vec<f32>,
    /// χ per [type][coverage]: the optical depth of the homogeneous layer that reflects
    /// what the noise's vertical columns reflect on average, over their mean optical depth
    /// ([`MeanDensity::effective`]).
    pub chi: Vec<f32>,
}

/// Columns of the layer whose transmittance gives χ.
const COLUMNS: usize = 2048;
/// Samples along each column.
const COLUMN_SAMPLES: usize = 32;

impl MeanDensity {
    /// The table of `kind` for the textures `base` and `detail`, a layer's height h being
    /// at h·`z_tiles`[0] of the base's tile and h·`z_tiles`[1] of the erosion's (each
    /// height's distributions are those of its slices of the textures, which differ from
    /// the whole volume's by a few per cent).
    ///
    /// `column_tau` is the layer's optical thickness at density 1 (σ_t times its
    /// thickness) and `one_minus_g` one less its phase function's mean cosine, for χ.
    pub fn new(
        kind: CloudKind,
        base: &NoiseVolume,
        detail: &NoiseVolume,
        z_tiles: [f64; 2],
        column_tau: f64,
        one_minus_g: f64,
    ) -> MeanDensity {
        let slices: Vec<(Vec<f64>, Vec<f64>)> = (0..HEIGHTS)
            .into_par_iter()
            .map(|i| {
                let h = i as f64 / (HEIGHTS - 1) as f64;
                (
                    quantiles(base, 0x6261_7365, h * z_tiles[0], BASE_QUANTILES),
                    quantiles(detail, 0x6465_7461, h * z_tiles[1], DETAIL_QUANTILES),
                )
            })
            .collect();
        let table = (0..TYPES * COVERAGES)
            .into_par_iter()
            .flat_map_iter(|tc| {
                let t = (tc / COVERAGES) as f64 / (TYPES - 1) as f64;
                let c = (tc % COVERAGES) as f64 / (COVERAGES - 1) as f64;
                let slices = &slices;
                (0..HEIGHTS).map(move |i| {
                    let h = i as f64 / (HEIGHTS - 1) as f64;
                    let (b, d) = &slices[i];
                    mean_density(kind, h, c, t, b, d) as f32
                })
            })
            .collect();
        let chi = (0..TYPES * COVERAGES)
            .into_par_iter()
            .map(|tc| {
                let t = (tc / COVERAGES) as f64 / (TYPES - 1) as f64;
                let c = (tc % COVERAGES) as f64 / (COVERAGES - 1) as f64;
                let column = (column_tau, one_minus_g);
                chi(kind, c, t, base, detail, z_tiles, column) as f32
            })
            .collect();
        MeanDensity { table, chi }
    }

    /// The filtered density at (h, c, t): the mean times χ(c, t), so that the homogeneous
    /// layer reflects what the noise's columns reflect on average (the effective thickness
    /// of a clumpy cloud, Cahalan et al. 1994: a homogeneous cloud of the mean optical
    /// depth reflects far too much, the reflectance being concave in τ).
    pub fn effective(&self, h: f64, c: f64, t: f64) -> f64 {
        self.sample(h, c, t) * self.chi(c, t)
    }

    /// χ(c, t), bilinear.
    pub fn chi(&self, c: f64, t: f64) -> f64 {
        let (ic, fc) = axis(c, COVERAGES);
        let (it, ft) = axis(t, TYPES);
        let at = |t: usize, c: usize| self.chi[t * COVERAGES + c] as f64;
        let lo = at(it, ic) + (at(it, ic + 1) - at(it, ic)) * fc;
        let hi = at(it + 1, ic) + (at(it + 1, ic + 1) - at(it + 1, ic)) * fc;
        lo + (hi - lo) * ft
    }

    /// The mean density at (h, c, t), trilinear.
    pub fn sample(&self, h: f64, c: f64, t: f64) -> f64 {
        let (ih, fh) = axis(h, HEIGHTS);
        let (ic, fc) = axis(c, COVERAGES);
        let (it, ft) = axis(t, TYPES);
        let at =
            |t: usize, c: usize, h: usize| self.table[(t * COVERAGES + c) * HEIGHTS + h] as f64;
        let mut sum = 0.0;
        for (dt, wt) in [(0, 1.0 - ft), (1, ft)] {
            for (dc, wc) in [(0, 1.0 - fc), (1, fc)] {
                let lo = at(it + dt, ic + dc, ih);
                let hi = at(it + dt, ic + dc, ih + 1);
                sum += wt * wc * (lo + (hi - lo) * fh);
            }
        }
        sum
    }
}

/// A layer's [`MeanDensity`], made the first time a sample needs it: views from the ground
/// at full resolution never filter (the noon cumulus at 1920×1080: a quarter of a cell
/// per pixel is 460 km away, beyond its farthest cloud; at 640×360 its horizon does), and
/// the table and χ take 0.9 s of a 2-core host to make.
#[derive(Debug)]
pub struct LazyMeanDensity {
    /// What [`MeanDensity::new`] takes.
    inputs: Option<MeanInputs>,
    /// The table once made (or as given).
    cell: OnceLock<Arc<MeanDensity>>,
}

/// The arguments of [`MeanDensity::new`].
#[derive(Debug)]
struct MeanInputs {
    kind: CloudKind,
    noise: [Arc<NoiseVolume>; 2],
    z_tiles: [f64; 2],
    column_tau: f64,
    one_minus_g: f64,
}

impl LazyMeanDensity {
    /// The mean density of [`MeanDensity::new`]'s arguments, made on first [`Self::get`].
    pub fn new(
        kind: CloudKind,
        noise: [Arc<NoiseVolume>; 2],
        z_tiles: [f64; 2],
        column_tau: f64,
        one_minus_g: f64,
    ) -> LazyMeanDensity {
        LazyMeanDensity {
            inputs: Some(MeanInputs {
                kind,
                noise,
                z_tiles,
                column_tau,
                one_minus_g,
            }),
            cell: OnceLock::new(),
        }
    }

    /// One already made (a viewer's previous frame's).
    pub fn ready(mean: Arc<MeanDensity>) -> LazyMeanDensity {
        LazyMeanDensity {
            inputs: None,
            cell: OnceLock::from(mean),
        }
    }

    /// The table, made now if it was not (threads asking meanwhile wait for it).
    pub fn get(&self) -> &Arc<MeanDensity> {
        self.cell.get_or_init(|| {
            let i = self
                .inputs
                .as_ref()
                .expect("a lazy mean density has its inputs");
            Arc::new(MeanDensity::new(
                i.kind,
                &i.noise[0],
                &i.noise[1],
                i.z_tiles,
                i.column_tau,
                i.one_minus_g,
            ))
        })
    }

    /// Whether the table has been made.
    pub fn is_made(&self) -> bool {
        self.cell.get().is_some()
    }
}

/// The cell below `v` ∈ [0, 1] on an axis of `n` nodes and the fraction past it.
#[inline]
fn axis(v: f64, n: usize) -> (usize, f64) {
    let f = v.clamp(0.0, 1.0) * (n - 1) as f64;
    let i = (f as usize).min(n - 2);
    (i, f - i as f64)
}

/// The mean over the quantiles of the base `b` and the erosion `d` of the layer's density
/// rule ([`super::layer`]) at (h, c, t).
fn mean_density(kind: CloudKind, h: f64, c: f64, t: f64, b: &[f64], d: &[f64]) -> f64 {
    let profile = kind.density(h, t);
    if profile <= 1.0 - c {
        return 0.0;
    }
    let e = kind.erosion(h);
    let mut sum = 0.0;
    for &bv in b {
        let shape = remap(bv * profile, 1.0 - c, 1.0, 0.0, 1.0).max(0.0);
        if shape <= 0.0 {
            continue;
        }
        for &dv in d {
            sum += remap(shape, e * dv, 1.0, 0.0, 1.0).max(0.0);
        }
    }
    sum / (b.len() * d.len()) as f64
}

/// χ = τ_eff / E[τ] over [`COLUMNS`] random vertical columns of the layer at (c, t) (1
/// where the columns are empty), τ_eff the optical depth whose reflectance is the columns'
/// mean reflectance (the independent column approximation, Cahalan et al. 1994), with a
/// conservative slab's two-stream reflectance R(τ) = (1 − g)τ / (1 + (1 − g)τ) (the
/// hemispheric-mean closure the marcher's ambient light uses, Meador & Weaver 1980):
/// τ_eff = R̄ / ((1 − g)(1 − R̄)). The optical depth τ of each column by the midpoint rule
/// through the density rule, the base and the erosion sampled where the layer samples them
/// (the erosion's coordinates the base's times its tiles' ratio).
fn chi(
    kind: CloudKind,
    c: f64,
    t: f64,
    base: &NoiseVolume,
    detail: &NoiseVolume,
    z_tiles: [f64; 2],
    (column_tau, one_minus_g): (f64, f64),
) -> f64 {
    let ratio = if z_tiles[0] > 0.0 {
        z_tiles[1] / z_tiles[0]
    } else {
        8.0
    };
    let (mut mean_tau, mut mean_r) = (0.0, 0.0);
    for i in 0..COLUMNS as u32 {
        let r = |k: u32| unit(lowbias32(0x636f_6c75 ^ lowbias32(2 * i + k)));
        let (u, v) = (r(0), r(1));
        let mut tau = 0.0;
        for j in 0..COLUMN_SAMPLES {
            let h = (j as f64 + 0.5) / COLUMN_SAMPLES as f64;
            let profile = kind.density(h, t);
            if profile <= 1.0 - c {
                continue;
            }
            let b = base.sample([u, v, h * z_tiles[0]]);
            let shape = remap(b * profile, 1.0 - c, 1.0, 0.0, 1.0).max(0.0);
            if shape <= 0.0 {
                continue;
            }
            let d = detail.sample([u * ratio, v * ratio, h * z_tiles[1]]);
            let density = remap(shape, kind.erosion(h) * d, 1.0, 0.0, 1.0).max(0.0);
            tau += column_tau * density / COLUMN_SAMPLES as f64;
        }
        mean_tau += tau / COLUMNS as f64;
        let k = one_minus_g * tau;
        mean_r += k / (1.0 + k) / COLUMNS as f64;
    }
    if mean_tau < 1e-6 {
        1.0
    } else {
        let tau_eff = mean_r / (one_minus_g * (1.0 - mean_r));
        (tau_eff / mean_tau).clamp(0.0, 1.0)
    }
}

/// `count` mid-quantiles of `volume`'s trilinear values at [`DRAWS`] random points of its
/// slice at `z` (in tiles).
fn quantiles(volume: &NoiseVolume, salt: u32, z: f64, count: usize) -> Vec<f64> {
    let mut v: Vec<f64> = (0..DRAWS as u32)
        .map(|i| {
            let r = |k: u32| unit(lowbias32(salt ^ lowbias32(2 * i + k)));
            volume.sample([r(0), r(1), z])
        })
        .collect();
    v.sort_by(f64::total_cmp);
    (0..count)
        .map(|q| v[((q as f64 + 0.5) / count as f64 * DRAWS as f64) as usize])
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Vec3;
    use crate::scene::clouds::{CloudLayer, CloudLayerConfig, NoiseKind, ViewFootprint};

    #[test]
    fn the_mean_density_matches_the_closed_form_without_erosion() {
        // With the erosion off and the base uniform on [0, 1], E[max(0, (u·p − 1 + c)/c)]
        // = (p − (1 − c))²/(2·p·c) for p > 1 − c.
        let uniform: Vec<f64> = (0..4096).map(|i| (i as f64 + 0.5) / 4096.0).collect();
        let none = [0.0];
        for (h, c, t) in [(0.3, 0.45, 1.0), (0.5, 0.8, 0.5), (0.2, 0.2, 0.0)] {
            let p = CloudKind::Altostratus.density(h, t);
            let m = mean_density(CloudKind::Altostratus, h, c, t, &uniform, &none);
            // Altostratus erodes by 0.3·d; with d = 0 nothing is eroded.
            let exact = if p > 1.0 - c {
                (p - (1.0 - c)).powi(2) / (2.0 * p * c)
            } else {
                0.0
            };
            assert!((m - exact).abs() < 1e-4, "{h} {c} {t}: {m} vs {exact}");
        }
    }

    #[test]
    fn the_table_is_the_mean_of_the_density_over_the_noise() {
        // Against a direct average of the rule over the textures at 20 000 random points.
        let base = NoiseVolume::generate(NoiseKind::BaseShape, 32, 1);
        let detail = NoiseVolume::generate(NoiseKind::Erosion, 16, 2);
        let z_tiles = [0.2, 1.6];
        let table = MeanDensity::new(CloudKind::Cumulus, &base, &detail, z_tiles, 100.0, 0.5);
        for (h, c, t) in [(0.3, 0.45, 1.0), (0.6, 0.7, 0.75), (0.15, 0.3, 0.25)] {
            let n = 20_000u32;
            let sum: f64 = (0..n)
                .map(|i| {
                    let r = |k: u32| unit(lowbias32(0x5eed ^ lowbias32(6 * i + k)));
                    let bv = base.sample([r(0), r(1), h * z_tiles[0]]);
                    let dv = detail.sample([r(3), r(4), h * z_tiles[1]]);
                    mean_density(CloudKind::Cumulus, h, c, t, &[bv], &[dv])
                })
                .sum();
            let direct = sum / n as f64;
            let tabled = table.sample(h, c, t);
            assert!(
                (tabled - direct).abs() < 0.01 + 0.03 * direct,
                "{h} {c} {t}: {tabled} vs {direct}"
            );
        }
        assert_eq!(filter_weight(100.0, 1000.0), 0.0);
        assert_eq!(filter_weight(2500.0, 1000.0), 1.0);
    }

    /// A default cumulus layer over a 6 360 km planet with noise textures of these sizes.
    fn cumulus_layer(base_size: usize, detail_size: usize) -> CloudLayer {
        let noise = [
            Arc::new(NoiseVolume::generate(NoiseKind::BaseShape, base_size, 1)),
            Arc::new(NoiseVolume::generate(NoiseKind::Erosion, detail_size, 2)),
        ];
        let config = CloudLayerConfig::of_kind(CloudKind::Cumulus);
        CloudLayer::new(&config, 6.36e6, noise, (0.0, 0.0), "c").unwrap()
    }

    #[test]
    fn a_layer_seen_from_afar_reflects_as_its_columns_do() {
        // The same vertical columns of a cumulus layer through the noise's density and
        // through the filtered one of a camera 30 000 km away (every footprint past the
        // filter's end): their mean two-stream reflectance agrees (what χ is made for, here
        // through the layer's own weather and sampling), while the mean optical depth of
        // the filtered columns is lower (χ < 1: the reflectance is concave in τ).
        let near = cumulus_layer(32, 16);
        let radius = near.planet_radius_m;
        let mut far = near.clone();
        far.set_view(
            ViewFootprint {
                eye: Vec3::new(0.0, 0.0, radius + 3.0e7),
                pixel_angle_rad: 1e-3,
            },
            None,
        );
        let sigma = near.params.extinction_per_m;
        let phase = crate::medium::PhaseFunction::DualLobeHg {
            g1: near.params.phase[0],
            g2: near.params.phase[1],
            weight: near.params.phase[2],
        };
        let k = 1.0 - phase.mean_cosine();
        let reflectance = |tau: f64| k * tau / (1.0 + k * tau);
        let (mut r_near, mut r_far, mut tau_near, mut tau_far) = (0.0, 0.0, 0.0, 0.0);
        let n = 3000u32;
        for i in 0..n {
            let r = |k: u32| unit(lowbias32(0xf00d ^ lowbias32(2 * i + k)));
            let dir = Vec3::new(60e3 * (r(0) - 0.5), 60e3 * (r(1) - 0.5), radius).normalize();
            let (mut a, mut b) = (0.0, 0.0);
            for j in 0..200 {
                let p = dir * (radius + 1500.0 + (j as f64 + 0.5) * 10.0);
                a += sigma * near.density(p) * 10.0;
                b += sigma * far.density(p) * 10.0;
            }
            r_near += reflectance(a) / n as f64;
            r_far += reflectance(b) / n as f64;
            tau_near += a / n as f64;
            tau_far += b / n as f64;
        }
        assert!(
            (r_far / r_near - 1.0).abs() < 0.06,
            "reflectance: filtered {r_far} vs noise {r_near}"
        );
        assert!(
            tau_far < 0.9 * tau_near,
            "τ: filtered {tau_far} vs {tau_near}"
        );
    }

    #[test]
    fn the_mean_density_is_made_only_when_a_sample_needs_it() {
        let plain = cumulus_layer(16, 8);
        let radius = plain.planet_radius_m;
        let mut layer = plain.clone();
        // From the ground, pixels of 1 mrad: a quarter of a cell per pixel only 300 km away.
        layer.set_view(
            ViewFootprint {
                eye: Vec3::new(0.0, 0.0, radius + 2.0),
                pixel_angle_rad: 1e-3,
            },
            None,
        );
        let mean = layer.filter.as_ref().unwrap().1.clone();
        let near: Vec<Vec3> = (0..400)
            .map(|i| {
                Vec3::new(i as f64 * 50.0, 3e3, radius + 2500.0).normalize() * (radius + 2500.0)
            })
            .collect();
        for &p in &near {
            assert_eq!(layer.density(p), plain.density(p));
        }
        assert!(!mean.is_made(), "made for samples that do not filter");
        // 1 000 km away: the mean alone.
        let far = Vec3::new(1.0e6, 0.0, radius).normalize() * (radius + 2500.0);
        let d = layer.density(far);
        assert!(mean.is_made(), "not made for a sample that filters");
        let made = MeanDensity::clone(mean.get());
        let mut given = plain.clone();
        given.set_view(layer.filter.as_ref().unwrap().0, Some(Arc::new(made)));
        assert_eq!(given.density(far), d);
    }
}

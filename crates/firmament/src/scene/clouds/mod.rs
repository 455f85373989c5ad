//! Volumetric clouds (Hillaire 2016 §5, seed `hillaire-2016-frostbite-sky-atmosphere-clouds`;
//! Schneider 2015): layers between two altitudes that follow the planet, shaped by a weather
//! map, a cloud-type height profile and two tileable noise textures, each layer a
//! [`crate::scene::Volume`] ([`CloudMedium`]) that the renderer's marcher and the reference
//! path tracer sample through the same seam.
//!
//! - [`noise`]: tileable Perlin and Worley noise; [`noise_volume`]: the two 3D textures
//!   made from them, cached on disk.
//! - [`weather`]: the weather map (procedural or a PNG); [`planetary`]: one over the whole
//!   planet; [`profile`]: the cloud types.
//! - [`lod`]: the density filtered over a pixel's footprint (clouds seen from far away).
//! - [`config`]: a `[[clouds]]` section; [`layer`]: the density it gives; [`medium`]: the
//!   volume.

pub mod config;
pub mod layer;
pub mod lod;
pub mod medium;
pub mod noise;
pub mod noise_volume;
pub mod planetary;
pub mod profile;
pub mod two_stream;
pub mod weather;

use std::path::Path;
use std::sync::Arc;

pub use config::{CloudLayerConfig, LayerParams, MultipleScattering, WeatherWrap};
pub use layer::{CloudLayer, ViewFootprint};
pub use medium::CloudMedium;
pub use noise_volume::{NoiseKind, NoiseVolume};
pub use profile::CloudKind;

use crate::Result;

/// The base-shape texture's default size (texels per side; Schneider 2015's 128³).
pub const BASE_SHAPE_SIZE: usize = 128;
/// The erosion texture's default size (Schneider 2015's 32³).
pub const EROSION_SIZE: usize = 32;
/// The noise textures' salt.
const NOISE_SALT: u32 = 0x636c_6f75;

/// The two noise textures every layer shares.
#[derive(Clone, Debug)]
pub struct CloudNoise {
    /// Base shape and erosion.
    pub textures: [Arc<NoiseVolume>; 2],
}

impl CloudNoise {
    /// The textures at `sizes` (base, erosion), read from the cache directory `cache` when a
    /// file holds them, else computed (and written there); the bool says whether both were
    /// read.
    pub fn new(sizes: [usize; 2], cache: Option<&Path>) -> Result<(CloudNoise, bool)> {
        let (base, hit_a) = NoiseVolume::cached(NoiseKind::BaseShape, sizes[0], NOISE_SALT, cache)?;
        let (detail, hit_b) = NoiseVolume::cached(NoiseKind::Erosion, sizes[1], NOISE_SALT, cache)?;
        Ok((
            CloudNoise {
                textures: [Arc::new(base), Arc::new(detail)],
            },
            hit_a && hit_b,
        ))
    }
}

/// The volumes of the layers `configs` over a planet of `planet_radius_m`, the observer at
/// (`lat_deg`, `lon_deg`) of a planetary weather map (errors name `clouds[i]`). Layers may
/// not overlap: each point has one phase function.
pub fn cloud_media(
    configs: &[CloudLayerConfig],
    planet_radius_m: f64,
    location: (f64, f64),
    noise: &CloudNoise,
) -> Result<Vec<CloudMedium>> {
    validate_layers(configs)?;
    configs
        .iter()
        .enumerate()
        .map(|(i, c)| {
            CloudLayer::new(
                c,
                planet_radius_m,
                noise.textures.clone(),
                location,
                &format!("clouds[{i}]"),
            )
            .map(CloudMedium::new)
        })
        .collect()
}

/// Check each layer and that no two overlap in altitude.
pub fn validate_layers(configs: &[CloudLayerConfig]) -> Result<()> {
    for (i, c) in configs.iter().enumerate() {
        c.validate(&format!("clouds[{i}]"))?;
    }
    for (i, a) in configs.iter().enumerate() {
        let pa = a.resolved();
        for (j, b) in configs.iter().enumerate().skip(i + 1) {
            let pb = b.resolved();
            if pa.bottom_m < pb.top_m && pb.bottom_m < pa.top_m {
                return Err(crate::Error::invalid(
                    format!("clouds[{j}].bottom_m"),
                    pb.bottom_m,
                    format!(
                        "a layer apart from clouds[{i}] ({}–{} m): layers may not overlap",
                        pa.bottom_m, pa.top_m
                    ),
                ));
            }
        }
    }
    Ok(())
}

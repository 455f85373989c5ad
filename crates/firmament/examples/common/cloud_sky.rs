//! What the cloud examples share: Earth's RGB sky from the user's table cache (computed and
//! stored there the first time) and the full-size cloud noise textures from the same cache.

use firmament::atmosphere::{Atmosphere, Model};
use firmament::scene::clouds::{CloudNoise, BASE_SHAPE_SIZE, EROSION_SIZE};
use firmament::sky::bruneton4d::cache::{Loaded, TableCache};
use firmament::sky::bruneton4d::{Bruneton4d, TableConfig, Tables};
use firmament::spectrum::Wavelengths;

/// The model, its sky from the default tables and the clouds' noise.
pub fn earth_rgb_with_noise() -> firmament::Result<(Model, Bruneton4d, CloudNoise)> {
    let model = Atmosphere::earth().resolve(&Wavelengths::rgb())?;
    let config = TableConfig::default();
    let tables = match TableCache::from_env()? {
        Some(cache) => match cache.load(&model, &config) {
            Loaded::Hit { tables, .. } => *tables,
            _ => {
                *cache
                    .store(&Tables::compute(&model, &config)?, &model, &config)?
                    .tables
            }
        },
        None => Tables::compute(&model, &config)?,
    };
    let sky = Bruneton4d::new(model.clone(), tables)?;
    let cache = TableCache::from_env()?.map(|c| c.dir);
    let (noise, _) = CloudNoise::new([BASE_SHAPE_SIZE, EROSION_SIZE], cache.as_deref())?;
    Ok((model, sky, noise))
}

//! What a picture shows: the atmosphere through a sky method, surfaces, volumes and lights
//! ([`Scene`]), seen by a camera ([`camera`]); and the scene files that describe it in TOML
//! ([`file`](mod@file)).
//!
//! The world is planet-centred (metres); the observer stands above the point of the planet
//! on the +z axis, whose local frame is x = east, y = north, z = up.

pub mod camera;
pub mod clouds;
pub mod file;
pub mod light;
pub mod lunar;
pub mod planet;
pub mod planet_config;
pub mod planet_texture;
pub mod sky_lights;
pub mod surface;
pub mod terrain;
pub mod volume;

pub use camera::{Camera, PreparedCamera, Projection, Ray};
pub use file::SceneFile;
pub use light::{DiskProfile, Light};
pub use surface::{Relief, Sphere, Surface, SurfaceHit};
pub use volume::{DiffuseLight, HomogeneousSphere, Octaves, Volume};

use crate::math::{direction_from_zenith_azimuth, Vec3};
use crate::sky::SkyMethod;

/// Distance (m) within which two surfaces' hits count as the same point.
pub const TIE_M: f64 = 1e-2;

/// Everything a frame composes. The renderer asks each part only what its seam offers: the
/// sky method for the atmosphere's light, each surface for hits and shadows, each volume for
/// its medium, each light for its direction, irradiance and disk.
pub struct Scene<'a> {
    /// The atmosphere's light transport.
    pub sky: &'a dyn SkyMethod,
    /// Surfaces, the planet's ground among them.
    pub surfaces: Vec<Box<dyn Surface + 'a>>,
    /// Participating media besides the atmosphere's constituents.
    pub volumes: Vec<Box<dyn Volume + 'a>>,
    /// Lights.
    pub lights: Vec<Light>,
    /// A glow from beyond the atmosphere in every direction (the night sky's,
    /// [`sky_lights::night_sky_background`]), seen through the air.
    pub background: Option<sky_lights::Background>,
    /// Point lights outside the atmosphere drawn into images (the stars), seen through it.
    pub stars: Vec<sky_lights::PointSource>,
    /// Surfaces' aerial perspective from a froxel volume per light rather than per pixel
    /// ([`crate::render::aerial_volume`]); None: per pixel.
    pub aerial_volume: Option<crate::render::aerial_volume::AerialVolumeConfig>,
}

impl<'a> Scene<'a> {
    /// The clear sky: the planet's ground sphere under the model's sun in `sun_direction`
    /// (its disk drawn when `sun_disk`).
    pub fn clear_sky(sky: &'a dyn SkyMethod, sun_direction: Vec3, sun_disk: bool) -> Scene<'a> {
        let model = sky.model();
        Scene {
            sky,
            surfaces: vec![Box::new(Sphere::ground(model))],
            volumes: Vec::new(),
            lights: vec![Light::sun(model, sun_direction, sun_disk)],
            background: None,
            stars: Vec::new(),
            aerial_volume: None,
        }
    }

    /// Put `terrain` into a [`Scene::clear_sky`] scene on a planet of radius
    /// `planet_radius_m`: the terrain first (it wins where it lies on the sphere), and the
    /// ground sphere at the planet's radius, which is the sky method's bottom unless the
    /// method's ground is lifted to the terrain's floor ([`Atmosphere::lifted`]).
    ///
    /// [`Atmosphere::lifted`]: crate::atmosphere::Atmosphere::lifted
    pub fn add_terrain(&mut self, terrain: impl Surface + 'a, planet_radius_m: f64) {
        self.set_ground(Sphere {
            radius_m: planet_radius_m,
            ..Sphere::ground(self.sky.model())
        });
        self.surfaces.insert(0, Box::new(terrain));
    }

    /// Replace the planet's ground sphere of a [`Scene::clear_sky`] scene (its last surface,
    /// after any terrain) with `ground` (a map: `scene::planet`).
    pub fn set_ground(&mut self, ground: impl Surface + 'a) {
        let last = self.surfaces.len() - 1;
        self.surfaces[last] = Box::new(ground);
    }

    /// The nearest surface hit of `ray` closer than `max_distance_m`: (surface index, hit).
    /// An earlier surface wins a tie within [`TIE_M`] (the terrain, listed before the
    /// planet's sphere, where it lies on it).
    pub fn nearest_hit(&self, ray: &Ray, max_distance_m: f64) -> Option<(usize, SurfaceHit)> {
        let mut best: Option<(usize, SurfaceHit)> = None;
        for (i, s) in self.surfaces.iter().enumerate() {
            let limit = best.map_or(max_distance_m, |(_, h)| h.distance_m - TIE_M);
            if let Some(h) = s.intersect(ray, limit) {
                best = Some((i, h));
            }
        }
        best
    }

    /// The intervals of `ray` within [0, `max_distance_m`] that some surface hides from
    /// `light` (unordered, possibly overlapping), appended to `out`.
    pub fn shadowed_intervals(
        &self,
        ray: &Ray,
        light: Vec3,
        max_distance_m: f64,
        out: &mut Vec<(f64, f64)>,
    ) {
        for s in &self.surfaces {
            s.shadowed_intervals(ray, light, max_distance_m, out);
        }
    }
}

/// Sun direction from zenith and azimuth (degrees; azimuth clockwise from north).
pub fn sun_direction(zenith_deg: f64, azimuth_deg: f64) -> Vec3 {
    direction_from_zenith_azimuth(zenith_deg.to_radians(), azimuth_deg.to_radians())
}

//! The lights of a date and a place: the sun and the moon where [`crate::astro`] puts them,
//! the stars of the catalogue, and the natural night sky's background glow.
//!
//! Stars: each a point of spectral irradiance outside the atmosphere, a Planck spectrum at
//! the temperature of its B−V (Ballesteros 2012) scaled to the illuminance of its V
//! magnitude (zero point in [`crate::astro::photometry`]).
//!
//! The background (integrated starlight, zodiacal light, airglow) is a uniform radiance
//! outside the atmosphere seen through the atmosphere's transmittance, with the solar
//! spectrum's shape (zodiacal light and the integrated light of the stars are close to
//! solar in the visible; Leinert et al. 1998, A&AS 127, 1, §§8–10). Its level, 21.8 V
//! mag/arcsec² above the air, gives the 21.9–22.0 mag/arcsec² measured at the zenith of
//! dark sites at sea level (Benn & Ellison 1998, La Palma: 21.9 V at solar minimum; Walker
//! 1987). About half of it at the zenith is airglow (Leinert et al. 1998, Table 1 and §9),
//! emitted by a thin layer near 90 km and so brighter towards the horizon by the van Rhijn
//! (1921) factor 1/√(1 − (R/(R + h))² sin² z). Left out: airglow's emission lines (its
//! colour is the solar shape here) and the glow scattered by the air itself, which is why
//! the last degrees above the horizon come out darker than a real night sky.

use crate::astro::photometry::{
    illuminance_from_magnitude_lx, luminance_from_surface_brightness, planck_shape,
    scale_to_illuminance, temperature_from_b_v,
};
use crate::astro::stars::{catalogue, star_place};
use crate::astro::sun::ASTRONOMICAL_UNIT_M;
use crate::astro::Sky;
use crate::atmosphere::Model;
use crate::math::Vec3;
use crate::scene::light::Light;
use crate::scene::lunar::MoonGeometry;

/// The night sky's surface brightness above the atmosphere at the zenith (V mag/arcsec²).
pub const NIGHT_SKY_TOP_MAG_ARCSEC2: f64 = 21.8;
/// The share of airglow in it at the zenith, and the height of its layer (m).
const AIRGLOW_FRACTION: f64 = 0.5;
const AIRGLOW_HEIGHT_M: f64 = 90_000.0;

/// A glow from beyond the atmosphere: radiance per channel at the zenith, part of it from
/// a thin emitting layer (brighter at slant views).
#[derive(Clone, Debug)]
pub struct Background {
    /// Radiance at the zenith per channel (W·m⁻²·sr⁻¹·nm⁻¹).
    pub zenith_radiance: Vec<f64>,
    /// The share emitted by the layer.
    pub layer_fraction: f64,
    /// Radius of the layer (m, planet-centred).
    pub layer_radius_m: f64,
}

impl Background {
    /// The factor on the zenith radiance seen from `origin` along `dir` (unit): the van
    /// Rhijn factor for the layer's share, 1 for the rest.
    pub fn factor(&self, origin: Vec3, dir: Vec3) -> f64 {
        let r = origin.length();
        let cos_z = (dir.dot(origin) / r).clamp(-1.0, 1.0);
        let x = (r / self.layer_radius_m).min(1.0);
        let van_rhijn = 1.0 / (1.0 - x * x * (1.0 - cos_z * cos_z)).max(1e-6).sqrt();
        self.layer_fraction * van_rhijn + (1.0 - self.layer_fraction)
    }
}

/// Below this altitude (degrees) the moon lights nothing a camera on the ground sees (its
/// whole disk and the refraction margin under the horizon).
const MOON_CUTOFF_ALTITUDE_DEG: f64 = -3.0;

/// The natural night sky's glow for `model`'s planet and wavelengths.
pub fn night_sky_background(model: &Model) -> Background {
    let colour = model.colour_matrix();
    Background {
        zenith_radiance: scale_to_illuminance(
            &model.solar_irradiance,
            &colour,
            luminance_from_surface_brightness(NIGHT_SKY_TOP_MAG_ARCSEC2),
        ),
        layer_fraction: AIRGLOW_FRACTION,
        layer_radius_m: model.bottom_radius_m + AIRGLOW_HEIGHT_M,
    }
}

/// How the moon stands for the lighting: its direction, the sun's direction from it, its
/// phase and size (the apparent, refracted directions a camera sees).
pub fn moon_geometry(sky: &Sky) -> MoonGeometry {
    let m = sky.moon_direction();
    let sun = sky.sun_direction() * (sky.sun.distance_au * ASTRONOMICAL_UNIT_M);
    let moon = m * (sky.moon.distance_km * 1000.0);
    MoonGeometry {
        direction: m,
        sun_from_moon: (sun - moon).normalize(),
        phase_angle_rad: sky.moon.phase_angle_deg.to_radians(),
        distance_m: sky.moon.distance_km * 1000.0,
        angular_radius_rad: sky.moon.angular_radius_deg.to_radians(),
        sun_distance_au: sky.sun.distance_au,
    }
}

/// The lights of `sky` for `model`: the sun (its irradiance scaled by its distance), and the
/// moon when it stands above −3°.
pub fn lights_of(model: &Model, sky: &Sky, sun_disk: bool, moon_disk: bool) -> Vec<Light> {
    let mut sun = Light::sun(model, sky.sun_direction(), sun_disk);
    // The model's solar spectrum is for 1 AU.
    let r2 = sky.sun.distance_au * sky.sun.distance_au;
    sun.irradiance.iter_mut().for_each(|e| *e /= r2);
    if let crate::scene::DiskProfile::Emitting {
        centre_radiance, ..
    } = &mut sun.disk
    {
        centre_radiance.iter_mut().for_each(|e| *e /= r2);
    }
    let mut lights = vec![sun];
    if 90.0 - sky.moon.apparent_zenith_deg > MOON_CUTOFF_ALTITUDE_DEG {
        lights.push(Light::moon(model, &moon_geometry(sky), moon_disk));
    }
    lights
}

/// A point light outside the atmosphere: a star.
#[derive(Clone, Debug)]
pub struct PointSource {
    /// Unit vector towards it (local frame, refracted).
    pub direction: Vec3,
    /// Spectral irradiance per channel outside the atmosphere (W·m⁻²·nm⁻¹).
    pub irradiance: Vec<f64>,
}

/// The catalogue's stars above the horizon (apparent altitude > −1°) of `sky`, for
/// `model`'s wavelengths.
pub fn stars_of(model: &Model, sky: &Sky) -> Vec<PointSource> {
    let nm = model.wavelengths.nm();
    let colour = model.colour_matrix();
    catalogue()
        .iter()
        .filter_map(|star| {
            let p = star_place(star, &sky.instant, &sky.place, &sky.weather);
            if p.apparent_zenith_deg > 91.0 {
                return None;
            }
            let t = temperature_from_b_v(star.b_v);
            let shape: Vec<f64> = nm.iter().map(|&l| planck_shape(l, t)).collect();
            Some(PointSource {
                direction: crate::astro::local_direction(p.apparent_zenith_deg, p.azimuth_deg),
                irradiance: scale_to_illuminance(
                    &shape,
                    &colour,
                    illuminance_from_magnitude_lx(star.vmag),
                ),
            })
        })
        .collect()
}

/// Everything a date and a place light a scene with.
#[derive(Clone, Debug, Default)]
pub struct SkySources {
    /// The sun, and the moon when up.
    pub lights: Vec<Light>,
    /// The night sky's glow, while the sun is down.
    pub background: Option<Background>,
    /// The stars, while the sun is down.
    pub stars: Vec<PointSource>,
}

impl SkySources {
    /// `model`'s sun alone in direction `direction` (a scene without a date).
    pub fn sun(model: &Model, direction: Vec3, disk: bool) -> SkySources {
        SkySources {
            lights: vec![Light::sun(model, direction, disk)],
            ..SkySources::default()
        }
    }
}

/// The sources of `sky` for `model`: [`lights_of`], and at night (the sun's upper limb
/// below the horizon, −0.833°) the glow and the stars; by day both are under 10⁻⁶ of the
/// sky's radiance.
pub fn sources_of(model: &Model, sky: &Sky, sun_disk: bool, moon_disk: bool) -> SkySources {
    let night = 90.0 - sky.sun.apparent_zenith_deg < -0.833;
    SkySources {
        lights: lights_of(model, sky, sun_disk, moon_disk),
        background: night.then(|| night_sky_background(model)),
        stars: if night {
            stars_of(model, sky)
        } else {
            Vec::new()
        },
    }
}

//! The lights of a date and a place: the sun and the moon where [`crate::astro`] puts them,
//! and the natural night sky's background glow.
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

use crate::astro::photometry::{luminance_from_surface_brightness, scale_to_illuminance};
use crate::astro::sun::ASTRONOMICAL_UNIT_M;
use crate::astro::Sky;
use crate::atmosphere::Model;
use crate::math::Vec3;
use crate::scene::light::Light;
use crate::scene::lunar::MoonGeometry;
use crate::spectrum::ColourMatrix;

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
    let colour = ColourMatrix::new(model.wavelengths.nm());
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

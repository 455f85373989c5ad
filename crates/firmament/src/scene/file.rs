//! Scene files (TOML): everything `firmament render` needs, with defaults that make a
//! handsome picture. Unknown fields are refused.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::camera::{Camera, Projection};
use super::terrain::TerrainConfig;
use crate::atmosphere::Adjustments;
use crate::render::tonemap::ToneCurve;
use crate::{Error, Result};

/// Which atmosphere.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneAtmosphere {
    /// Preset name (ignored when `file` is given).
    #[serde(default = "default_preset")]
    pub preset: String,
    /// Atmosphere TOML file, relative to the scene file.
    #[serde(default)]
    pub file: Option<PathBuf>,
    /// `spectral`, `rgb` or `NM,NM,...`; absent: the wavelengths of the tables file a
    /// program is given, else [`DEFAULT_WAVELENGTHS`].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wavelengths: Option<String>,
    /// `[atmosphere.adjust]`: the aerosols' optical depth, the ozone column, the Rayleigh
    /// scale, the ground albedo or the planet's radius changed on the preset or file
    /// ([`Adjustments`]).
    #[serde(default, skip_serializing_if = "Adjustments::is_empty")]
    pub adjust: Adjustments,
}

/// The wavelengths a picture is rendered at unless told otherwise: spectral. With the RGB
/// mode's three wavelengths the sky at sunset is lavender where it is blue, and 5–16 %
/// brighter than the spectral value; once the tables are cached (`sky::bruneton4d::cache`)
/// the 16 wavelengths cost ×1.15 the RGB time of the default 1080p scene, ×1.6 for the sky
/// alone (`docs/accuracy.md`).
pub const DEFAULT_WAVELENGTHS: &str = "spectral";

fn default_preset() -> String {
    "earth".into()
}

/// Image size.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneImage {
    /// Width (pixels).
    pub width: usize,
    /// Height (pixels).
    pub height: usize,
}

/// The sun.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneSun {
    /// Zenith angle (degrees, 0–180); the default scene's when absent (a dated scene's
    /// `[sun]` says only whether the disk is drawn).
    #[serde(default = "default_sun_zenith")]
    pub zenith_deg: f64,
    /// Azimuth (degrees clockwise from north); the default scene's when absent.
    #[serde(default = "default_sun_azimuth")]
    pub azimuth_deg: f64,
    /// Draw the solar disk.
    #[serde(default = "yes")]
    pub disk: bool,
}

fn default_sun_zenith() -> f64 {
    SceneSun::default().zenith_deg
}

fn default_sun_azimuth() -> f64 {
    SceneSun::default().azimuth_deg
}

fn yes() -> bool {
    true
}

/// Where the observer stands on the Earth (with `[time]`, the sun and the moon follow).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneLocation {
    /// Latitude (degrees north, [−90, 90]).
    pub lat_deg: f64,
    /// Longitude (degrees east, [−180, 360)).
    pub lon_deg: f64,
    /// Height above the ellipsoid (m) for the parallax; the camera's altitude is separate.
    #[serde(default)]
    pub elevation_m: f64,
    /// Surface pressure for refraction (hPa).
    #[serde(default = "standard_pressure")]
    pub pressure_hpa: f64,
    /// Surface temperature for refraction (°C).
    #[serde(default = "standard_temperature")]
    pub temperature_c: f64,
}

fn standard_pressure() -> f64 {
    crate::astro::Weather::default().pressure_hpa
}
fn standard_temperature() -> f64 {
    crate::astro::Weather::default().temperature_c
}

/// When: an instant, ISO 8601 with `Z` or an offset.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneTime {
    /// The instant, e.g. `2026-06-21T16:30:00+02:00`.
    pub at: String,
    /// Draw the moon's disk (its light is always there).
    #[serde(default = "yes")]
    pub moon_disk: bool,
}

/// Exposure, tone mapping and files.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneOutput {
    /// Exposure value at ISO 100; automatic (log-average luminance) when absent.
    #[serde(default)]
    pub ev100: Option<f64>,
    /// Tone curve for PNG output.
    #[serde(default)]
    pub tonemap: ToneCurve,
    /// White-balance to the sun's colour.
    #[serde(default)]
    pub white_balance: bool,
    /// Output files; the format follows the extension (.png, .exr, .hdr).
    #[serde(default = "default_files")]
    pub files: Vec<PathBuf>,
}

fn default_files() -> Vec<PathBuf> {
    vec![
        PathBuf::from("firmament.png"),
        PathBuf::from("firmament.exr"),
    ]
}

/// A whole scene file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    /// Atmosphere.
    pub atmosphere: SceneAtmosphere,
    /// Camera.
    pub camera: Camera,
    /// Image size.
    pub image: SceneImage,
    /// Sun (from `[time]` and `[location]` when those are given; then `[sun]` may only
    /// say whether its disk is drawn).
    #[serde(default)]
    pub sun: SceneSun,
    /// Where, for `[time]`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub location: Option<SceneLocation>,
    /// When: the sun, the moon and the night sky from the date.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub time: Option<SceneTime>,
    /// Mountains around the observer (none: the planet's smooth sphere). The camera's
    /// altitude is then above the terrain's surface below it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub terrain: Option<TerrainConfig>,
    /// The planet's ground seen from afar: a map (procedural by default) with oceans, land
    /// and ice, and the sun's glint (none: the atmosphere's uniform ground albedo).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub surface: Option<super::planet_config::SurfaceConfig>,
    /// Cloud layers (`[[clouds]]`), none by default in a file.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub clouds: Vec<super::clouds::CloudLayerConfig>,
    /// Output.
    pub output: SceneOutput,
}

impl Default for SceneSun {
    /// 5.5° high in the south-west, behind a peak from the default camera: golden hour.
    fn default() -> Self {
        SceneSun {
            zenith_deg: 84.5,
            azimuth_deg: 237.0,
            disk: true,
        }
    }
}

impl Default for SceneFile {
    /// Golden hour in an alpine valley: the camera 25 m above the valley floor looking
    /// west-south-west up the valley towards the low sun behind the ridges, the light
    /// shafts in the air between them, a few cumulus over the ridges.
    fn default() -> Self {
        SceneFile {
            atmosphere: SceneAtmosphere {
                preset: default_preset(),
                file: None,
                wavelengths: None,
                adjust: Adjustments::default(),
            },
            camera: Camera {
                projection: Projection::Perspective,
                altitude_m: 25.0,
                heading_deg: 250.0,
                pitch_deg: 6.0,
                roll_deg: 0.0,
                fov_deg: 55.0,
            },
            image: SceneImage {
                width: 1920,
                height: 1080,
            },
            sun: SceneSun::default(),
            location: None,
            time: None,
            terrain: Some(TerrainConfig::default()),
            surface: None,
            clouds: vec![default_cumulus()],
            output: SceneOutput {
                ev100: None,
                tonemap: ToneCurve::Aces,
                white_balance: false,
                files: default_files(),
            },
        }
    }
}

/// The default scene's few cumulus: a fair-weather layer based above the valley's ridges
/// (~2.8 km), a tenth of the sky (coverage 0.12: a cluster over the northern ridge, the
/// valley's shafts towards the sun left clear).
fn default_cumulus() -> super::clouds::CloudLayerConfig {
    super::clouds::CloudLayerConfig {
        bottom_m: Some(3200.0),
        top_m: Some(5000.0),
        coverage: Some(0.12),
        ..super::clouds::CloudLayerConfig::of_kind(super::clouds::CloudKind::Cumulus)
    }
}

impl SceneFile {
    /// Parse a scene file; relative paths are resolved against its directory.
    pub fn from_file(path: &Path) -> Result<SceneFile> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::File {
            path: path.display().to_string(),
            reason: e.to_string(),
        })?;
        let mut scene: SceneFile = toml::from_str(&text)
            .map_err(|e| Error::Toml(format!("scene {}: {e}", path.display())))?;
        // The sun's place comes from the date or from the angles, never both.
        let raw: toml::Table = toml::from_str(&text)
            .map_err(|e| Error::Toml(format!("scene {}: {e}", path.display())))?;
        let sun_angles = raw
            .get("sun")
            .and_then(|s| s.as_table())
            .is_some_and(|s| s.contains_key("zenith_deg") || s.contains_key("azimuth_deg"));
        if scene.time.is_some() && sun_angles {
            return Err(Error::invalid(
                "sun.zenith_deg/sun.azimuth_deg",
                "given with [time]",
                "either [time] (with [location]) or the sun's angles, not both",
            ));
        }
        if let (Some(f), Some(dir)) = (&scene.atmosphere.file, path.parent()) {
            if f.is_relative() {
                scene.atmosphere.file = Some(dir.join(f));
            }
        }
        if let (Some(t), Some(dir)) = (&mut scene.terrain, path.parent()) {
            t.resolve_paths(dir);
        }
        if let (Some(s), Some(dir)) = (&mut scene.surface, path.parent()) {
            s.resolve_paths(dir);
        }
        if let Some(dir) = path.parent() {
            scene.clouds.iter_mut().for_each(|c| c.resolve_paths(dir));
        }
        scene.validate()?;
        Ok(scene)
    }

    /// The sun and the moon of `[time]` at `[location]`, when given.
    pub fn astro(&self) -> Result<Option<crate::astro::Sky>> {
        let (Some(t), Some(l)) = (&self.time, &self.location) else {
            return Ok(None);
        };
        let instant = crate::astro::Instant::parse(&t.at, "time.at")?;
        let place = crate::astro::Place::new(l.lat_deg, l.lon_deg, l.elevation_m)
            .map_err(|e| e.prefixed("location."))?;
        let weather = crate::astro::Weather::new(l.pressure_hpa, l.temperature_c)
            .map_err(|e| e.prefixed("location."))?;
        crate::astro::Sky::at(instant, place, &weather).map(Some)
    }

    /// The terrain of `[terrain]` on `model`'s planet, its materials at the model's
    /// wavelengths.
    pub fn build_terrain(
        &self,
        model: &crate::atmosphere::Model,
    ) -> Result<Option<super::terrain::Heightfield>> {
        self.terrain
            .as_ref()
            .map(|t| t.build(model.bottom_radius_m, model.wavelengths.nm()))
            .transpose()
    }

    /// The planet's ground of `[surface]` on a planet of radius `radius_m` (the terrain's,
    /// when there is one), the observer at `[location]` (or 0° N, 0° E), its spectra at
    /// `wavelengths_nm`.
    pub fn build_surface(
        &self,
        radius_m: f64,
        wavelengths_nm: &[f64],
    ) -> Result<Option<super::planet::PlanetSurface>> {
        let (lat, lon) = self
            .location
            .as_ref()
            .map_or((0.0, 0.0), |l| (l.lat_deg, l.lon_deg));
        self.surface
            .as_ref()
            .map(|s| s.build(radius_m, lat, lon, wavelengths_nm))
            .transpose()
    }

    /// The camera, its altitude taken above `terrain`'s surface below the observer when
    /// there is one (as `[terrain]` documents), as an altitude above a sky method's bottom
    /// sphere of radius `bottom_radius_m` (the terrain's planet, or its lifted ground).
    pub fn camera_over(
        &self,
        terrain: Option<&super::terrain::Heightfield>,
        bottom_radius_m: f64,
    ) -> Camera {
        let mut camera = self.camera.clone();
        if let Some(t) = terrain {
            camera.altitude_m += t.height_at(0.0, 0.0) - (bottom_radius_m - t.radius_m);
        }
        camera
    }

    /// The cloud layers' volumes over a planet of `planet_radius_m`, their noise textures
    /// read from (or computed into) the cache directory `cache`; empty without `[[clouds]]`.
    pub fn build_clouds(
        &self,
        planet_radius_m: f64,
        cache: Option<&Path>,
    ) -> Result<Vec<super::clouds::CloudMedium>> {
        if self.clouds.is_empty() {
            return Ok(Vec::new());
        }
        let sizes = [super::clouds::BASE_SHAPE_SIZE, super::clouds::EROSION_SIZE];
        let (noise, _) = super::clouds::CloudNoise::new(sizes, cache)?;
        let location = self
            .location
            .as_ref()
            .map_or((0.0, 0.0), |l| (l.lat_deg, l.lon_deg));
        super::clouds::cloud_media(&self.clouds, planet_radius_m, location, &noise)
    }

    /// Check every value; messages name the field.
    pub fn validate(&self) -> Result<()> {
        self.camera.validate()?;
        self.atmosphere
            .adjust
            .validate()
            .map_err(|e| e.prefixed("atmosphere."))?;
        let (w, h) = (self.image.width, self.image.height);
        if !(1..=32768).contains(&w) {
            return Err(Error::invalid("image.width", w, "an integer in [1, 32768]"));
        }
        if !(1..=32768).contains(&h) {
            return Err(Error::invalid(
                "image.height",
                h,
                "an integer in [1, 32768]",
            ));
        }
        if self.camera.projection == Projection::Cubemap && w != 6 * h {
            return Err(Error::invalid(
                "image.width",
                w,
                format!("6 × image.height ({}) for a cube map", 6 * h),
            ));
        }
        if self.camera.projection == Projection::Equirect && w != 2 * h {
            return Err(Error::invalid(
                "image.width",
                w,
                format!("2 × image.height ({}) for an equirect map", 2 * h),
            ));
        }
        if !(self.sun.zenith_deg.is_finite() && (0.0..=180.0).contains(&self.sun.zenith_deg)) {
            return Err(Error::invalid(
                "sun.zenith_deg",
                self.sun.zenith_deg,
                "a number in [0, 180] degrees",
            ));
        }
        if !(self.sun.azimuth_deg.is_finite() && self.sun.azimuth_deg.abs() <= 360.0) {
            return Err(Error::invalid(
                "sun.azimuth_deg",
                self.sun.azimuth_deg,
                "a number in [-360, 360] degrees",
            ));
        }
        if self.time.is_some() && self.location.is_none() {
            return Err(Error::invalid(
                "location",
                "missing",
                "a [location] with lat_deg and lon_deg when [time] is given",
            ));
        }
        self.astro()?;
        if let Some(t) = &self.terrain {
            t.validate()?;
        }
        if let Some(s) = &self.surface {
            s.validate()?;
        }
        super::clouds::validate_layers(&self.clouds)?;
        if let Some(ev) = self.output.ev100 {
            if !(ev.is_finite() && (-20.0..=30.0).contains(&ev)) {
                return Err(Error::invalid("output.ev100", ev, "a number in [-20, 30]"));
            }
        }
        if self.output.files.is_empty() {
            return Err(Error::invalid("output.files", "[]", "at least one file"));
        }
        for (i, f) in self.output.files.iter().enumerate() {
            let format = crate::io::OutputFormat::from_path(f).map_err(|_| {
                Error::invalid(
                    format!("output.files[{i}]"),
                    f.display(),
                    "a file name ending in .png, .exr, .hdr, .dds or .ktx2",
                )
            })?;
            let cube_file = matches!(
                format,
                crate::io::OutputFormat::Dds | crate::io::OutputFormat::Ktx2
            );
            if cube_file && self.camera.projection != Projection::Cubemap {
                return Err(Error::invalid(
                    format!("output.files[{i}]"),
                    f.display(),
                    "a .png, .exr or .hdr file: a .dds or .ktx2 file holds a cube map (projection = \"cubemap\")",
                ));
            }
        }
        Ok(())
    }
}

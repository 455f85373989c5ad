//! firmament: a physically based sky, atmosphere and cloud renderer.
//!
//! Data flows one way: an [`atmosphere::Atmosphere`] (parameters, TOML, presets) is resolved
//! for a wavelength grid into an [`atmosphere::Model`]; a sky method ([`sky::SkyMethod`],
//! e.g. the precomputed tables of [`sky::bruneton4d`]) evaluates its light transport; a
//! [`scene::Scene`] composes it with surfaces, volumes and lights; [`render`] turns the
//! scene into a [`render::Frame`] seen by a camera; [`io`] writes the files. The
//! [`reference`](mod@reference) path tracer computes the same quantities by Monte Carlo, to
//! measure every approximation against.
//!
//! # Units and frames
//!
//! SI units throughout, named in the field or the doc comment: lengths in metres
//! (`altitude_m`), angles in radians unless named `_deg`, wavelengths in nm. Spectral
//! quantities are one value per channel of the model's wavelength grid
//! ([`spectrum::Wavelengths`]): radiance in W·m⁻²·sr⁻¹·nm⁻¹, irradiance in W·m⁻²·nm⁻¹.
//! [`spectrum::luminance_from_spectrum`] turns them into luminance (cd/m²) and illuminance
//! (lux); a rendered [`render::Frame`] is linear Rec. 709 with Y in cd/m².
//!
//! Positions are planet-centred (m). The observer stands above the planet's +z pole, where
//! the local frame is x = east, y = north, z = up; zenith angles are measured from +z and
//! azimuths clockwise from north ([`math::direction_from_zenith_azimuth`],
//! [`scene::sun_direction`]).
//!
//! # Use it as a library
//!
//! Resolve a preset, precompute its tables, ask a [`sky::SkyView`] for the sky's radiance
//! along a few rays and the sun's light on the ground, then render a small image:
//!
//! ```
//! use firmament::atmosphere::Atmosphere;
//! use firmament::math::{direction_from_zenith_azimuth, Vec3};
//! use firmament::render::{self, tonemap, RenderSettings, ToneCurve};
//! use firmament::scene::{sun_direction, Camera, Light, Projection, Scene};
//! use firmament::sky::bruneton4d::{Bruneton4d, TableConfig, TableSizes};
//! use firmament::sky::{Shadow, SkyMethod};
//! use firmament::spectrum::{luminance_from_spectrum, Wavelengths};
//!
//! # fn main() -> firmament::Result<()> {
//! // The `earth` preset at three wavelengths: 680, 550 and 440 nm.
//! let model = Atmosphere::preset("earth")?.resolve(&Wavelengths::rgb())?;
//! let nm = model.wavelengths.nm().to_vec();
//!
//! // Bruneton's 4D tables. Small tables and 3 orders take a second or two;
//! // `TableConfig::default()` (Bruneton 2017's sizes, 4 orders) is the accurate choice.
//! let config = TableConfig {
//!     sizes: TableSizes::small(),
//!     orders: 3,
//!     ..TableConfig::default()
//! };
//! let sky = Bruneton4d::compute(model, &config)?;
//!
//! // An observer 1.5 m above the ground; the sun 30° from the zenith, in the south.
//! let observer = Vec3::new(0.0, 0.0, sky.model.bottom_radius_m + 1.5);
//! let sun = Light::sun(&sky.model, sun_direction(30.0, 180.0), true);
//! let view = sky.view(observer, &sun);
//!
//! // Sky radiance (W·m⁻²·sr⁻¹·nm⁻¹ per channel) and transmittance along a ray; the
//! // luminance (cd/m²) of that spectrum.
//! let n = sky.channels();
//! let (mut radiance, mut transmittance) = (vec![0.0; n], vec![0.0; n]);
//! view.sky_radiance(Vec3::Z, Shadow::None, &mut radiance, &mut transmittance);
//! let zenith_cd_m2 = luminance_from_spectrum(&nm, &radiance);
//! // A clear sky's zenith with the sun 60° high: a few thousand cd/m², bluer than red.
//! assert!((2_000.0..8_000.0).contains(&zenith_cd_m2), "{zenith_cd_m2}");
//! assert!(radiance[2] > 2.0 * radiance[0], "440 nm over 680 nm: {radiance:?}");
//!
//! // Towards the horizon opposite the sun, 85° from the zenith in the north.
//! let north = direction_from_zenith_azimuth(85f64.to_radians(), 0.0);
//! view.sky_radiance(north, Shadow::None, &mut radiance, &mut []);
//! assert!(luminance_from_spectrum(&nm, &radiance) > zenith_cd_m2);
//!
//! // The sun's direct illuminance on a surface facing it (lux), and the direct and sky
//! // irradiance (W·m⁻²·nm⁻¹) on a horizontal surface.
//! let mut t_sun = vec![0.0; n];
//! view.transmittance_to_light(observer, &mut t_sun);
//! let beam: Vec<f64> = sun.irradiance.iter().zip(&t_sun).map(|(e, t)| e * t).collect();
//! let direct_normal_lux = luminance_from_spectrum(&nm, &beam);
//! assert!((80e3..125e3).contains(&direct_normal_lux), "{direct_normal_lux}");
//! let (mut direct, mut diffuse) = (vec![0.0; n], vec![0.0; n]);
//! view.sun_and_sky_irradiance(observer, Vec3::Z, &mut direct, &mut diffuse);
//! let sky_lux = luminance_from_spectrum(&nm, &diffuse);
//! assert!((5e3..40e3).contains(&sky_lux), "{sky_lux}");
//!
//! // A 64×32 equirectangular map of the scene (ground, sky, the sun's disk); the frame is
//! // linear Rec. 709 with Y in cd/m². Expose it like a camera's meter and write a PNG.
//! let scene = Scene::clear_sky(&sky, sun.direction, true);
//! let camera = Camera {
//!     projection: Projection::Equirect,
//!     altitude_m: 1.5,
//!     heading_deg: 0.0,
//!     pitch_deg: 0.0,
//!     roll_deg: 0.0,
//!     fov_deg: 60.0,
//! };
//! let settings = RenderSettings { camera: &camera, width: 64, height: 32, white_balance: false };
//! let frame = render::render(&scene, &settings, &|_fraction_done| {}, None)?;
//! let top = frame.image.get(32, 0); // just below the zenith
//! assert!(top[2] > top[0], "the sky is blue: {top:?}");
//! let ev100 = tonemap::auto_ev100(frame.log_average_luminance());
//! let rgb8 = frame.to_srgb8(tonemap::exposure_from_ev100(ev100, ToneCurve::Aces), ToneCurve::Aces);
//! let dir = std::env::temp_dir().join(format!("firmament-doc-{}", std::process::id()));
//! std::fs::create_dir_all(&dir).unwrap();
//! firmament::io::write_png_srgb8(dir.join("sky.png"), 64, 32, &rgb8)?;
//! # std::fs::remove_dir_all(&dir).unwrap();
//! # Ok(())
//! # }
//! ```
//!
//! Full-size tables take 10–20 s on two cores (more with spectral wavelengths: 16 channels
//! instead of 3). Compute them once with `firmament bake --out earth.lut` (the same
//! atmosphere and wavelength flags as `render`) or [`sky::bruneton4d::file::write`], and load
//! them with [`sky::bruneton4d::file::read`] and [`Bruneton4d::new`](sky::Bruneton4d::new),
//! which refuses tables baked for another atmosphere or wavelength grid:
//!
//! ```no_run
//! # use firmament::{atmosphere::Atmosphere, spectrum::Wavelengths};
//! # use firmament::sky::bruneton4d::{file, Bruneton4d};
//! # fn main() -> firmament::Result<()> {
//! let model = Atmosphere::preset("earth")?.resolve(&Wavelengths::rgb())?;
//! let tables = file::read(std::path::Path::new("earth.lut"))?;
//! let sky = Bruneton4d::new(model, tables)?;
//! # Ok(())
//! # }
//! ```
//!
//! `examples/sky_query.rs` does all of this with more output (chromaticities, linear
//! sRGB, an EXR of the map in physical units): `cargo run --release -p firmament --example
//! sky_query`.

#![warn(missing_docs)]

pub mod astro;
pub mod atmosphere;
pub mod error;
pub mod io;
pub mod math;
pub mod medium;
pub mod reference;
pub mod render;
pub mod scene;
pub mod sky;
pub mod spectrum;

pub use error::{Error, Result};

//! The clouds on the GPU: the scene's cloud layers ([`CloudMedium`]) with their weather maps
//! (a layer with `weather_wrap = "planet"`: the planet's map and its two detail maps too),
//! the shared noise volumes, each layer's two-stream tables, the mean density its view's
//! filter blends towards (`CloudLayer::filter`, `shaders/clouds/lod.wgsl`) and each light's
//! shadow map (computed on the CPU by [`firmament::render::cloud_shadow::CloudShadow`], taken
//! from the CPU's [`Shader`] of the same scene), packed into one storage buffer (binding 19),
//! and the uniform that says where each part lies (binding 20, `shaders/clouds/layer.wgsl`). The
//! render pass marches them as the CPU does (`shaders/clouds/`, `shaders/render/volumes.wgsl`,
//! `shaders/render/cloud_frame.wgsl`) in f32, in metres relative to the observer's foot.
//!
//! ```no_run
//! # fn demo(ctx: &firmament_gpu::GpuContext, sky: &firmament_gpu::GpuSky,
//! #         media: &[firmament::scene::clouds::CloudMedium],
//! #         shader: &firmament::render::Shader) -> Result<(), firmament_gpu::GpuError> {
//! // `shader`: Shader::new of the CPU scene with the clouds, from the frame's observer.
//! let clouds = firmament_gpu::GpuClouds::new(ctx, sky, media, shader)?;
//! let inputs = firmament_gpu::RenderInputs { clouds: Some(&clouds), ..Default::default() };
//! # let _ = inputs; Ok(()) }
//! ```

use std::sync::Arc;

use firmament::math::Vec3;
use firmament::render::{RenderSettings, Shader};
use firmament::scene::clouds::lod::{COVERAGES, HEIGHTS, TYPES};
use firmament::scene::clouds::{CloudKind, CloudMedium, ViewFootprint};
use firmament::scene::Light;
use firmament::scene::Volume;

use crate::bruneton4d::atmosphere::{groups, GROUP};
use crate::device::{check_buffers, scoped};
use crate::passes::init;
use crate::render::frame::MAX_LIGHTS;
use crate::{GpuContext, GpuError, GpuSky};

/// The most cloud layers a GPU frame takes.
pub const MAX_CLOUD_LAYERS: usize = 4;
/// `CloudLayerParams.kind` codes (`CLOUD_*` in WGSL).
pub const CLOUD_CUMULUS: u32 = 0;
pub const CLOUD_ALTOSTRATUS: u32 = 1;
pub const CLOUD_CIRRUS: u32 = 2;
pub const CLOUD_UNIFORM: u32 = 3;
/// Values per weather texel: coverage, type, precipitation, warp x, warp y.
pub const WEATHER_CHANNELS: usize = 5;
/// Values per texel of the planet's weather map: w, type, precipitation.
pub const PLANET_CHANNELS: usize = 3;
/// The planetary map's fine detail's gain (`PlanetaryWeather::detail`: DETAIL_GAIN·(½(a + b)
/// − ½)); a mirror of `scene::clouds::planetary::DETAIL_GAIN`, which is private there (the
/// test `the_planet_detail_gain_is_the_cpus` checks it against `PlanetaryWeather::detail`).
pub const PLANET_DETAIL_GAIN: f64 = 1.4;
/// "No data here" (`NONE` in WGSL).
const NONE: u32 = u32::MAX;
/// Words of one `CloudLayerParams`.
const LAYER_WORDS: usize = 56;
/// Words of the `Clouds` uniform: five vec4 rows, then the layers.
pub(crate) const UNIFORM_WORDS: usize = HEADER_WORDS + MAX_CLOUD_LAYERS * LAYER_WORDS;
/// Words of the `Clouds` uniform before its layers.
const HEADER_WORDS: usize = 20;
/// Word index of the observer's altitude in the uniform (`Clouds.observer_alt_m`), then
/// the tables' ground above the clouds' planet (`lift_m`).
const OBSERVER_WORD: usize = 10;
/// The most the tables' ground may be lifted above the clouds' planet (m): a terrain's
/// floor (the Dead Sea's shore to the Tibetan plateau's).
const MAX_LIFT_M: f64 = 10_000.0;
/// Word index of a layer's view (`CloudLayerParams.eye`, then `pixel_angle_rad`) in its
/// words.
const EYE_WORD: usize = 40;
/// Word index of a layer's mean density (`CloudLayerParams.mean_at`) in its words.
const MEAN_WORD: usize = 52;

/// The clouds of a scene and their lights' shadow maps, on the device.
pub struct GpuClouds {
    data: wgpu::Buffer,
    /// The uniform's words but the observer's altitude.
    words: Vec<u32>,
    /// The light directions the shadow maps were computed for.
    lights: Vec<Vec3>,
    /// The layers' planet (m from its centre).
    planet_radius_m: f64,
}

impl std::fmt::Debug for GpuClouds {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("GpuClouds")
            .field("lights", &self.lights.len())
            .finish()
    }
}

fn bits(x: f64) -> u32 {
    (x as f32).to_bits()
}

fn kind_code(kind: CloudKind) -> u32 {
    match kind {
        CloudKind::Cumulus => CLOUD_CUMULUS,
        CloudKind::Altostratus => CLOUD_ALTOSTRATUS,
        CloudKind::Cirrus => CLOUD_CIRRUS,
        CloudKind::Uniform => CLOUD_UNIFORM,
    }
}

impl GpuClouds {
    /// Upload `media` (the scene's cloud layers, at most [`MAX_CLOUD_LAYERS`], sharing one
    /// pair of noise volumes, over the planet of `sky`'s tables) for frames prepared by
    /// `shader` (the CPU's [`Shader`] of the same scene from the frame's observer, whose
    /// shadow maps are uploaded).
    pub fn new(
        ctx: &GpuContext,
        sky: &GpuSky,
        media: &[CloudMedium],
        shader: &Shader,
    ) -> Result<GpuClouds, GpuError> {
        let invalid = |field: &str, value: String, accepted: String| -> GpuError {
            firmament::Error::invalid(field, value, accepted).into()
        };
        let lights: Vec<&Light> = shader.lights().collect();
        if lights.len() > MAX_LIGHTS {
            return Err(invalid(
                "lights",
                lights.len().to_string(),
                format!("at most {MAX_LIGHTS} lights under GPU clouds"),
            ));
        }
        if media.is_empty() || media.len() > MAX_CLOUD_LAYERS {
            return Err(invalid(
                "clouds",
                format!("{} layers", media.len()),
                format!("1 to {MAX_CLOUD_LAYERS} layers on the GPU"),
            ));
        }
        // The layers' planet: the tables' ground, or a terrain's sphere under a ground
        // lifted to the terrain's floor (render's `terrain_and_atmosphere`).
        let bottom = sky.radii.bottom;
        let planet = media[0].layer.planet_radius_m;
        for (i, m) in media.iter().enumerate() {
            let r = m.layer.planet_radius_m;
            if (r - planet).abs() > 1.0 || !(bottom - MAX_LIFT_M - 1.0..=bottom + 1.0).contains(&r)
            {
                return Err(invalid(
                    &format!("clouds[{i}]"),
                    format!("a layer over a planet of radius {r} m"),
                    format!(
                        "every layer over one planet, from the tables' ground ({bottom} m) to {MAX_LIFT_M} m below it"
                    ),
                ));
            }
        }
        let lift = (bottom - planet).max(0.0);
        let mut data: Vec<f32> = Vec::new();
        // The noise volumes (every layer with noise shares one pair).
        let noise = media.iter().find_map(|m| m.layer.noise.clone());
        if let Some(n) = &noise {
            let same = media.iter().all(|m| {
                m.layer
                    .noise
                    .as_ref()
                    .is_none_or(|o| Arc::ptr_eq(&o[0], &n[0]) && Arc::ptr_eq(&o[1], &n[1]))
            });
            if !same {
                return Err(invalid(
                    "clouds",
                    "layers with different noise volumes".into(),
                    "one pair of noise volumes shared by every layer (scene::clouds::cloud_media)"
                        .into(),
                ));
            }
        }
        let (base_size, base_at, detail_size, detail_at) = match &noise {
            Some([base, detail]) => {
                let b = data.len() as u32;
                data.extend_from_slice(&base.data);
                let d = data.len() as u32;
                data.extend_from_slice(&detail.data);
                (base.size as u32, b, detail.size as u32, d)
            }
            None => (0, NONE, 0, NONE),
        };
        let mut layer_words = Vec::with_capacity(MAX_CLOUD_LAYERS * LAYER_WORDS);
        for (i, m) in media.iter().enumerate() {
            let l = &m.layer;
            let p = &l.params;
            let (ww, wh, weather_at) = match &l.weather {
                Some(w) => {
                    let at = data.len() as u32;
                    data.extend(w.texels.iter().flatten());
                    (w.width as u32, w.height as u32, at)
                }
                None => (0, 0, NONE),
            };
            let (ts_at, ts) = match &m.two_stream {
                Some(ts) => {
                    let at = data.len() as u32;
                    data.extend(ts.sun_table().iter().flatten().map(|&v| v as f32));
                    data.extend(ts.diffuse_table().iter().flatten().map(|&v| v as f32));
                    (
                        at,
                        [
                            ts.scattering_scale,
                            ts.extinction_scale,
                            ts.asymmetry,
                            ts.forward_phase_cap,
                        ],
                    )
                }
                None => (NONE, [1.0, 1.0, 0.0, 0.0]),
            };
            let o = m.octaves();
            let [g1, g2, weight] = p.phase;
            // The planet's weather: its [w, t, p] texels, its frame, and the two detail maps'
            // coverage (the only channel PlanetaryWeather::detail reads).
            let mut frame = [[0.0f64; 3]; 3];
            let (mut planet_at, mut planet_size) = (NONE, [0u32; 2]);
            let (mut detail_at, mut detail_width, mut detail_height, mut detail_tile) =
                ([NONE; 2], [0u32; 2], [0u32; 2], [0.0f64; 2]);
            // (A layer without weather, the uniform slab, never reads it: CloudLayer::local.)
            if let (Some(planetary), Some(_)) = (&l.planetary, &l.weather) {
                planet_at = data.len() as u32;
                data.extend(planetary.texels.iter().flatten());
                planet_size = [planetary.width as u32, planetary.height as u32];
                for (f, v) in frame.iter_mut().zip(&planetary.frame) {
                    *f = [v.x, v.y, v.z];
                }
                for (k, map) in planetary.detail.iter().enumerate() {
                    detail_at[k] = data.len() as u32;
                    data.extend(map.texels.iter().map(|t| t[0]));
                    detail_width[k] = map.width as u32;
                    detail_height[k] = map.height as u32;
                    detail_tile[k] = map.tile_m;
                }
            }
            // The view's filter: the mean density's table and χ, the camera and its pixels.
            let (mut mean_at, mut eye, mut pixel_angle) = (NONE, [0.0f64; 3], 0.0);
            if let Some((view, mean)) = &l.filter {
                let mean = mean.get();
                if mean.table.len() != TYPES * COVERAGES * HEIGHTS
                    || mean.chi.len() != TYPES * COVERAGES
                {
                    return Err(invalid(
                        &format!("clouds[{i}].filter"),
                        format!(
                            "a mean density of {} and {} values",
                            mean.table.len(),
                            mean.chi.len()
                        ),
                        "lod::MeanDensity's [type][coverage][height] table and χ".into(),
                    ));
                }
                mean_at = data.len() as u32;
                data.extend_from_slice(&mean.table);
                data.extend_from_slice(&mean.chi);
                eye = [view.eye.x, view.eye.y, view.eye.z];
                pixel_angle = view.pixel_angle_rad;
            }
            let words = [
                kind_code(p.kind),
                ww,
                wh,
                weather_at,
                bits(p.bottom_m),
                bits(p.top_m),
                bits(p.coverage),
                bits(p.extinction_per_m),
                bits(p.albedo),
                bits(g1),
                bits(g2),
                bits(weight),
                bits(m.phase.mean_cosine()),
                bits(p.tiles_m[0]),
                bits(p.tiles_m[1]),
                bits(p.tiles_m[2]),
                bits(p.kind.horizontal_stretch()),
                bits(p.wind_offset_m[0]),
                bits(p.wind_offset_m[1]),
                ts_at,
                bits(ts[0]),
                bits(ts[1]),
                bits(ts[2]),
                o.count,
                bits(o.scattering),
                bits(o.extinction),
                bits(o.eccentricity),
                bits(ts[3]),
                // 28: the planet's weather's frame (east, north, up), offset and size.
                bits(frame[0][0]),
                bits(frame[0][1]),
                bits(frame[0][2]),
                planet_at,
                bits(frame[1][0]),
                bits(frame[1][1]),
                bits(frame[1][2]),
                planet_size[0],
                bits(frame[2][0]),
                bits(frame[2][1]),
                bits(frame[2][2]),
                planet_size[1],
                // 40 (EYE_WORD): the view's eye (planet-centred) and pixel angle.
                bits(eye[0]),
                bits(eye[1]),
                bits(eye[2]),
                bits(pixel_angle),
                // 44: the detail maps.
                detail_at[0],
                detail_at[1],
                detail_width[0],
                detail_width[1],
                detail_height[0],
                detail_height[1],
                bits(detail_tile[0]),
                bits(detail_tile[1]),
                // 52 (MEAN_WORD): the mean density and the noise's cell.
                mean_at,
                bits(l.cell_m()),
                0,
                0,
            ];
            layer_words.extend(words);
        }
        layer_words.resize(MAX_CLOUD_LAYERS * LAYER_WORDS, 0);
        // The shadow maps, from the CPU's shader: per light the texels, the coarse map's
        // blocks and the shadowed air's weights w and the ground's g (channel groups of 4
        // per texel, padded with 1), one after another from shadow_at[light].
        let mut shadow_at = [NONE; MAX_LIGHTS];
        let mut shadow_base_m = 0.0;
        let maps = shader.cloud_shadows().iter().zip(shader.shadowed_air());
        for (j, (map, air)) in maps.enumerate().take(MAX_LIGHTS) {
            if let (Some(map), Some(air)) = (map, air) {
                shadow_at[j] = data.len() as u32;
                data.extend_from_slice(map.texels());
                data.extend_from_slice(map.coarse_texels());
                let n = air.channels();
                let padded = GROUP * groups(sky.channels);
                if n != sky.channels {
                    return Err(invalid(
                        "shader",
                        format!("a CPU shader of {n} channels"),
                        format!("the tables' {} channels", sky.channels),
                    ));
                }
                for table in [air.texels(), air.ground_texels()] {
                    for texel in table.chunks(n) {
                        data.extend_from_slice(texel);
                        data.extend(std::iter::repeat_n(1.0, padded - n));
                    }
                }
                shadow_base_m = map.base_radius_m() - planet;
            }
        }
        // The march's octaves: the most any layer asks for (volumes::composite).
        let octaves = media
            .iter()
            .map(|m| m.octaves())
            .max_by_key(|o| o.count)
            .expect("at least one layer");
        let feature = media
            .iter()
            .filter_map(|m| m.feature_size_m())
            .fold(f64::INFINITY, f64::min);
        // The far march's cap: the thinnest shell crossed in VERTICAL_STEPS
        // (volumes::composite).
        let thinnest = media
            .iter()
            .map(|m| m.layer.radii_m[1] - m.layer.radii_m[0])
            .fold(f64::INFINITY, f64::min);
        // Whether the coarse shadow map's edge stands for the clouds beyond it
        // (CloudShadow::mean_transmittance: not over a planet's weather).
        let extends = media.iter().all(|m| m.alike_everywhere());
        if data.is_empty() {
            data.push(0.0);
        }
        let bytes = (data.len() * 4) as u64;
        check_buffers(ctx, &[("clouds", bytes)])?;
        let mut words = vec![
            media.len() as u32,
            base_size,
            detail_size,
            base_at,
            detail_at,
            octaves.count,
            bits(octaves.extinction),
            bits(feature),
            bits(planet),
            bits(shadow_base_m),
            0, // the observer's altitude, per frame
            bits(lift),
        ];
        words.extend(shadow_at);
        words.extend([bits(thinnest), extends as u32, 0, 0]);
        assert_eq!(words.len(), HEADER_WORDS, "the Clouds uniform's header");
        words.extend(layer_words);
        assert_eq!(words.len(), UNIFORM_WORDS, "the Clouds uniform's layout");
        let data = scoped(ctx, "uploading the clouds", || {
            Ok(init(
                ctx.device(),
                "clouds",
                bytemuck::cast_slice(&data),
                wgpu::BufferUsages::STORAGE,
            ))
        })?;
        Ok(GpuClouds {
            data,
            words,
            planet_radius_m: planet,
            lights: lights.iter().map(|l| l.direction).collect(),
        })
    }

    /// Filter the density of every layer uploaded with a filter (`CloudLayer::filter`) over
    /// the footprint of `view`'s pixels from now on (the viewer's camera moves between
    /// uploads; `CloudLayer::set_view` on the CPU); the shadow maps keep the footprint they
    /// were computed with. Returns whether any layer has a filter.
    pub fn set_view(&mut self, view: ViewFootprint) -> bool {
        let layers = self.words[0] as usize;
        let mut any = false;
        for i in 0..layers {
            let w = &mut self.words[HEADER_WORDS + i * LAYER_WORDS..][..LAYER_WORDS];
            if w[MEAN_WORD] == NONE {
                continue;
            }
            w[EYE_WORD..EYE_WORD + 4].copy_from_slice(&[
                bits(view.eye.x),
                bits(view.eye.y),
                bits(view.eye.z),
                bits(view.pixel_angle_rad),
            ]);
            any = true;
        }
        any
    }

    /// The layers' planet (m from its centre): a terrain under them must lie on it.
    pub fn planet_radius_m(&self) -> f64 {
        self.planet_radius_m
    }

    /// The storage buffer (binding 19).
    pub(crate) fn data(&self) -> &wgpu::Buffer {
        &self.data
    }

    /// The uniform (binding 20) for a frame of `settings` over `sky`'s tables lit by
    /// `lights`, which must be the lights the clouds were uploaded for.
    pub(crate) fn uniform_words(
        &self,
        sky: &GpuSky,
        lights: &[Light],
        settings: &RenderSettings,
    ) -> Result<Vec<u32>, GpuError> {
        let same = lights.len() == self.lights.len()
            && lights
                .iter()
                .zip(&self.lights)
                .all(|(l, d)| l.direction == *d);
        if !same {
            return Err(firmament::Error::invalid(
                "lights",
                "other lights than the clouds'",
                "the lights GpuClouds::new was given (their shadow maps)",
            )
            .into());
        }
        let mut words = self.words.clone();
        // The camera stands above the tables' ground, which may be lifted above the
        // clouds' planet (a terrain's floor): its altitude above that planet.
        words[OBSERVER_WORD] =
            bits(sky.radii.bottom + settings.camera.altitude_m - self.planet_radius_m);
        Ok(words)
    }
}

/// The uniform of a frame without clouds (no layers).
pub(crate) fn no_clouds_words() -> Vec<u32> {
    vec![0; UNIFORM_WORDS]
}

#[cfg(test)]
mod tests {
    use super::*;
    use firmament::scene::clouds::planetary::PlanetaryWeather;
    use firmament::scene::clouds::weather::WeatherMap;

    #[test]
    fn the_planet_detail_gain_is_the_cpus() {
        // planetary.wgsl's detail is PLANET_DETAIL_GAIN·(½(a + b) − ½) of the maps' w.
        let map = |seed: u32, tile: f64| WeatherMap::procedural(CloudKind::Cumulus, seed, tile);
        let planet = PlanetaryWeather {
            width: 2,
            height: 1,
            texels: vec![[0.5; 3]; 2],
            frame: [Vec3::X, Vec3::Y, Vec3::Z],
            detail: [map(1, 617e3), map(2, 1013e3)],
        };
        let mut checked = 0;
        for (x, y) in [
            (1.0e3, 2.0e3),
            (-3.1e5, 7.7e5),
            (2.4e6, -9.0e5),
            (5.0e4, 5.0e4),
        ] {
            let [a, b] = &planet.detail;
            let mean = 0.5 * (a.sample(x, y)[0] + b.sample(x, y)[0]) - 0.5;
            if mean.abs() < 0.05 {
                continue;
            }
            let gain = planet.detail(x, y) / mean;
            assert!((gain - PLANET_DETAIL_GAIN).abs() < 1e-9, "{gain}");
            checked += 1;
        }
        assert!(checked >= 2, "too few points away from w = ½");
    }

    /// The size naga gives the render shader's WGSL struct `name`, and the offsets of its
    /// members.
    fn wgsl_struct(name: &str) -> (u32, Vec<(String, u32)>) {
        let source = crate::shader::render_source(None);
        let module = naga::front::wgsl::parse_str(&source).unwrap();
        let mut layouter = naga::proc::Layouter::default();
        layouter.update(module.to_ctx()).unwrap();
        let (handle, ty) = (module.types.iter())
            .find(|(_, t)| t.name.as_deref() == Some(name))
            .unwrap_or_else(|| panic!("no struct {name}"));
        let naga::TypeInner::Struct { members, .. } = &ty.inner else {
            panic!("{name} is not a struct");
        };
        let offsets = members
            .iter()
            .map(|m| (m.name.clone().unwrap_or_default(), m.offset))
            .collect();
        (layouter[handle].size, offsets)
    }

    #[test]
    fn the_uniform_words_are_the_shader_structs() {
        let offset = |members: &[(String, u32)], name: &str| {
            let (_, at) = members.iter().find(|(n, _)| n == name).unwrap();
            *at as usize / 4
        };
        let (size, members) = wgsl_struct("CloudLayerParams");
        assert_eq!(size as usize, 4 * LAYER_WORDS);
        assert_eq!(offset(&members, "planet_east"), 28);
        assert_eq!(offset(&members, "eye"), EYE_WORD);
        assert_eq!(offset(&members, "pixel_angle_rad"), EYE_WORD + 3);
        assert_eq!(offset(&members, "planet_detail_at"), 44);
        assert_eq!(offset(&members, "mean_at"), MEAN_WORD);
        let (size, members) = wgsl_struct("Clouds");
        assert_eq!(size as usize, 4 * UNIFORM_WORDS);
        assert_eq!(offset(&members, "observer_alt_m"), OBSERVER_WORD);
        assert_eq!(offset(&members, "lift_m"), OBSERVER_WORD + 1);
        assert_eq!(offset(&members, "thinnest_m"), 16);
        assert_eq!(offset(&members, "layer"), HEADER_WORDS);
    }
}

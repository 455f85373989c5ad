//! The clouds on the GPU: the scene's cloud layers ([`CloudMedium`]) with their weather maps,
//! the shared noise volumes, each layer's two-stream tables and each light's shadow map
//! (computed on the CPU by [`firmament::render::cloud_shadow::CloudShadow`], taken from the
//! CPU's [`Shader`] of the same scene), packed into one storage buffer (binding 19), and the
//! uniform that says where each part lies (binding 20, `shaders/clouds/layer.wgsl`). The
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
use firmament::scene::clouds::{CloudKind, CloudMedium};
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
/// "No data here" (`NONE` in WGSL).
const NONE: u32 = u32::MAX;
/// Words of one `CloudLayerParams`.
const LAYER_WORDS: usize = 28;
/// Words of the `Clouds` uniform: three vec4 rows, then the layers.
pub(crate) const UNIFORM_WORDS: usize = 16 + MAX_CLOUD_LAYERS * LAYER_WORDS;
/// Word index of the observer's altitude in the uniform (`Clouds.observer_alt_m`).
const OBSERVER_WORD: usize = 10;

/// The clouds of a scene and their lights' shadow maps, on the device.
pub struct GpuClouds {
    data: wgpu::Buffer,
    /// The uniform's words but the observer's altitude.
    words: Vec<u32>,
    /// The light directions the shadow maps were computed for.
    lights: Vec<Vec3>,
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
        let planet = sky.radii.bottom;
        for (i, m) in media.iter().enumerate() {
            if m.layer.planetary.is_some() {
                return Err(invalid(
                    &format!("clouds[{i}].weather_wrap"),
                    "planet".into(),
                    "tile on the GPU (the planet's weather is marched on the CPU: --backend cpu)"
                        .into(),
                ));
            }
            if (m.layer.planet_radius_m - planet).abs() > 1.0 {
                return Err(invalid(
                    &format!("clouds[{i}]"),
                    format!(
                        "a layer over a planet of radius {} m",
                        m.layer.planet_radius_m
                    ),
                    format!("the tables' ground, {planet} m"),
                ));
            }
        }
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
        for m in media {
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
                    (at, [ts.scattering_scale, ts.extinction_scale, ts.asymmetry])
                }
                None => (NONE, [1.0, 1.0, 0.0]),
            };
            let o = m.octaves();
            let [g1, g2, weight] = p.phase;
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
                0,
            ];
            layer_words.extend(words);
        }
        layer_words.resize(MAX_CLOUD_LAYERS * LAYER_WORDS, 0);
        // The shadow maps, from the CPU's shader: per light the texels, the coarse map's
        // blocks and the shadowed air's weights (channel groups of 4 per texel, padded
        // with 1), one after another from shadow_at[light].
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
                for texel in air.texels().chunks(n) {
                    data.extend_from_slice(texel);
                    data.extend(std::iter::repeat_n(1.0, padded - n));
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
            0,
        ];
        words.extend(shadow_at);
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
            lights: lights.iter().map(|l| l.direction).collect(),
        })
    }

    /// The storage buffer (binding 19).
    pub(crate) fn data(&self) -> &wgpu::Buffer {
        &self.data
    }

    /// The uniform (binding 20) for a frame of `settings` lit by `lights`, which must be
    /// the lights the clouds were uploaded for.
    pub(crate) fn uniform_words(
        &self,
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
        words[OBSERVER_WORD] = bits(settings.camera.altitude_m);
        Ok(words)
    }
}

/// The uniform of a frame without clouds (no layers).
pub(crate) fn no_clouds_words() -> Vec<u32> {
    vec![0; UNIFORM_WORDS]
}

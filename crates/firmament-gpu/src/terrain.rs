//! The terrain on the GPU: a [`Heightfield`] with its max-mip pyramid, its sky visibility
//! and horizons, each light's shadow-height field with its three pyramids and clearance
//! (computed on the CPU by the sweep, `scene::terrain::shadow`), each light's sky dome
//! (`render::sky_dome`) and the observer's air volume (`render::air_volume`), both from the
//! CPU's [`Shader`], packed into one storage buffer, and the
//! uniform that says where each part lies (`shaders/terrain/terrain.wgsl`). The render pass
//! walks them as the CPU does (`shaders/terrain/`: grid, heightfield, shadow, materials) in
//! f32, in metres relative to the observer's foot.
//!
//! ```no_run
//! # fn demo(ctx: &firmament_gpu::GpuContext, sky: &firmament_gpu::GpuSky,
//! #         terrain: &firmament::scene::terrain::Heightfield,
//! #         shader: &firmament::render::Shader) -> Result<(), firmament_gpu::GpuError> {
//! // `shader`: Shader::new of the CPU scene with the terrain, from the frame's observer.
//! let gpu_terrain = firmament_gpu::GpuTerrain::new(ctx, sky, terrain, shader)?;
//! let inputs = firmament_gpu::RenderInputs { terrain: Some(&gpu_terrain), ..Default::default() };
//! # let _ = inputs; Ok(()) }
//! ```

use firmament::math::Vec3;
use firmament::render::air_volume;
use firmament::render::{RenderSettings, Shader};
use firmament::scene::terrain::grid::{Grid, MaxPyramid};
use firmament::scene::terrain::shadow::EDGE_MARGIN;
use firmament::scene::terrain::{Heightfield, Materials};
use firmament::scene::Light;
use firmament::spectrum::MAX_CHANNELS;

use crate::bruneton4d::atmosphere::GROUP;
use crate::device::{check_buffers, scoped};
use crate::passes::init;
use crate::render::frame::MAX_LIGHTS;
use crate::{GpuContext, GpuError, GpuSky};

/// Pyramid levels the uniform holds (a grid of 8 193 vertices a side has 14).
pub const MAX_PYRAMID_LEVELS: usize = 16;
/// vec4 of material albedo in the uniform: four materials per channel group.
pub const TERRAIN_ALBEDO_VEC4: usize = 4 * MAX_CHANNELS / GROUP;
/// `Terrain.flags`: a terrain is bound.
pub const TERRAIN_PRESENT: u32 = 1;
/// `Terrain.flags`: it casts shadows (on itself and the ground).
pub const TERRAIN_CASTS_SHADOWS: u32 = 2;
/// `Terrain.flags`: and into the air (the light shafts).
pub const TERRAIN_SHAFTS: u32 = 4;
/// `Terrain.flags`: ambient occlusion of the sky light.
pub const TERRAIN_OCCLUSION: u32 = 8;
/// `Terrain.flags`: one albedo everywhere (the snow rows).
pub const TERRAIN_UNIFORM_ALBEDO: u32 = 16;
/// "No field here" (`NONE` in WGSL).
const NONE: u32 = u32::MAX;
/// Words of the `Terrain` uniform: seven vec4 rows, two per light, the pyramid's levels and
/// the albedo rows.
pub(crate) const UNIFORM_WORDS: usize =
    4 * (7 + 2 * MAX_LIGHTS + MAX_PYRAMID_LEVELS) + 4 * TERRAIN_ALBEDO_VEC4;

/// A terrain, its lights' shadow fields and the observer's air volume, on the device.
pub struct GpuTerrain {
    data: wgpu::Buffer,
    /// The uniform's words but the observer's height.
    words: Vec<u32>,
    radius_m: f64,
    /// The light directions the shadow fields were computed for.
    lights: Vec<Vec3>,
}

impl std::fmt::Debug for GpuTerrain {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("GpuTerrain")
            .field("radius_m", &self.radius_m)
            .field("lights", &self.lights.len())
            .finish()
    }
}

/// Word index of the observer's height in the uniform (`Terrain.observer_height_m`).
const OBSERVER_WORD: usize = 11;

/// Append a pyramid's levels to `data`; their (w, h, offset from the pyramid's start).
fn push_pyramid(data: &mut Vec<f32>, pyramid: &MaxPyramid) -> Vec<[u32; 3]> {
    let start = data.len();
    pyramid
        .levels()
        .map(|(w, h, v)| {
            let at = (data.len() - start) as u32;
            data.extend_from_slice(v);
            [w as u32, h as u32, at]
        })
        .collect()
}

fn bits(x: f64) -> u32 {
    (x as f32).to_bits()
}

impl GpuTerrain {
    /// The terrain's sphere (m from the planet's centre): heights are above it.
    pub fn radius_m(&self) -> f64 {
        self.radius_m
    }

    /// Upload `terrain` for frames prepared by `shader` (the CPU's [`Shader`] of the same
    /// scene from the frame's observer, over the tables of `sky`): its lights' shadow
    /// fields (computed here on the CPU when the terrain casts light shafts), its air volume
    /// (the terrain's change of the air's light) and its sky domes (the sky's radiance under
    /// the terrain's horizons), those it has.
    pub fn new(
        ctx: &GpuContext,
        sky: &GpuSky,
        terrain: &Heightfield,
        shader: &Shader,
    ) -> Result<GpuTerrain, GpuError> {
        let lights: Vec<&Light> = shader.lights().collect();
        if lights.len() > MAX_LIGHTS {
            return Err(firmament::Error::invalid(
                "lights",
                lights.len(),
                format!("at most {MAX_LIGHTS} lights over a GPU terrain"),
            )
            .into());
        }
        let grid = &terrain.heights;
        let levels_of = |p: &MaxPyramid| p.levels().count();
        if levels_of(terrain.pyramid()) > MAX_PYRAMID_LEVELS {
            return Err(firmament::Error::invalid(
                "terrain.resolution",
                grid.nx.max(grid.ny),
                format!(
                    "at most {} vertices a side on the GPU",
                    (1 << (MAX_PYRAMID_LEVELS - 1)) + 1
                ),
            )
            .into());
        }
        let mut data: Vec<f32> = Vec::new();
        let heights = 0u32;
        data.extend_from_slice(&grid.values);
        let pyramid = data.len() as u32;
        let levels = push_pyramid(&mut data, terrain.pyramid());
        let visibility = data.len() as u32;
        let occlusion = terrain.occlusion.as_ref();
        let vis = occlusion.map_or(
            Grid {
                values: vec![1.0; 4],
                nx: 2,
                ny: 2,
                ..grid.clone()
            },
            |o| o.visibility.clone(),
        );
        data.extend_from_slice(&vis.values);
        let horizons = match occlusion {
            Some(o) => {
                let at = data.len() as u32;
                data.extend_from_slice(&o.horizons);
                at
            }
            None => NONE,
        };
        let shafts = terrain.casts_shadows && terrain.shafts;
        let mut shadow = [[NONE; 4]; MAX_LIGHTS];
        // Per light: the clearance's offset, the sky dome's.
        let mut per_light = [[NONE; 4]; MAX_LIGHTS];
        for (l, light) in lights.iter().enumerate() {
            if shafts {
                let field = terrain.shadow_field(light.direction);
                let s = data.len() as u32;
                data.extend_from_slice(&field.heights.values);
                let mut at = [s, 0, 0, 0];
                for (k, p) in field.pyramids().into_iter().enumerate() {
                    at[k + 1] = data.len() as u32;
                    push_pyramid(&mut data, p);
                }
                shadow[l] = at;
                per_light[l][0] = data.len() as u32;
                data.extend_from_slice(&field.clearance.values);
            }
            if let (Some(dome), Some(_)) = (shader.sky_domes().and_then(|d| d.get(l)), occlusion) {
                per_light[l][1] = data.len() as u32;
                data.extend(dome.moments().iter().map(|&v| v as f32));
                data.extend(dome.open().iter().map(|&v| v as f32));
            }
        }
        let dome_nodes = shader
            .sky_domes()
            .and_then(|d| d.first())
            .map_or(0, |d| d.node_count() as u32);
        let air_at = match shader.air_volume() {
            Some(a) => {
                let at = data.len() as u32;
                data.extend(a.reach_m().iter().map(|&d| d as f32));
                data.extend_from_slice(a.values());
                debug_assert_eq!(
                    a.reach_m().len(),
                    air_volume::AZIMUTHS * air_volume::ELEVATIONS
                );
                at
            }
            None => NONE,
        };
        let bytes = (data.len() * 4) as u64;
        check_buffers(ctx, &[("terrain", bytes)])?;

        let mut flags = TERRAIN_PRESENT;
        if terrain.casts_shadows {
            flags |= TERRAIN_CASTS_SHADOWS;
        }
        if shafts {
            flags |= TERRAIN_SHAFTS;
        }
        if occlusion.is_some() {
            flags |= TERRAIN_OCCLUSION;
        }
        let mut albedo = vec![0.0f32; 4 * TERRAIN_ALBEDO_VEC4];
        let mut zones = [0.0; 2];
        let mut put = |material: usize, spectrum: &[f64]| {
            for (k, v) in spectrum.iter().enumerate().take(sky.channels) {
                albedo[(4 * (k / GROUP) + material) * 4 + k % GROUP] = *v as f32;
            }
        };
        match &terrain.materials {
            Materials::Uniform(a) => {
                flags |= TERRAIN_UNIFORM_ALBEDO;
                put(0, a);
            }
            Materials::ByHeightAndSlope(z) => {
                zones = [z.snow_line_m, z.tree_line_m];
                for (m, s) in [&z.snow, &z.rock, &z.grass, &z.forest]
                    .into_iter()
                    .enumerate()
                {
                    put(m, s);
                }
            }
        }
        let lift_m = sky.radii.bottom - terrain.radius_m;
        let mut words = vec![
            grid.nx as u32,
            grid.ny as u32,
            levels.len() as u32,
            flags,
            bits(grid.origin[0]),
            bits(grid.origin[1]),
            bits(grid.axis[0]),
            bits(grid.axis[1]),
            bits(grid.spacing_m),
            bits(terrain.radius_m),
            bits(terrain.max_height_m()),
            0, // the observer's height, per frame
            heights,
            pyramid,
            visibility,
            lights.len() as u32,
            vis.nx as u32,
            vis.ny as u32,
            bits(vis.spacing_m),
            air_at,
            bits(zones[0]),
            bits(zones[1]),
            bits(lift_m),
            bits(EDGE_MARGIN),
            horizons,
            dome_nodes,
            0,
            0,
        ];
        for at in shadow.into_iter().chain(per_light) {
            words.extend(at);
        }
        for l in 0..MAX_PYRAMID_LEVELS {
            let [w, h, o] = levels.get(l).copied().unwrap_or([0; 3]);
            words.extend([w, h, o, 0]);
        }
        words.extend(albedo.iter().map(|v| v.to_bits()));
        assert_eq!(words.len(), UNIFORM_WORDS, "the Terrain uniform's layout");
        let data = scoped(ctx, "uploading the terrain", || {
            Ok(init(
                ctx.device(),
                "terrain",
                bytemuck::cast_slice(&data),
                wgpu::BufferUsages::STORAGE,
            ))
        })?;
        Ok(GpuTerrain {
            data,
            words,
            radius_m: terrain.radius_m,
            lights: lights.iter().map(|l| l.direction).collect(),
        })
    }

    /// The storage buffer (binding 17).
    pub(crate) fn data(&self) -> &wgpu::Buffer {
        &self.data
    }

    /// The uniform (binding 18) for a frame of `settings` over the tables of `sky` lit by
    /// `lights`, which must be the lights the terrain was uploaded for.
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
                "other lights than the terrain's",
                "the lights GpuTerrain::new was given (their shadow fields)",
            )
            .into());
        }
        let mut words = self.words.clone();
        // The observer above the terrain's sphere: the camera stands above the tables'
        // ground, which may be lifted above that sphere.
        let height = sky.radii.bottom + settings.camera.altitude_m - self.radius_m;
        words[OBSERVER_WORD] = bits(height);
        Ok(words)
    }
}

/// The uniform of a frame without terrain (flags 0).
pub(crate) fn no_terrain_words() -> Vec<u32> {
    vec![0; UNIFORM_WORDS]
}

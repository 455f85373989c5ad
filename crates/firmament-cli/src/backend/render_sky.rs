//! The sky a frame is drawn from, on the backend [`super::Backend`] chose: the 4D tables on
//! the CPU or the GPU, Hillaire 2020 and the 3D table on either, with what each frame
//! needs besides (lights, stars, the terrain, the aerial-perspective volume).

use std::sync::OnceLock;
use std::time::Instant;

use anyhow::Result;
use firmament::atmosphere::Model;
use firmament::math::Vec3;
use firmament::render::aerial_volume::AerialVolumeConfig;
use firmament::render::{stars, Frame, RenderSettings};
use firmament::scene::clouds::CloudMedium;
use firmament::scene::planet::PlanetSurface;
use firmament::scene::sky_lights::SkySources;
use firmament::scene::terrain::Heightfield;
use firmament::scene::{Scene, Surface};
use firmament::sky::bruneton4d::{Bruneton4d, TableConfig};
use firmament::sky::SkyMethod;
use firmament_gpu::elek3d::{GpuElek3d, GpuElek3dRenderer};
use firmament_gpu::hillaire2020::{GpuHillaire, GpuHillaireRenderer, HillairePrecomputer};
use firmament_gpu::{
    GpuClouds, GpuError, GpuPlanet, GpuRenderer, GpuSky, GpuTerrain, RenderInputs, RenderTarget,
    TemporalFrames,
};

use super::{gpu_failure, on_gpu, Backend, Gpu};
use crate::common::{cancel_flag, progress_bar, spinner, AtmosphereArgs};
use crate::method::{CpuSky, Method, ELEK3D_IN_WORDS};

/// Hillaire 2020 in words, for provenance.
const HILLAIRE_IN_WORDS: &str =
    "hillaire2020 (transmittance, multiple-scattering and sky-view tables; ray march)";

/// A sky ready to render on a backend.
pub enum RenderSky<'a> {
    /// A CPU sky, and the aerial-perspective volume its frames use (None: per pixel).
    Cpu(Box<CpuSky>, Option<AerialVolumeConfig>),
    Gpu {
        gpu: &'a Gpu,
        sky: Box<GpuSky>,
        /// The model the sky was computed for (lights are built from it).
        sky_model: Box<Model>,
        renderer: Box<GpuRenderer>,
        /// The tables on the CPU (the file's, or read back from the device on first use):
        /// the terrain's change of the air's light is computed on the CPU from them.
        cpu_sky: Box<OnceLock<Bruneton4d>>,
        /// The tables' configuration (to read them back).
        config: TableConfig,
    },
    /// Hillaire 2020 on the GPU (the clear sky: no terrain there yet).
    GpuHillaire {
        gpu: &'a Gpu,
        sky: Box<GpuHillaire>,
        sky_model: Box<Model>,
        renderer: Box<GpuHillaireRenderer>,
        /// Its table passes, kept for a new atmosphere ([`RenderSky::retable`]).
        precomputer: Box<HillairePrecomputer>,
    },
    /// The 3D tables, computed on the CPU and rendered on the GPU (the clear sky).
    GpuElek3d {
        gpu: &'a Gpu,
        sky: Box<GpuElek3d>,
        sky_model: Box<Model>,
        renderer: Box<GpuElek3dRenderer>,
    },
}

impl<'a> RenderSky<'a> {
    /// The sky of `method`: for the 4D tables, from --tables (uploaded to the GPU for
    /// `gpu`) or precomputed on the backend (kept on the device for `gpu`); the other
    /// methods on the CPU only so far (refused on a GPU backend).
    pub fn new(
        backend: &'a Backend,
        atmosphere: &AtmosphereArgs,
        method: Method,
        quiet: bool,
    ) -> Result<Self> {
        Self::with_tables_from(backend, atmosphere, method, quiet, false)
    }

    /// [`RenderSky::new`], the GPU's 4D tables computed on the CPU (through the table
    /// cache) and uploaded when `cpu_tables`: a software rasteriser takes half a minute
    /// for what the CPU does in seconds, or reads from its cache at once.
    pub fn with_tables_from(
        backend: &'a Backend,
        atmosphere: &AtmosphereArgs,
        method: Method,
        quiet: bool,
        cpu_tables: bool,
    ) -> Result<Self> {
        let gpu = match (backend, method) {
            (Backend::Cpu, _) => {
                return Ok(RenderSky::Cpu(
                    Box::new(atmosphere.cpu_sky(method, quiet)?),
                    None,
                ))
            }
            (Backend::Gpu(gpu), Method::Bruneton4d) => gpu,
            (Backend::Gpu(gpu), Method::Hillaire2020) => {
                let model = atmosphere.model()?;
                let config = atmosphere.hillaire.config();
                let started = Instant::now();
                let (sky, precomputer) =
                    on_gpu("Hillaire 2020's tables on the GPU", quiet, || {
                        let precomputer = HillairePrecomputer::new(&gpu.ctx)
                            .map_err(|e| gpu_failure("compiling Hillaire 2020's passes", e))?;
                        let sky = GpuHillaire::compute(&gpu.ctx, &precomputer, &model, &config)
                            .map_err(|e| gpu_failure("Hillaire 2020's tables", e))?;
                        gpu.wait_idle("Hillaire 2020's tables")?;
                        Ok((sky, precomputer))
                    })?;
                if !quiet {
                    eprintln!(
                        "tables: {:.2} s on the GPU (hillaire2020, f_ms ≤ {:.2}; shader compilation included; kept on the device)",
                        started.elapsed().as_secs_f64(),
                        sky.max_f_ms()
                    );
                }
                let renderer = GpuHillaireRenderer::new(&gpu.ctx)
                    .map_err(|e| gpu_failure("compiling the render shader", e))?;
                return Ok(RenderSky::GpuHillaire {
                    gpu,
                    sky: Box::new(sky),
                    sky_model: Box::new(model),
                    renderer: Box::new(renderer),
                    precomputer: Box::new(precomputer),
                });
            }
            (Backend::Gpu(gpu), Method::Elek3d) => {
                // The 3D tables precompute on the CPU (under a second) and are uploaded.
                let CpuSky::Elek3d(cpu) = atmosphere.cpu_sky(method, quiet)? else {
                    unreachable!("cpu_sky(Elek3d) builds the 3D tables")
                };
                let sky = on_gpu("uploading the 3D tables", quiet, || {
                    GpuElek3d::from_sky(&gpu.ctx, &cpu)
                        .map_err(|e| gpu_failure("uploading the 3D tables", e))
                })?;
                let renderer = GpuElek3dRenderer::new(&gpu.ctx)
                    .map_err(|e| gpu_failure("compiling the render shader", e))?;
                return Ok(RenderSky::GpuElek3d {
                    gpu,
                    sky: Box::new(sky),
                    sky_model: Box::new(cpu.model.clone()),
                    renderer: Box::new(renderer),
                });
            }
            (Backend::Gpu(_), Method::Reference) => {
                anyhow::bail!(
                    "`--method {}` renders on the CPU only so far",
                    method.name()
                )
            }
        };
        let cpu_sky = Box::new(OnceLock::new());
        let (sky, sky_model, config) = if atmosphere.tables.is_some() || cpu_tables {
            let cpu = atmosphere.sky(quiet)?;
            let sky = GpuSky::from_sky(&gpu.ctx, &cpu)
                .map_err(|e| gpu_failure("uploading the tables", e))?;
            let (model, config) = (cpu.model.clone(), cpu.tables.config);
            let _ = cpu_sky.set(cpu);
            (sky, model, config)
        } else {
            let model = atmosphere.model()?;
            let config = atmosphere.table_config()?;
            (gpu.sky(&model, &config, quiet)?, model, config)
        };
        let renderer = GpuRenderer::new(&gpu.ctx)
            .map_err(|e| gpu_failure("compiling the render shader", e))?;
        Ok(RenderSky::Gpu {
            gpu,
            sky: Box::new(sky),
            sky_model: Box::new(sky_model),
            renderer: Box::new(renderer),
            cpu_sky,
            config,
        })
    }

    /// Frames whose surfaces read their aerial perspective from a froxel volume
    /// (`render::aerial_volume`); the CPU renderer only so far.
    pub fn with_aerial_volume(self, config: AerialVolumeConfig) -> Result<Self> {
        match self {
            RenderSky::Cpu(sky, _) => Ok(RenderSky::Cpu(sky, Some(config))),
            RenderSky::Gpu { .. } | RenderSky::GpuHillaire { .. } | RenderSky::GpuElek3d { .. } => {
                anyhow::bail!(
                "`--aerial-volume` is built by the CPU renderer only so far: use `--backend cpu`"
            )
            }
        }
    }

    /// " on the GPU" or "", for messages.
    pub fn on(&self) -> &'static str {
        match self {
            RenderSky::Cpu(..) => "",
            RenderSky::Gpu { .. } | RenderSky::GpuHillaire { .. } | RenderSky::GpuElek3d { .. } => {
                " on the GPU"
            }
        }
    }

    /// Render one frame of the sky lit by `sources`, over `terrain` when given: the CPU
    /// renderer with a progress bar, or the GPU renderer (the terrain's shadow fields and
    /// its change of the air's light computed on the CPU and uploaded with it).
    pub fn render(
        &self,
        settings: &RenderSettings,
        sources: &SkySources,
        terrain: Option<&Heightfield>,
        planet: Option<&PlanetSurface>,
        clouds: &[CloudMedium],
        quiet: bool,
    ) -> Result<Frame> {
        if !clouds.is_empty() && !matches!(self, RenderSky::Cpu(..) | RenderSky::Gpu { .. }) {
            anyhow::bail!(
                "clouds ([[clouds]]) render on the CPU or with `--method bruneton4d` on the GPU so far: use `--backend cpu` (or `auto`)"
            );
        }
        if terrain.is_some() && matches!(self, RenderSky::GpuHillaire { .. }) {
            anyhow::bail!(
                "`--method hillaire2020` draws terrain on the CPU only so far: use `--backend cpu` (or `auto`)"
            );
        }
        if terrain.is_some() && matches!(self, RenderSky::GpuElek3d { .. }) {
            anyhow::bail!(
                "`--method elek3d` draws terrain on the CPU only so far: use `--backend cpu` (or `auto`)"
            );
        }
        match self {
            RenderSky::Cpu(sky, aerial) => {
                let bar = progress_bar(1000, quiet);
                bar.set_message("rendering");
                let mut scene = cpu_scene(sky.method(), sources, terrain, planet);
                scene.aerial_volume = *aerial;
                for c in clouds {
                    scene.volumes.push(Box::new(c));
                }
                let frame = firmament::render::render(
                    &scene,
                    settings,
                    &|f| bar.set_position((f * 1000.0) as u64),
                    Some(cancel_flag()),
                );
                bar.finish_and_clear();
                Ok(frame?)
            }
            RenderSky::Gpu {
                gpu,
                sky,
                renderer,
                sky_model,
                ..
            } => {
                let gpu_terrain = match terrain {
                    Some(t) => Some(self.gpu_terrain(t, settings, sources, quiet)?),
                    None => None,
                };
                let gpu_clouds = match clouds {
                    [] => None,
                    media => Some(self.gpu_clouds(media, settings, sources, quiet)?),
                };
                let gpu_planet = self.gpu_planet(planet)?;
                let inputs = RenderInputs {
                    background: sources.background.as_ref(),
                    terrain: gpu_terrain.as_ref(),
                    clouds: gpu_clouds.as_ref(),
                    planet: gpu_planet.as_ref(),
                    ..RenderInputs::default()
                };
                gpu_frame(sources, settings, sky_model, terrain, quiet, |lights| {
                    renderer.render_with(&gpu.ctx, sky, lights, settings, inputs)
                })
            }
            RenderSky::GpuHillaire {
                gpu,
                sky,
                sky_model,
                renderer,
                ..
            } => {
                let gpu_planet = self.gpu_planet(planet)?;
                let inputs = RenderInputs {
                    background: sources.background.as_ref(),
                    planet: gpu_planet.as_ref(),
                    ..RenderInputs::default()
                };
                gpu_frame(sources, settings, sky_model, None, quiet, |lights| {
                    renderer.render_with(&gpu.ctx, sky, lights, settings, inputs)
                })
            }
            RenderSky::GpuElek3d {
                gpu,
                sky,
                sky_model,
                renderer,
            } => {
                let gpu_planet = self.gpu_planet(planet)?;
                let inputs = RenderInputs {
                    background: sources.background.as_ref(),
                    planet: gpu_planet.as_ref(),
                    ..RenderInputs::default()
                };
                gpu_frame(sources, settings, sky_model, None, quiet, |lights| {
                    renderer.render_with(&gpu.ctx, sky, lights, settings, inputs)
                })
            }
        }
    }

    /// Record a frame lit by `sources` into `target` on the GPU (nothing submitted), over
    /// `terrain` when given (uploaded by [`RenderSky::gpu_terrain`] for these lights and
    /// this camera; the 4D tables only), under `clouds` (uploaded by
    /// [`RenderSky::gpu_clouds`] on the terrain's sphere when there is one; the 4D tables
    /// only); no stars (those
    /// need the CPU's parts of [`RenderSky::render`]); `timestamps` as
    /// `RenderInputs::timestamps`, over the planet's map `planet` ([`RenderSky::gpu_planet`];
    /// every method); under clouds or over a terrain with `temporal` (a buffer target), one pixel of each of its
    /// blocks marched and the rest resolved from the previous frames
    /// ([`TemporalFrames::encode`]). The viewer's frame path.
    #[allow(clippy::too_many_arguments)]
    pub fn encode_frame(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        settings: &RenderSettings,
        sources: &SkySources,
        target: RenderTarget,
        timestamps: Option<&wgpu::QuerySet>,
        terrain: Option<&GpuTerrain>,
        clouds: Option<&GpuClouds>,
        planet: Option<&GpuPlanet>,
        temporal: Option<&mut TemporalFrames>,
    ) -> Result<()> {
        if (terrain.is_some() || clouds.is_some()) && !matches!(self, RenderSky::Gpu { .. }) {
            anyhow::bail!("a terrain or clouds are drawn on the GPU by the 4D tables only so far");
        }
        let inputs = RenderInputs {
            background: sources.background.as_ref(),
            timestamps,
            terrain,
            clouds,
            planet,
            ..RenderInputs::default()
        };
        let lights = &sources.lights;
        let recorded = match self {
            RenderSky::Cpu(..) => anyhow::bail!("encode_frame draws on the GPU only"),
            RenderSky::Gpu {
                gpu, sky, renderer, ..
            } => match (temporal, target) {
                // Under clouds or over a terrain a share of the pixels, the rest from the
                // previous frames.
                (Some(t), RenderTarget::Buffer(output)) => {
                    let ctx = &gpu.ctx;
                    t.encode(
                        ctx, encoder, renderer, sky, lights, settings, output, inputs,
                    )
                }
                _ => renderer.encode(&gpu.ctx, encoder, sky, lights, settings, target, inputs),
            },
            RenderSky::GpuHillaire {
                gpu, sky, renderer, ..
            } => renderer.encode(&gpu.ctx, encoder, sky, lights, settings, target, inputs),
            RenderSky::GpuElek3d {
                gpu, sky, renderer, ..
            } => renderer.encode(&gpu.ctx, encoder, sky, lights, settings, target, inputs),
        };
        recorded.map_err(|e| gpu_failure("recording the frame", e))
    }

    /// `planet`'s map on the device of a GPU sky (None without one): its weights baked on
    /// the CPU, a procedural map's through the table cache's directory
    /// (`PlanetSurface::cached_weight_texture`).
    pub fn gpu_planet(&self, planet: Option<&PlanetSurface>) -> Result<Option<GpuPlanet>> {
        let Some(planet) = planet else {
            return Ok(None);
        };
        let gpu = match self {
            RenderSky::Cpu(..) => unreachable!("gpu_planet is called for GPU skies"),
            RenderSky::Gpu { gpu, .. }
            | RenderSky::GpuHillaire { gpu, .. }
            | RenderSky::GpuElek3d { gpu, .. } => gpu,
        };
        let cache = firmament::sky::bruneton4d::cache::TableCache::from_env()?.map(|c| c.dir);
        let (texels, _) = planet.cached_weight_texture(cache.as_deref())?;
        GpuPlanet::from_texels(&gpu.ctx, planet, &texels)
            .map(Some)
            .map_err(|e| gpu_failure("uploading the planet's surface map", e))
    }

    /// The CPU twin of the GPU's 4D tables (read back from the device once), with the
    /// observer at the camera: the CPU computes the terrain's and the clouds' shadow fields
    /// from it for the GPU frame.
    fn with_cpu_shader<T>(
        &self,
        settings: &RenderSettings,
        sources: &SkySources,
        terrain: Option<&Heightfield>,
        clouds: &[CloudMedium],
        then: impl FnOnce(&firmament::render::Shader) -> Result<T>,
    ) -> Result<T> {
        let RenderSky::Gpu {
            gpu,
            sky,
            sky_model,
            cpu_sky,
            config,
            ..
        } = self
        else {
            unreachable!("with_cpu_shader is called for the GPU's 4D tables")
        };
        let cpu = match cpu_sky.get() {
            Some(c) => c,
            None => {
                let tables = sky
                    .tables()
                    .read_back(&gpu.ctx, sky_model, config)
                    .map_err(|e| gpu_failure("reading the tables back", e))?;
                let _ = cpu_sky.set(Bruneton4d::new(sky_model.as_ref().clone(), tables)?);
                cpu_sky.get().expect("just set")
            }
        };
        let mut scene = cpu_scene(cpu, sources, terrain, None);
        for c in clouds {
            scene.volumes.push(Box::new(c));
        }
        let observer = Vec3::new(
            0.0,
            0.0,
            sky_model.bottom_radius_m + settings.camera.altitude_m,
        );
        let shader = firmament::render::Shader::new(&scene, observer)?;
        then(&shader)
    }

    /// `terrain` on the device for a GPU frame: its shadow fields for the frame's lights,
    /// the sky's radiance under its horizons and, when it changes the air's light, the
    /// observer's air volume, all computed on the CPU.
    pub fn gpu_terrain(
        &self,
        terrain: &Heightfield,
        settings: &RenderSettings,
        sources: &SkySources,
        quiet: bool,
    ) -> Result<GpuTerrain> {
        let RenderSky::Gpu { gpu, sky, .. } = self else {
            unreachable!("gpu_terrain is called for GPU skies")
        };
        let bar = spinner("the terrain's shadows, sky and air light (CPU)", quiet);
        let uploaded = self.with_cpu_shader(settings, sources, Some(terrain), &[], |shader| {
            GpuTerrain::new(&gpu.ctx, sky, terrain, shader)
                .map_err(|e| gpu_failure("uploading the terrain", e))
        });
        bar.finish_and_clear();
        uploaded
    }

    /// The cloud layers on the device for a GPU frame: their noise, weather and two-stream
    /// tables, and each light's cloud-shadow map computed on the CPU.
    pub fn gpu_clouds(
        &self,
        media: &[CloudMedium],
        settings: &RenderSettings,
        sources: &SkySources,
        quiet: bool,
    ) -> Result<GpuClouds> {
        let RenderSky::Gpu { gpu, sky, .. } = self else {
            unreachable!("gpu_clouds is called for GPU skies")
        };
        let bar = spinner("the clouds' shadow maps (CPU)", quiet);
        let uploaded = self.with_cpu_shader(settings, sources, None, media, |shader| {
            GpuClouds::new(&gpu.ctx, sky, media, shader)
                .map_err(|e| gpu_failure("uploading the clouds", e))
        });
        bar.finish_and_clear();
        uploaded
    }

    /// The method's tables as JSON (the 4D tables' configuration: sizes, orders, Mie
    /// storage; Hillaire's sizes and counts).
    pub fn tables_json(&self) -> serde_json::Value {
        match self {
            RenderSky::Cpu(sky, _) => sky.tables_json(),
            RenderSky::Gpu { config, .. } => {
                serde_json::to_value(config).unwrap_or(serde_json::Value::Null)
            }
            RenderSky::GpuHillaire { sky, .. } => {
                crate::method::hillaire_json(sky.config(), sky.max_f_ms())
            }
            RenderSky::GpuElek3d { sky, .. } => crate::method::elek3d_json(sky.config()),
        }
    }

    /// The method in words, for provenance.
    pub fn describe(&self) -> &'static str {
        match self {
            RenderSky::Cpu(sky, _) if sky.name() == "elek3d" => ELEK3D_IN_WORDS,
            RenderSky::GpuElek3d { .. } => ELEK3D_IN_WORDS,
            RenderSky::Cpu(sky, _) if sky.bruneton4d().is_none() => HILLAIRE_IN_WORDS,
            RenderSky::GpuHillaire { .. } => HILLAIRE_IN_WORDS,
            _ => "bruneton4d (precomputed tables)",
        }
    }

    /// The model the sky's tables hold (lights are built from it).
    pub fn model(&self) -> &Model {
        match self {
            RenderSky::Cpu(sky, _) => sky.model(),
            RenderSky::Gpu { sky_model, .. } => sky_model,
            RenderSky::GpuHillaire { sky_model, .. } => sky_model,
            RenderSky::GpuElek3d { sky_model, .. } => sky_model,
        }
    }
}

/// A GPU frame of `render(lights)` under a spinner, with the stars and the small disks
/// splatted into it on the CPU (hidden by `terrain`).
fn gpu_frame(
    sources: &SkySources,
    settings: &RenderSettings,
    model: &Model,
    terrain: Option<&Heightfield>,
    quiet: bool,
    render: impl FnOnce(&[firmament::scene::Light]) -> Result<Frame, GpuError>,
) -> Result<Frame> {
    let (lights, small) = gpu_lights(sources, settings, model);
    let mut frame = on_gpu("rendering on the GPU", quiet, || {
        render(&lights).map_err(|e| gpu_failure("rendering", e))
    })?;
    draw_points(&mut frame, sources, small, model, settings, terrain);
    Ok(frame)
}

/// The lights a GPU frame draws, and the disks smaller than four pixels, which are points
/// (as on the CPU) left out of its lights.
pub fn gpu_lights(
    sources: &SkySources,
    settings: &RenderSettings,
    model: &Model,
) -> (
    Vec<firmament::scene::Light>,
    Vec<(usize, firmament::scene::sky_lights::PointSource)>,
) {
    let (w, h) = (settings.width, settings.height);
    let prepared = settings.camera.prepare(model.bottom_radius_m, w, h);
    let small = stars::small_disks(&sources.lights, &prepared, w, h);
    let mut lights = sources.lights.clone();
    for (i, _) in &small {
        lights[*i].visible_disk = false;
    }
    (lights, small)
}

/// The stars and the small disks of a GPU frame, splatted on the CPU into the frame read
/// back, hidden by the terrain.
fn draw_points(
    frame: &mut Frame,
    sources: &SkySources,
    small: Vec<(usize, firmament::scene::sky_lights::PointSource)>,
    model: &Model,
    settings: &RenderSettings,
    terrain: Option<&Heightfield>,
) {
    let occluders: Vec<&dyn Surface> = terrain.iter().map(|t| *t as &dyn Surface).collect();
    let points: Vec<_> = (sources.stars.iter().cloned())
        .chain(small.into_iter().map(|(_, p)| p))
        .collect();
    stars::draw_points_into(frame, &points, model, settings, &occluders);
}

/// The CPU scene of a frame: the sky's tables, the sources' lights, glow and stars, over the
/// terrain and the planet's surface when given.
fn cpu_scene<'s>(
    sky: &'s dyn SkyMethod,
    sources: &SkySources,
    terrain: Option<&'s Heightfield>,
    planet: Option<&'s PlanetSurface>,
) -> Scene<'s> {
    let mut scene = Scene::clear_sky(sky, Vec3::Z, false);
    if let Some(t) = terrain {
        scene.add_terrain(t, t.radius_m);
    }
    if let Some(p) = planet {
        scene.set_ground(p);
    }
    scene.lights = sources.lights.clone();
    scene.background = sources.background.clone();
    scene.stars = sources.stars.clone();
    scene
}

//! The viewer's frame: the scene's sky drawn by the GPU backend into an HDR frame buffer
//! (`RenderSky::encode_frame`, the same pipeline and dispatch `firmament render --backend
//! gpu` reads back), then exposed and tone-mapped on the GPU into the window or an offscreen target
//! (`firmament_gpu::display`). No readback in the frame loop; captures read the textures.
//! The same path draws in the window and offscreen (tests, `--screenshot` without one).

use anyhow::{Context, Result};
use firmament::render::stars::point_splats;
use firmament::render::{Frame, RenderSettings};
use firmament::scene::clouds::lod::MeanDensity;
use firmament::scene::clouds::{CloudMedium, ViewFootprint};
use firmament::scene::planet::PlanetSurface;
use firmament::scene::sky_lights::SkySources;
use firmament::scene::terrain::Heightfield;
use firmament::sky::bruneton4d::amortised::{AmortisedTables, UpdateProgress};
use firmament_gpu::display::{
    hdr_buffer, read_hdr_frame, read_rgba8, Display, DisplaySettings, Exposure,
};
use firmament_gpu::pass_timer::{PassTimer, PassTimes, SkySlots};
use firmament_gpu::render::stars::PointSplats;
use firmament_gpu::{GpuClouds, GpuPlanet, GpuTerrain, RenderTarget, TemporalFrames};

use std::sync::Arc;

use super::progressive::Overlay;
use super::state::ViewState;
use crate::backend::{gpu_failure, gpu_lights, Backend, RenderSky};
use crate::commands::render::sources_of_scene;
use crate::method::Method;
use sky::{AirKey, SkyKey};

/// What the terrain's uploads depend on besides the sky: the lights and the observer.
#[derive(Clone, Debug, PartialEq)]
struct TerrainKey {
    lights: Vec<[f64; 3]>,
    altitude_m: f64,
}

/// The scene's surface map on the device and on the CPU (the reference traces it).
struct PlanetMap {
    /// The map, the planet's radius and the wavelengths its texture was baked for.
    key: String,
    /// The observer's latitude and longitude on it (degrees).
    place: (f64, f64),
    gpu: GpuPlanet,
    cpu: Arc<PlanetSurface>,
}

/// The viewer's GPU frame path.
pub struct FramePath {
    backend: &'static Backend,
    /// Baked 4D tables for the first atmosphere (`--tables`), and the table sizes of fresh
    /// ones.
    tables: Option<(SkyKey, AirKey, std::path::PathBuf)>,
    table_size: String,
    /// The sky, what its passes were built for, and the atmosphere asked of it last.
    sky: Option<(SkyKey, AirKey, RenderSky<'static>)>,
    /// The atmosphere's arguments of the last fresh build (the terrain's albedo and floor
    /// in them): a new atmosphere changes the preset, file and adjustments only.
    args: Option<crate::common::AtmosphereArgs>,
    /// The 4D tables' amortised update on a software rasteriser (the CPU computes them
    /// over frames; the device draws the previous set until the swap).
    amortised: Option<AmortisedTables>,
    /// Where the amortised update stood after the last frame.
    update: Option<UpdateProgress>,
    display: Display,
    /// The HDR frame buffer and its size.
    hdr: Option<(wgpu::Buffer, (u32, u32))>,
    /// Seconds the last sky build took (for the panel).
    pub last_build_s: f64,
    /// Per-pass GPU times (None without timestamp queries).
    timer: Option<PassTimer>,
    /// The scene's terrain on the sky's planet (built with the sky).
    terrain: Option<Arc<Heightfield>>,
    /// Its shadow fields, sky domes and air volume on the device for the current lights and
    /// observer (the 4D tables only).
    gpu_terrain: Option<(TerrainKey, GpuTerrain)>,
    /// Seconds the last terrain upload took (its CPU parts).
    pub last_terrain_s: f64,
    /// The scene's cloud layers as media (their TOML and planet radius as the key), their
    /// density unfiltered (as the reference traces it).
    clouds: Option<(String, f64, Arc<Vec<CloudMedium>>)>,
    /// Each layer's mean density for the filter over the pixels' footprint (made with the
    /// first upload of the layers, kept while they stay).
    cloud_means: Vec<Option<Arc<MeanDensity>>>,
    /// Their shadow maps on the device for the current lights and observer.
    gpu_clouds: Option<(TerrainKey, GpuClouds)>,
    /// The pass adding the stars and small disks into the frame (made when first needed).
    points: Option<PointSplats>,
    /// The scene's surface map on the device, what its texture was baked for, and the
    /// observer's latitude and longitude on it (degrees).
    planet: Option<PlanetMap>,
    /// Frames under clouds a share of the pixels at a time (made when first needed), and
    /// what the scene was besides the camera when its history was drawn: anything else
    /// changing resets it.
    temporal: Option<(TemporalFrames, String)>,
    /// Counts the skies and tables drawn (a new one resets the clouds' history).
    sky_generation: u64,
    /// The reference path tracer's passes over the frame (`state.compare`).
    reference: Overlay,
    /// The atmosphere the reference traces, and the keys it was made for.
    ref_model: Option<((SkyKey, AirKey), Arc<firmament::atmosphere::Model>)>,
}

/// The size the sky is drawn at for a target of `size` pixels.
pub fn render_size(state: &ViewState, size: (u32, u32)) -> (u32, u32) {
    let s = state.render_scale.clamp(0.1, 1.0);
    (
        ((size.0 as f64 * s).round() as u32).max(1),
        ((size.1 as f64 * s).round() as u32).max(1),
    )
}

impl FramePath {
    /// A frame path on the backend's GPU (`backend` must be a GPU one); `tables` (baked
    /// by `firmament bake`) serve the 4D method while the atmosphere is `state`'s, and
    /// fresh tables have `table_size` (`default` or `small`).
    pub fn new(
        backend: &'static Backend,
        state: &ViewState,
        tables: Option<std::path::PathBuf>,
        table_size: &str,
    ) -> Result<FramePath> {
        let Backend::Gpu(gpu) = backend else {
            anyhow::bail!("the viewer draws on the GPU");
        };
        let display = Display::new(&gpu.ctx).map_err(|e| gpu_failure("the display pass", e))?;
        Ok(FramePath {
            backend,
            tables: tables.map(|t| (SkyKey::of(state), AirKey::of(state), t)),
            table_size: table_size.to_string(),
            sky: None,
            args: None,
            amortised: None,
            update: None,
            display,
            hdr: None,
            last_build_s: 0.0,
            timer: PassTimer::new(&gpu.ctx),
            terrain: None,
            gpu_terrain: None,
            last_terrain_s: 0.0,
            reference: Overlay::default(),
            ref_model: None,
            clouds: None,
            cloud_means: Vec::new(),
            gpu_clouds: None,
            points: None,
            planet: None,
            temporal: None,
            sky_generation: 0,
        })
    }

    fn ctx(&self) -> &firmament_gpu::GpuContext {
        match self.backend {
            Backend::Gpu(gpu) => &gpu.ctx,
            Backend::Cpu => unreachable!("FramePath::new refuses the CPU"),
        }
    }

    /// The scene's cloud layers as media on a planet of `radius_m` (built when their
    /// settings change: the noise volumes come from the disk cache).
    fn ensure_clouds(&mut self, state: &ViewState, radius_m: f64) -> Result<()> {
        let key = toml::to_string(&state.scene.clouds).unwrap_or_default();
        if self
            .clouds
            .as_ref()
            .is_some_and(|(k, r, _)| *k == key && *r == radius_m)
        {
            return Ok(());
        }
        let media = crate::common::scene_clouds(&state.scene, radius_m, false, true)?;
        self.clouds = Some((key, radius_m, Arc::new(media)));
        self.cloud_means = Vec::new();
        self.gpu_clouds = None;
        Ok(())
    }

    /// The layers with their density filtered over the footprint of `view`'s pixels, as
    /// `render` sets them (`CloudLayer::set_view`), for the device: copies of `media`, each
    /// layer's mean density made once and kept in `means`.
    fn viewed_clouds(
        media: &[CloudMedium],
        means: &mut Vec<Option<Arc<MeanDensity>>>,
        view: ViewFootprint,
    ) -> Vec<CloudMedium> {
        means.resize(media.len(), None);
        media
            .iter()
            .zip(means.iter_mut())
            .map(|(m, mean)| {
                let mut layer = m.layer.clone();
                layer.set_view(view, mean.clone());
                *mean = layer.filter.as_ref().map(|(_, a)| a.get().clone());
                CloudMedium::new(layer)
            })
            .collect()
    }

    /// The scene's surface map (`[surface]`) on the device for a planet of `radius_m` (None
    /// without one): its texture baked when the map, the planet or the wavelengths change,
    /// the observer's place on it set every frame (the date-and-place panel moves it).
    fn ensure_planet(&mut self, state: &ViewState, radius_m: f64) -> Result<Option<&GpuPlanet>> {
        let Some(surface) = &state.scene.surface else {
            self.planet = None;
            return Ok(None);
        };
        let sky = self.sky.as_ref().map(|(_, _, s)| s).context("no sky yet")?;
        let nm = sky.model().wavelengths.nm();
        let key = format!(
            "{}|{radius_m}|{nm:?}",
            toml::to_string(surface).unwrap_or_default()
        );
        let place = (state.scene.location.as_ref()).map_or((0.0, 0.0), |l| (l.lat_deg, l.lon_deg));
        if (self.planet.as_ref()).is_some_and(|m| m.key == key && m.place == place) {
            return Ok(self.planet.as_ref().map(|m| &m.gpu));
        }
        let planet = state
            .scene
            .build_surface(radius_m, nm)?
            .expect("the scene has a [surface]");
        match &mut self.planet {
            Some(m) if m.key == key => {
                m.gpu.set_frame(planet.frame());
                m.place = place;
                m.cpu = Arc::new(planet);
            }
            _ => {
                let gpu = sky.gpu_planet(Some(&planet))?.expect("a planet was given");
                self.planet = Some(PlanetMap {
                    key,
                    place,
                    gpu,
                    cpu: Arc::new(planet),
                });
            }
        }
        Ok(self.planet.as_ref().map(|m| &m.gpu))
    }

    /// Whether the scene's clouds are drawn with this method (the 4D tables), for the
    /// panel.
    pub fn clouds_drawn(&self, state: &ViewState) -> bool {
        state.method == Method::Bruneton4d
            && self.clouds.as_ref().is_some_and(|(_, _, m)| !m.is_empty())
    }

    /// A line for the panel on the temporal frames under clouds or over a terrain: the
    /// share of pixels marched a frame and whether the view has converged since the last
    /// change.
    pub fn march_line(&self, state: &ViewState) -> Option<String> {
        let marched = self.clouds_drawn(state)
            || (self.terrain.is_some() && state.method == Method::Bruneton4d);
        let (t, _) = self.temporal.as_ref().filter(|_| marched)?;
        let step = t.step();
        if step == 1 {
            return Some("march: every pixel each frame".into());
        }
        let needed = step * step;
        let done = t.still_frames();
        Some(if done >= needed {
            format!("march: 1/{needed} of the pixels a frame; converged")
        } else {
            format!(
                "march: 1/{needed} of the pixels a frame; {done} of {needed} frames since a change or a move (the rest reprojected or interpolated)"
            )
        })
    }

    /// The sky in use (after [`FramePath::ensure_sky`]).
    pub fn sky(&self) -> Option<&RenderSky<'static>> {
        self.sky.as_ref().map(|(_, _, s)| s)
    }

    /// The lights, glow and stars of the scene (from its date and place, or its sun).
    pub fn sources(&self, state: &ViewState) -> Result<SkySources> {
        let sky = self.sky.as_ref().map(|(_, _, s)| s).context("no sky yet")?;
        sources_of_scene(sky.model(), &state.scene)
    }

    /// Record a frame of `state` for a target of `target_size`: the sky into the HDR
    /// frame buffer at the render scale, then the display into `target`.
    #[allow(clippy::too_many_arguments)]
    pub fn encode(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        state: &ViewState,
        sources: &SkySources,
        target: &wgpu::TextureView,
        target_format: wgpu::TextureFormat,
        target_size: (u32, u32),
        display: DisplaySettings,
    ) -> Result<()> {
        let size = render_size(state, target_size);
        if self.hdr.as_ref().is_none_or(|(_, s)| *s != size) {
            self.hdr = Some((hdr_buffer(self.ctx(), size.0, size.1), size));
        }
        let radius = self.sky().context("no sky yet")?.model().bottom_radius_m;
        // The clouds and the map lie on the terrain's planet when there is one, as in
        // `render`.
        let planet_radius = self.terrain.as_ref().map_or(radius, |t| t.radius_m);
        self.ensure_clouds(state, planet_radius)?;
        self.ensure_planet(state, planet_radius)?;
        // The camera's altitude is above the terrain under it, as in `render`.
        let camera = state.scene.camera_over(self.terrain.as_deref(), radius);
        let job = self.reference_job(state, sources, &camera, size);
        let (hdr, _) = self.hdr.as_ref().expect("just made");
        let sky = self.sky.as_ref().map(|(_, _, s)| s).context("no sky yet")?;
        let settings = RenderSettings {
            camera: &camera,
            width: size.0 as usize,
            height: size.1 as usize,
            white_balance: state.scene.output.white_balance,
        };
        // The terrain's and the clouds' uploads follow the lights and the observer.
        let light_key = TerrainKey {
            lights: sources
                .lights
                .iter()
                .map(|l| [l.direction.x, l.direction.y, l.direction.z])
                .collect(),
            altitude_m: camera.altitude_m,
        };
        // The terrain with the 4D tables only.
        let terrain = match (&self.terrain, state.method) {
            (Some(t), Method::Bruneton4d) => {
                let key = light_key.clone();
                if self.gpu_terrain.as_ref().is_none_or(|(k, _)| *k != key) {
                    let started = std::time::Instant::now();
                    let uploaded = sky.gpu_terrain(t, &settings, sources, true)?;
                    self.last_terrain_s = started.elapsed().as_secs_f64();
                    self.gpu_terrain = Some((key, uploaded));
                }
                self.gpu_terrain.as_ref().map(|(_, g)| g)
            }
            _ => None,
        };
        // The clouds with the 4D tables (over the planet's sphere or the terrain), their
        // density filtered over the pixels' footprint as `render` sets it: the upload's
        // with its shadow maps, each frame's from then on.
        let view = camera
            .prepare(radius, settings.width, settings.height)
            .pixel_footprint()
            .map(|(eye, pixel_angle_rad)| ViewFootprint {
                eye,
                pixel_angle_rad,
            });
        let clouds = match (&self.clouds, state.method) {
            (Some((_, _, media)), Method::Bruneton4d) if !media.is_empty() => {
                if self
                    .gpu_clouds
                    .as_ref()
                    .is_none_or(|(k, _)| *k != light_key)
                {
                    let uploaded = match view {
                        Some(v) => {
                            let viewed = Self::viewed_clouds(media, &mut self.cloud_means, v);
                            sky.gpu_clouds(&viewed, &settings, sources, true)?
                        }
                        None => sky.gpu_clouds(media, &settings, sources, true)?,
                    };
                    self.gpu_clouds = Some((light_key.clone(), uploaded));
                }
                if let (Some((_, c)), Some(v)) = (self.gpu_clouds.as_mut(), view) {
                    c.set_view(v);
                }
                self.gpu_clouds.as_ref().map(|(_, c)| c)
            }
            _ => None,
        };
        // Disks under four pixels and the stars are points, splatted as `render` does: the
        // CPU weighs them, the device adds them into the frame.
        let (lights, small) = gpu_lights(sources, &settings, sky.model());
        let drawn = SkySources {
            lights,
            background: sources.background.clone(),
            stars: Vec::new(),
        };
        let points: Vec<_> = (sources.stars.iter().cloned())
            .chain(small.into_iter().map(|(_, p)| p))
            .collect();
        let occluders: Vec<&dyn firmament::scene::Surface> = self
            .terrain
            .iter()
            .map(|t| t.as_ref() as &dyn firmament::scene::Surface)
            .collect();
        let splats = point_splats(&points, sky.model(), &settings, &occluders);
        let set = self.timer.as_ref().map(|t| t.query_set());
        // Under clouds or over a terrain a share of the pixels marched, the rest from the
        // previous frames: their history holds while only the camera moves.
        let step = march_step(state);
        let temporal = match (clouds, terrain) {
            (None, None) => None,
            _ => {
                let scene = format!(
                    "{:?}|{}|{}|{:?}|{}",
                    light_key.lights,
                    self.clouds.as_ref().map_or("", |(k, _, _)| k.as_str()),
                    self.planet
                        .as_ref()
                        .map_or(String::new(), |m| format!("{}|{:?}", m.key, m.place)),
                    state.scene.output.white_balance,
                    self.sky_generation,
                );
                if self.temporal.is_none() {
                    let made = TemporalFrames::new(self.ctx(), step)
                        .map_err(|e| gpu_failure("the temporal resolve", e))?;
                    self.temporal = Some((made, scene.clone()));
                }
                let (t, held) = self.temporal.as_mut().expect("just made");
                t.set_step(step)
                    .map_err(|e| gpu_failure("the temporal resolve", e))?;
                if *held != scene {
                    t.reset();
                    *held = scene;
                }
                Some(t)
            }
        };
        sky.encode_frame(
            encoder,
            &settings,
            &drawn,
            RenderTarget::Buffer(hdr),
            set,
            terrain,
            clouds,
            self.planet.as_ref().map(|m| &m.gpu),
            temporal,
        )?;
        let ctx = match self.backend {
            Backend::Gpu(gpu) => &gpu.ctx,
            Backend::Cpu => unreachable!("FramePath::new refuses the CPU"),
        };
        // The method's frame is compared with the reference before the points are added.
        self.reference
            .encode(ctx, encoder, hdr, size, state.compare, job);
        if !splats.is_empty() {
            if self.points.is_none() {
                self.points =
                    Some(PointSplats::new(ctx).map_err(|e| gpu_failure("the stars' pass", e))?);
            }
            let pass = self.points.as_mut().expect("just made");
            pass.encode(ctx, encoder, hdr, &splats);
        }
        self.reference.cover(encoder, hdr, size);
        self.display.encode(
            self.ctx(),
            encoder,
            hdr,
            size,
            target,
            target_format,
            target_size,
            &display,
            set,
        );
        // Hillaire 2020 draws its sky-view pass (slots 0–1) from inside the atmosphere only
        // (FrameConstants::inside); its pixels at 2–3.
        let model = self.sky().context("no sky yet")?.model();
        let inside = model.bottom_radius_m + camera.altitude_m <= model.top_radius_m;
        let slots = match (state.method, inside) {
            (Method::Hillaire2020, true) => SkySlots::Two,
            (Method::Hillaire2020, false) => SkySlots::Pixels,
            _ => SkySlots::One,
        };
        if let Some(t) = self.timer.as_mut() {
            t.resolve(encoder, slots);
        }
        Ok(())
    }

    /// Call after submitting a frame [`FramePath::encode`] recorded: starts reading its
    /// timestamps back.
    pub fn submitted(&mut self) {
        if let Some(t) = self.timer.as_mut() {
            t.after_submit();
        }
        if let Backend::Gpu(gpu) = self.backend {
            self.reference.submitted(&gpu.ctx);
        }
    }

    /// Whether the adapter has timestamp queries (per-pass times).
    pub fn has_timer(&self) -> bool {
        self.timer.is_some()
    }

    /// The latest per-pass GPU times read back (None without timestamp queries).
    pub fn pass_times(&mut self) -> Option<PassTimes> {
        let Backend::Gpu(gpu) = self.backend else {
            return None;
        };
        self.timer.as_mut().and_then(|t| t.times(&gpu.ctx))
    }

    /// The last frame's HDR pixels (linear sRGB, Y in cd/m²), for EXR captures and tests.
    pub fn hdr_frame(&self) -> Result<Frame> {
        let (hdr, (w, h)) = self.hdr.as_ref().context("no frame drawn yet")?;
        read_hdr_frame(self.ctx(), hdr, *w, *h)
            .map_err(|e| gpu_failure("reading the frame back", e))
    }

    /// The EV100 the last frame was shown at.
    pub fn shown_ev100(&self) -> Result<f64> {
        Ok(self
            .display
            .read_exposure(self.ctx())
            .map_err(|e| gpu_failure("reading the exposure back", e))?
            .ev100)
    }

    /// Draw one frame of `state` offscreen at `size` (the same path as the window's) and
    /// return the HDR frame and the displayed 8-bit RGBA pixels.
    pub fn draw_offscreen(
        &mut self,
        state: &ViewState,
        size: (u32, u32),
        display: DisplaySettings,
    ) -> Result<(Frame, Vec<[u8; 4]>)> {
        self.ensure_sky(state)?;
        let sources = self.sources(state)?;
        let format = wgpu::TextureFormat::Rgba8UnormSrgb;
        let target = self
            .ctx()
            .device()
            .create_texture(&wgpu::TextureDescriptor {
                label: Some("offscreen display"),
                size: wgpu::Extent3d {
                    width: size.0,
                    height: size.1,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
                view_formats: &[],
            });
        let mut encoder =
            self.ctx()
                .device()
                .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                    label: Some("viewer frame"),
                });
        self.encode(
            &mut encoder,
            state,
            &sources,
            &target.create_view(&Default::default()),
            format,
            size,
            display,
        )?;
        self.ctx().queue().submit([encoder.finish()]);
        self.submitted();
        let pixels = read_rgba8(self.ctx(), &target)
            .map_err(|e| gpu_failure("reading the display back", e))?;
        Ok((self.hdr_frame()?, pixels))
    }
}

/// The step of the temporal frames: the state's, but every pixel beside the reference (the
/// method's frame compared as `render` draws it, not while it converges).
pub fn march_step(state: &ViewState) -> u32 {
    match state.compare {
        super::progressive::Compare::Off => state.march_step,
        _ => 1,
    }
}

/// The display settings of the state's exposure: the scene's EV100 when it has one, else
/// automatic with the state's adaptation.
pub fn display_settings(state: &ViewState, dt_s: f64, reset: bool) -> DisplaySettings {
    DisplaySettings {
        exposure: match state.scene.output.ev100 {
            Some(ev100) => Exposure::Manual { ev100 },
            None => Exposure::Automatic {
                tau_s: state.adapt_tau_s,
            },
        },
        curve: state.scene.output.tonemap,
        dt_s,
        reset,
    }
}

#[path = "frame_reference.rs"]
mod reference;
#[path = "frame_sky.rs"]
mod sky;

#[cfg(test)]
#[path = "frame_path_tests.rs"]
mod tests;

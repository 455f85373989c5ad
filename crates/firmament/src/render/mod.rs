//! Images: the render loop over a [`Scene`], per-pixel shading of the paper's eq. 16 (sky,
//! surfaces lit by the lights and the sky, aerial perspective, light shafts, the lights'
//! disks, volumes), spectral to colour ([`frame`]), exposure and tone mapping
//! ([`tonemap`]).
//!
//! The loop knows only the seams: it asks the sky method for one view per light, the
//! surfaces for the nearest hit and for the shadows they cast, the volumes for their medium,
//! the lights for their disks. A second surface or light needs no change here.

pub mod aerial_volume;
pub mod air_volume;
pub mod cloud_shadow;
pub mod cube_layout;
pub mod disk_edges;
pub mod frame;
pub mod shadowed_air;
pub mod sky_dome;
pub mod stars;
pub mod terrain_air;
pub mod tonemap;
pub mod volumes;

use std::f64::consts::PI;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Arc;

use rayon::prelude::*;

pub use frame::Frame;
pub use tonemap::ToneCurve;

use crate::io::ImageRgbF32;
use crate::scene::surface::{lit_intervals, HORIZON_AZIMUTHS};
use crate::scene::{Camera, Projection, Ray, Scene};
use crate::sky::{Shadow, SkyView};
use crate::spectrum::{with_channel_buffers, MAX_CHANNELS};
use crate::{Error, Result};

/// What to render: the camera and the image.
pub struct RenderSettings<'a> {
    /// Camera.
    pub camera: &'a Camera,
    /// Image width (pixels).
    pub width: usize,
    /// Image height (pixels).
    pub height: usize,
    /// Divide colours by the top-of-atmosphere sun's colour (white sun); off keeps the
    /// physical colour of the standard D65 white.
    pub white_balance: bool,
}

impl RenderSettings<'_> {
    /// The checks [`render`] makes before drawing (shared with other backends): image size,
    /// camera values, the cube map's 6:1 shape.
    pub fn validate(&self) -> Result<()> {
        let (w, h) = (self.width, self.height);
        if w == 0 || h == 0 || w > 32768 || h > 32768 {
            return Err(Error::invalid(
                "width/height",
                format!("{w}×{h}"),
                "between 1 and 32768 pixels each",
            ));
        }
        self.camera.validate()?;
        if self.camera.projection == Projection::Cubemap && w != 6 * h {
            return Err(Error::invalid(
                "width",
                w,
                format!("6 × height ({}) for a cube map", 6 * h),
            ));
        }
        Ok(())
    }
}

/// A scene prepared for one frame from one observer: the sky method's view of each light.
pub struct Shader<'s> {
    scene: &'s Scene<'s>,
    views: Vec<Arc<dyn SkyView + 's>>,
    /// The lights whose disks images show, with the cosine of their angular radius.
    disks: Vec<(usize, f64)>,
    channels: usize,
    /// The terrain's change of the air's light along this observer's views, when a surface
    /// reshapes the planet ([`terrain_air`]).
    air: Option<air_volume::AirVolume>,
    /// The sky's radiance per light for the irradiance of surfaces under a horizon
    /// ([`sky_dome`]); none: their [`crate::scene::Surface::sky_visibility`] alone.
    domes: Option<Arc<Vec<sky_dome::SkyDome>>>,
    /// The aerial-perspective volume per light ([`aerial_volume`]), when built.
    aerial: Vec<Option<aerial_volume::AerialVolume>>,
    /// The volumes' shadow below them per light ([`cloud_shadow`]), when a volume is a
    /// shell around the planet.
    cloud_shadows: Vec<Option<cloud_shadow::CloudShadow>>,
    /// The share of the multiple scattering the air under the clouds keeps per light
    /// ([`shadowed_air`]), where the light has a shadow map.
    shadowed_air: Vec<Option<shadowed_air::ShadowedAir>>,
}

/// Per-thread scratch space of [`Shader::shade`] (no allocation per pixel).
#[derive(Default)]
pub struct ShadeScratch {
    shadowed: Vec<(f64, f64)>,
    lit: Vec<(f64, f64)>,
    /// The clouds' shadows along the ray.
    clouded: Vec<(f64, f64)>,
    /// The stretches under the clouds with the share of the multiple scattering they keep.
    dimmed: shadowed_air::Dimmed,
}

impl<'s> Shader<'s> {
    /// The views of `scene`'s sky method from `observer`, one per light, and the terrain's
    /// change of the air's light ([`terrain_air`]) when a surface has a relief.
    pub fn new(scene: &'s Scene<'s>, observer: crate::math::Vec3) -> Result<Shader<'s>> {
        let mut shader = Shader::plain(scene, observer)?.with_sky_domes();
        // (A scene without lights has no air light to change.)
        if let Some(view) = shader.views.first() {
            if let Some(field) = terrain_air::AirField::new(scene, shader.domes.clone())? {
                let model = scene.sky.model();
                let volume = air_volume::AirVolume::new(&field, view.as_ref(), model, observer);
                shader.air = Some(volume);
            }
        }
        Ok(shader)
    }

    /// The terrain's change of the air's light along this observer's views, when a surface
    /// reshapes the planet (what a GPU frame of the same scene adds, `firmament_gpu`).
    pub fn air_volume(&self) -> Option<&air_volume::AirVolume> {
        self.air.as_ref()
    }

    /// The volumes' shadow map of each light (None for a light without one), what a GPU
    /// frame of the same scene samples (`firmament_gpu`).
    pub fn cloud_shadows(&self) -> &[Option<cloud_shadow::CloudShadow>] {
        &self.cloud_shadows
    }

    /// The share of the multiple scattering the air under the clouds keeps per light (None
    /// for a light without a shadow map), what a GPU frame of the same scene samples.
    pub fn shadowed_air(&self) -> &[Option<shadowed_air::ShadowedAir>] {
        &self.shadowed_air
    }

    /// The sky domes, one per light, when the shader has them ([`Shader::with_sky_domes`]).
    pub fn sky_domes(&self) -> Option<&[sky_dome::SkyDome]> {
        self.domes.as_deref().map(Vec::as_slice)
    }

    /// The lights, in the order of the scene's (the views').
    pub fn lights(&self) -> impl Iterator<Item = &crate::scene::Light> {
        self.views.iter().map(|v| v.light())
    }

    /// With the sky's radiance per light from this shader's observer ([`sky_dome`]), for
    /// the irradiance of surfaces under a horizon.
    pub fn with_sky_domes(self) -> Shader<'s> {
        let domes = (self.views.iter())
            .map(|v| sky_dome::SkyDome::new(v.as_ref(), self.channels))
            .collect();
        self.with_domes(Some(Arc::new(domes)))
    }

    /// With the sky domes `domes` (one per light, from [`Shader::with_sky_domes`] of a
    /// shader nearby: the sky's shape changes little over a terrain).
    pub fn with_domes(mut self, domes: Option<Arc<Vec<sky_dome::SkyDome>>>) -> Shader<'s> {
        self.domes = domes;
        self
    }

    /// With an aerial-perspective volume per light for `camera` drawing a `width` ×
    /// `height` image (from this shader's observer), which surfaces' aerial perspective
    /// then reads where it can ([`aerial_volume`]).
    pub fn with_aerial_volumes(
        mut self,
        observer: crate::math::Vec3,
        camera: &crate::scene::PreparedCamera,
        width: usize,
        height: usize,
        config: aerial_volume::AerialVolumeConfig,
    ) -> Result<Shader<'s>> {
        config.validate()?;
        self.aerial = (self.views.iter())
            .map(|v| {
                aerial_volume::AerialVolume::new(
                    v.as_ref(),
                    observer,
                    self.scene.sky.model().bottom_radius_m,
                    camera,
                    width,
                    height,
                    config,
                    self.channels,
                )
            })
            .collect();
        Ok(self)
    }

    /// The lights' disks left out of the sky.
    pub fn without_disks(mut self) -> Shader<'s> {
        self.disks.clear();
        self
    }

    /// [`Shader::new`] without the terrain's change of the air's light: the sky method's
    /// air over a smooth planet, with the surfaces' shadows.
    pub fn plain(scene: &'s Scene<'s>, observer: crate::math::Vec3) -> Result<Shader<'s>> {
        Shader::with_views(scene, observer, false)
    }

    /// [`Shader::plain`] for a few rays only (the terrain's air field at points of the
    /// air): the sky method's probe views ([`crate::sky::SkyMethod::probe`]).
    pub fn probe(scene: &'s Scene<'s>, observer: crate::math::Vec3) -> Result<Shader<'s>> {
        Shader::with_views(scene, observer, true)
    }

    /// [`Shader::probe`] of `scene`, a scene of the same sky and lights as this shader's
    /// (the terrain's air field shades each of its points with and without the relief), with
    /// this shader's views: their tables' slices made once for the two.
    pub fn probe_of<'t>(&self, scene: &'t Scene<'t>) -> Result<Shader<'t>>
    where
        's: 't,
    {
        debug_assert!(
            std::ptr::addr_eq(scene.sky, self.scene.sky)
                && (scene.lights.iter().map(|l| l.direction)).eq(self
                    .scene
                    .lights
                    .iter()
                    .map(|l| l.direction)),
            "probe_of: another sky or other lights"
        );
        let views = (self.views.iter())
            .map(|v| Arc::clone(v) as Arc<dyn SkyView + 't>)
            .collect();
        Shader::assemble(scene, views, true)
    }

    fn with_views(
        scene: &'s Scene<'s>,
        observer: crate::math::Vec3,
        probe: bool,
    ) -> Result<Shader<'s>> {
        let views = (scene.lights.iter())
            .map(|light| match probe {
                true => scene.sky.probe(observer, light),
                false => scene.sky.view(observer, light),
            })
            .map(Arc::from)
            .collect();
        Shader::assemble(scene, views, probe)
    }

    /// The shader of `scene` with its lights' `views`: without the volumes' shadows for a
    /// `probe`.
    fn assemble(
        scene: &'s Scene<'s>,
        views: Vec<Arc<dyn SkyView + 's>>,
        probe: bool,
    ) -> Result<Shader<'s>> {
        let channels = scene.sky.model().channels();
        crate::spectrum::check_channels(channels, "rendering")?;
        let disks = (scene.lights.iter().enumerate())
            .filter(|(_, light)| light.visible_disk)
            .map(|(i, light)| (i, light.angular_radius_rad.cos()))
            .collect();
        let cloud_shadows: Vec<_> = match probe || scene.volumes.is_empty() {
            true => Vec::new(),
            false => (scene.lights.iter())
                .map(|l| cloud_shadow::CloudShadow::new(scene, l))
                .collect(),
        };
        let shadowed_air = (cloud_shadows.iter().zip(views.iter()))
            .map(|(map, view)| {
                let map: &cloud_shadow::CloudShadow = map.as_ref()?;
                Some(shadowed_air::ShadowedAir::new(scene, view.as_ref(), map))
            })
            .collect();
        Ok(Shader {
            scene,
            views,
            disks,
            channels,
            air: None,
            domes: None,
            aerial: Vec::new(),
            cloud_shadows,
            shadowed_air,
        })
    }

    /// Spectral radiance (W·m⁻²·sr⁻¹·nm⁻¹) arriving at the observer along `ray` (from the
    /// observer): the nearest surface lit by the lights (in the shadows the other surfaces
    /// cast) and the sky, seen through aerial perspective, or the sky and the lights'
    /// disks; light shafts where surfaces shadow the air; volumes in front (paper eq. 16).
    pub fn shade(&self, ray: &Ray, scratch: &mut ShadeScratch, out: &mut [f64]) {
        let n = self.channels;
        let scene = self.scene;
        out[..n].iter_mut().for_each(|v| *v = 0.0);
        let hit = scene.nearest_hit(ray, f64::INFINITY);
        let end = hit.map_or(f64::INFINITY, |(_, h)| h.distance_m);
        // Each light's shadow along the ray, kept for the volumes in front.
        let keep = !scene.volumes.is_empty();
        let mut shadows: Vec<volumes::OwnedShadow> = Vec::new();
        match hit {
            Some((i, hit)) => with_channel_buffers(n, |[l, t, albedo, direct, sky, share]| {
                let surface = &scene.surfaces[i];
                surface.albedo(&hit, albedo);
                let mut horizon = [0.0; HORIZON_AZIMUTHS];
                let domes = (self.domes.as_ref()).filter(|_| surface.horizon(&hit, &mut horizon));
                let visible_sky = match domes {
                    Some(_) => 1.0,
                    None => surface.sky_visibility(&hit),
                };
                let up = hit.position.normalize();
                for (j, view) in self.views.iter().enumerate() {
                    let (shadow, lit_at_end, dimmed) = self.shadow(ray, j, end, scratch);
                    if keep {
                        shadows.push(volumes::OwnedShadow::new(shadow, dimmed));
                    }
                    view.sun_and_sky_irradiance(hit.position, hit.normal, direct, sky);
                    if !lit_at_end {
                        direct.iter_mut().for_each(|v| *v = 0.0);
                    }
                    if !scene.volumes.is_empty() {
                        let light = view.light();
                        let mut clear = [0.0; MAX_CHANNELS];
                        clear[..n].copy_from_slice(sky);
                        view.transmittance_to_light(hit.position, share);
                        volumes::dim_surface_light(
                            scene,
                            self.cloud_shadows.get(j).and_then(|m| m.as_ref()),
                            hit.position,
                            hit.normal,
                            light.direction,
                            &light.irradiance[..n],
                            share,
                            direct,
                            sky,
                        );
                        // The diffuse light under the clouds is the neighbourhood's.
                        if let Some(Some(air)) = self.shadowed_air.get(j) {
                            air.ground_sky(hit.position, &clear[..n], sky);
                        }
                    }
                    if let Some(domes) = domes {
                        // The sky's light under the horizon, weighted by its radiance, in
                        // place of the open plane's (1 + n·up)/2 that the sky method applied.
                        domes[j].share(up, hit.normal, &horizon, share);
                        let open = 0.5 * (1.0 + hit.normal.dot(up));
                        for k in 0..n {
                            sky[k] *= if open > 0.0 { share[k] / open } else { 0.0 };
                        }
                    }
                    let from_volume = match (shadow, self.aerial.get(j)) {
                        (Shadow::None, Some(Some(v))) => v.sample(ray.dir, hit.distance_m, l, t),
                        _ => false,
                    };
                    if !from_volume {
                        view.sky_radiance_to_point(hit.position, shadow, l, t);
                    }
                    shadowed_air::dim_multiple(view.as_ref(), ray, dimmed, end, l);
                    // A specular lobe (the sea's glint) on the direct beam.
                    let to_light = view.light().direction;
                    let glint = scene.surfaces[i].specular(&hit, -ray.dir, to_light);
                    for k in 0..n {
                        out[k] += l[k];
                        out[k] += albedo[k] / PI * (direct[k] + visible_sky * sky[k]) * t[k];
                        out[k] += glint * direct[k] * t[k];
                    }
                }
            }),
            None => with_channel_buffers(n, |[l, t]| {
                let disks = (self.disks.iter())
                    .any(|&(i, cos)| ray.dir.dot(scene.lights[i].direction) > cos);
                let background = scene.background.as_ref();
                for (j, view) in self.views.iter().enumerate() {
                    let (shadow, _, dimmed) = self.shadow(ray, j, end, scratch);
                    if keep {
                        shadows.push(volumes::OwnedShadow::new(shadow, dimmed));
                    }
                    // The transmittance along the ray (the same for every light) only for a
                    // disk in view or a background.
                    let t = if (disks || background.is_some()) && j == 0 {
                        &mut t[..]
                    } else {
                        &mut [][..]
                    };
                    view.sky_radiance(ray.dir, shadow, l, t);
                    shadowed_air::dim_multiple(view.as_ref(), ray, dimmed, end, &mut l[..n]);
                    for k in 0..n {
                        out[k] += l[k];
                    }
                }
                if disks {
                    for &(i, _) in &self.disks {
                        scene.lights[i].add_disk_radiance(ray.dir, t, &mut out[..n]);
                    }
                }
                if let Some(b) = background {
                    let f = b.factor(ray.origin, ray.dir);
                    for k in 0..n {
                        out[k] += b.zenith_radiance[k] * f * t[k];
                    }
                }
            }),
        }
        if let Some(air) = &self.air {
            if (ray.origin - air.observer()).length_squared() < 1.0 {
                air.add(ray.dir, end, &mut out[..n]);
            }
        }
        if keep {
            volumes::composite(scene, &self.views, ray, end, &shadows, &mut out[..n]);
        }
    }

    /// The parts of `ray` up to `end` that light `j` reaches (past the surfaces and under
    /// the volumes' shadow map), and whether it reaches `end` past the surfaces (the
    /// volumes' shadow on a surface is [`volumes::dim_surface_light`]'s), and the stretches
    /// below the clouds whose multiple scattering is dimmed ([`shadowed_air`]). In a cloud's
    /// shadow, as in a mountain's, the air loses its single scattering; its multiple
    /// scattering, lit by the sky and the ground around, is the neighbourhood's: under broken
    /// cloud nearly the clear sky's, under an overcast the dim light of its base
    /// (docs/accuracy.md, "Clouds").
    fn shadow<'b>(
        &self,
        ray: &Ray,
        j: usize,
        end: f64,
        scratch: &'b mut ShadeScratch,
    ) -> (Shadow<'b>, bool, &'b shadowed_air::Dimmed) {
        scratch.shadowed.clear();
        scratch.clouded.clear();
        scratch.dimmed.clear();
        let light = &self.scene.lights[j];
        self.scene
            .shadowed_intervals(ray, light.direction, end, &mut scratch.shadowed);
        let lit_at_end = !(scratch.shadowed.iter()).any(|&(a, b)| a <= end && b >= end);
        if let Some(Some(map)) = self.cloud_shadows.get(j) {
            map.shadowed_intervals(ray, end, &mut scratch.clouded);
        }
        if let Some(Some(air)) = self.shadowed_air.get(j) {
            air.weigh(ray, end, &scratch.clouded, &mut scratch.dimmed);
        }
        if scratch.shadowed.is_empty() && scratch.clouded.is_empty() {
            return (Shadow::None, true, &scratch.dimmed);
        }
        scratch.lit.clear();
        scratch.shadowed.extend_from_slice(&scratch.clouded);
        lit_intervals(&mut scratch.shadowed, end, &mut scratch.lit);
        let scratch: &'b ShadeScratch = scratch;
        (Shadow::Lit(&scratch.lit), lit_at_end, &scratch.dimmed)
    }
}

/// Render a frame of `scene` on the CPU, rows in parallel. `progress` receives the fraction
/// done; `cancel` stops it between rows.
pub fn render(
    scene: &Scene,
    settings: &RenderSettings,
    progress: &(dyn Fn(f64) + Sync),
    cancel: Option<&AtomicBool>,
) -> Result<Frame> {
    settings.validate()?;
    let (w, h) = (settings.width, settings.height);
    let model = scene.sky.model();
    let colour = model.colour_matrix();
    let balance = colour.white_balance(&model.solar_irradiance, settings.white_balance);
    let prepared = settings.camera.prepare(model.bottom_radius_m, w, h);
    let observer =
        crate::math::Vec3::new(0.0, 0.0, model.bottom_radius_m + settings.camera.altitude_m);
    let mut shader = Shader::new(scene, observer)?;
    if let Some(config) = scene.aerial_volume {
        shader = shader.with_aerial_volumes(observer, &prepared, w, h, config)?;
    }
    let points = stars::small_disks(&scene.lights, &prepared, w, h);
    shader
        .disks
        .retain(|(i, _)| points.iter().all(|(j, _)| j != i));
    let n = shader.channels;
    let edges = disk_edges::DiskEdges::new(
        &scene.lights,
        shader.disks.iter().map(|d| d.0),
        &prepared,
        w,
        h,
    );
    let mut image = ImageRgbF32::new(w, h);
    let mut mask = vec![false; w * h];
    let done = AtomicUsize::new(0);
    let interrupted = AtomicBool::new(false);
    image
        .data
        .par_chunks_mut(w)
        .zip(mask.par_chunks_mut(w))
        .enumerate()
        .for_each(|(y, (row, mrow))| {
            if cancel.is_some_and(|c| c.load(Ordering::Relaxed)) {
                interrupted.store(true, Ordering::Relaxed);
                return;
            }
            let mut scratch = ShadeScratch::default();
            let mut l = [0.0f64; MAX_CHANNELS];
            let l = &mut l[..n];
            for x in 0..w {
                let Some(ray) = prepared.ray(x as f64 + 0.5, y as f64 + 0.5) else {
                    continue;
                };
                if edges.straddles(&prepared, x, y, ray.dir) {
                    // A disk's edge: the mean over the pixel's footprint.
                    l.iter_mut().for_each(|v| *v = 0.0);
                    let mut sub = [0.0f64; MAX_CHANNELS];
                    let count = (disk_edges::SUBSAMPLES * disk_edges::SUBSAMPLES) as f64;
                    for (dx, dy) in disk_edges::subpixels() {
                        if let Some(r) = prepared.ray(x as f64 + dx, y as f64 + dy) {
                            shader.shade(&r, &mut scratch, &mut sub[..n]);
                            for k in 0..n {
                                l[k] += sub[k] / count;
                            }
                        }
                    }
                } else {
                    shader.shade(&ray, &mut scratch, l);
                }
                let c = colour.to_srgb(l);
                row[x] = [
                    (c[0] * balance[0]) as f32,
                    (c[1] * balance[1]) as f32,
                    (c[2] * balance[2]) as f32,
                ];
                mrow[x] = true;
            }
            let d = done.fetch_add(1, Ordering::Relaxed) + 1;
            if d.is_multiple_of(16) {
                progress(d as f64 / h as f64);
            }
        });
    if interrupted.load(Ordering::Relaxed) {
        return Err(Error::Interrupted);
    }
    if let Some(view) = shader.views.first() {
        let transmittance = |dir: crate::math::Vec3, out: &mut [f64]| {
            stars::scene_transmittance(scene, view.as_ref(), observer, dir, out)
        };
        let points_view = stars::PointView {
            transmittance: &transmittance,
            camera: &prepared,
            colour: &colour,
            balance,
        };
        stars::draw_points(
            scene.stars.iter().chain(points.iter().map(|(_, p)| p)),
            n,
            &points_view,
            &mut image,
            &mask,
        );
    }
    Ok(Frame { image, mask })
}

//! `firmament render`: pictures of the sky from flags or a scene file.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, Result};
use firmament::atmosphere::Model;
use firmament::io::OutputFormat;
use firmament::render::{self, tonemap, RenderSettings};
use firmament::scene::clouds::ViewFootprint;
use firmament::scene::sky_lights::{sources_of, SkySources};
use firmament::scene::terrain::Heightfield;
use firmament::scene::{sun_direction, Projection, SceneFile as Scene};
use firmament::sky::bruneton4d::twilight;

use crate::backend::{Backend, BackendChoice, RenderSky};
use crate::commands::lamps::{lamps, MapFrame};
use crate::commands::outputs::{write_outputs, FileNotes, FileOptions};
use crate::commands::provenance::{exr_attributes, merged, provenance};
use crate::commands::render_args::{scene_from_args, RenderArgs};
use crate::commands::timelapse;
use crate::common::{check_output_dir, print_wavelengths, AtmosphereArgs};
use crate::method::Method;
use firmament::render::aerial_volume::AerialVolumeConfig;

/// Atmosphere arguments equivalent to the scene's.
pub fn atmosphere_args(
    scene: &Scene,
    tables: Option<PathBuf>,
    table_size: &str,
    no_cache: bool,
) -> AtmosphereArgs {
    AtmosphereArgs {
        preset: if scene.atmosphere.file.is_none() {
            Some(scene.atmosphere.preset.clone())
        } else {
            None
        },
        atmosphere: scene.atmosphere.file.clone(),
        wavelengths: scene.atmosphere.wavelengths.clone(),
        adjust: crate::common::AdjustArgs::of(&scene.atmosphere.adjust),
        tables,
        table_size: table_size.to_string(),
        no_cache,
        ..AtmosphereArgs::default()
    }
}

/// The render settings of the scene's camera and image.
pub fn render_settings(scene: &Scene) -> RenderSettings<'_> {
    RenderSettings {
        camera: &scene.camera,
        width: scene.image.width,
        height: scene.image.height,
        white_balance: scene.output.white_balance,
    }
}

/// The scene's lights, glow and stars: from `[time]` at `[location]` when given, else its
/// sun.
pub fn sources_of_scene(model: &Model, scene: &Scene) -> Result<SkySources> {
    Ok(match scene.astro()? {
        Some(sky) => {
            let moon_disk = scene.time.as_ref().is_none_or(|t| t.moon_disk);
            sources_of(model, &sky, scene.sun.disk, moon_disk)
        }
        None => SkySources::sun(
            model,
            sun_direction(scene.sun.zenith_deg, scene.sun.azimuth_deg),
            scene.sun.disk,
        ),
    })
}

/// A note when the sun is below the tables' lowest sun (the twilight extrapolated,
/// `twilight::note`) or the air is optically thick (`thickness::note`).
fn approximation_notes(model: &Model, scene: &Scene) -> Result<()> {
    let zenith_deg = match scene.astro()? {
        Some(sky) => sky.sun.apparent_zenith_deg,
        None => scene.sun.zenith_deg,
    };
    if let Some(note) = twilight::note(model.mu_s_min, zenith_deg.to_radians().cos()) {
        eprintln!("note: {note}");
    }
    if let Some(note) = firmament::sky::bruneton4d::thickness::note(model) {
        eprintln!("note: {note}");
    }
    Ok(())
}

/// The scene's EV100, or the automatic exposure of the frame.
pub fn ev100(scene: &Scene, frame: &render::Frame) -> f64 {
    scene
        .output
        .ev100
        .unwrap_or_else(|| tonemap::auto_ev100(frame.log_average_luminance()))
}

/// The scene's terrain on `model`'s planet (`terrain: …` on stderr unless `quiet`).
pub fn build_terrain(model: &Model, scene: &Scene, quiet: bool) -> Result<Option<Heightfield>> {
    let t = Instant::now();
    let terrain = scene.build_terrain(model)?;
    if let (Some(h), false) = (&terrain, quiet) {
        eprintln!(
            "terrain: {}×{} vertices, {:.0} m spacing, up to {:.0} m, in {:.2} s",
            h.heights.nx,
            h.heights.ny,
            h.heights.spacing_m,
            h.max_height_m(),
            t.elapsed().as_secs_f64()
        );
    }
    Ok(terrain)
}

/// The scene's terrain and the atmosphere arguments of its tables. Without --tables the
/// tables' ground albedo is the terrain's mean, so the ground bounce in the sky's light
/// (its irradiance, the multiple scattering) is the terrain's and not the preset's grey;
/// with --tables theirs is kept, with a note. The planet's sphere around the terrain takes
/// the same albedo.
pub fn terrain_and_atmosphere(
    scene: &Scene,
    tables: Option<PathBuf>,
    table_size: &str,
    no_cache: bool,
    quiet: bool,
) -> Result<(Option<Heightfield>, AtmosphereArgs)> {
    let mut atmosphere = atmosphere_args(scene, tables, table_size, no_cache);
    if scene.terrain.is_none() {
        return Ok((None, atmosphere));
    }
    let model = atmosphere.model()?;
    let terrain = build_terrain(&model, scene, quiet)?;
    if let Some(t) = &terrain {
        let albedo = t.mean_albedo(model.channels());
        let k = model.channels() / 2;
        if atmosphere.tables.is_none() {
            if !quiet {
                eprintln!(
                    "terrain: the tables' ground albedo is the terrain's mean, {:.3} at {:.0} nm (the atmosphere's: {:.3})",
                    albedo[k], model.wavelengths.nm()[k], model.ground_albedo[k]
                );
            }
            atmosphere.ground_albedo = Some(albedo);
            let lift = t.floor_m();
            if !quiet && lift > 0.0 {
                eprintln!(
                    "terrain: the tables' ground is lifted to the terrain's floor, {lift:.0} m (the air below it is the terrain's)"
                );
            }
            atmosphere.ground_lift_m = Some(lift);
        } else if !quiet {
            eprintln!(
                "note: the tables' ground albedo ({:.3} at {:.0} nm) is kept; the terrain's mean is {:.3} (without --tables the tables take it)",
                model.ground_albedo[k], model.wavelengths.nm()[k], albedo[k]
            );
        }
    }
    Ok((terrain, atmosphere))
}

/// Render the scene with a sky on its backend over its terrain (built by
/// [`build_terrain`]); returns the frame and the EV100 used.
pub fn render_scene(
    sky: &RenderSky,
    scene: &Scene,
    terrain: Option<&Heightfield>,
    no_cache: bool,
    quiet: bool,
) -> Result<(render::Frame, f64)> {
    let sources = sources_of_scene(sky.model(), scene)?;
    let camera = scene.camera_over(terrain, sky.model().bottom_radius_m);
    let radius = terrain.map_or(sky.model().bottom_radius_m, |t| t.radius_m);
    let planet = scene.build_surface(radius, sky.model().wavelengths.nm())?;
    let mut clouds = crate::common::scene_clouds(scene, radius, no_cache, quiet)?;
    let settings = RenderSettings {
        camera: &camera,
        ..render_settings(scene)
    };
    // The clouds' density is filtered over the pixels' footprint (far clouds).
    let prepared = camera.prepare(sky.model().bottom_radius_m, settings.width, settings.height);
    if let Some((eye, pixel_angle_rad)) = prepared.pixel_footprint() {
        let view = ViewFootprint {
            eye,
            pixel_angle_rad,
        };
        for c in &mut clouds {
            c.layer.set_view(view, None);
        }
    }
    let frame = sky
        .render(
            &settings,
            &sources,
            terrain,
            planet.as_ref(),
            &clouds,
            quiet,
        )
        .context("rendering")?;
    let ev100 = ev100(scene, &frame);
    Ok((frame, ev100))
}

/// Run `firmament render`.
pub fn run(args: &RenderArgs) -> Result<()> {
    let scene = scene_from_args(args)?;
    let files = FileOptions::from_args(args)?;
    let times = match (&args.until, &args.every, &scene.time) {
        (Some(until), Some(every), Some(t)) => {
            for f in &scene.output.files {
                OutputFormat::from_path(f)?;
                timelapse::numbered(f, 0)?;
            }
            Some(timelapse::instants(&t.at, until, every)?)
        }
        _ => {
            for f in &scene.output.files {
                check_output_dir(f, "--out")?;
                OutputFormat::from_path(f)?;
            }
            None
        }
    };
    if times.is_some() && args.method == Method::Reference {
        anyhow::bail!(
            "a time-lapse (--until) uses the tables: `--method reference` is not supported with it"
        );
    }
    match args.method {
        Method::Bruneton4d | Method::Hillaire2020 | Method::Elek3d => {}
        Method::Reference => {
            if args.aerial_volume {
                anyhow::bail!("`--aerial-volume` is for the tabulated methods: `--method reference` traces every path");
            }
            if args.tables.is_some() {
                anyhow::bail!("`--method reference` uses no tables: --tables makes no sense here");
            }
            if args.backend == BackendChoice::Gpu {
                anyhow::bail!(
                    "`--method reference` runs on the CPU only: `--backend gpu` is not supported with it (use `--backend cpu` or `auto`, or `--method bruneton4d` for the GPU)"
                );
            }
            if !args.quiet {
                eprintln!("backend: cpu (the reference path tracer runs on the CPU only)");
            }
            let (terrain, atmosphere) =
                terrain_and_atmosphere(&scene, None, &args.table_size, true, args.quiet)?;
            let model = atmosphere.unlifted().model()?;
            print_wavelengths(&model, args.quiet);
            let t = Instant::now();
            let (frame, ev100) = super::render_reference::render_scene_reference(
                &model,
                &scene,
                terrain.as_ref(),
                args.samples,
                args.no_cache,
                args.quiet,
            )?;
            if !args.quiet {
                eprintln!(
                    "render (reference): {}×{} {:?} in {:.2} s (EV100 {:.1})",
                    scene.image.width,
                    scene.image.height,
                    scene.camera.projection,
                    t.elapsed().as_secs_f64(),
                    ev100
                );
            }
            let provenance = provenance(&model, "reference (Monte Carlo path tracer)", None);
            let notes = notes_of(&model, &scene, terrain.as_ref(), &files, ev100, provenance)?;
            return write_outputs(&frame, &scene, ev100, files, &notes, args.quiet);
        }
    }
    args.hillaire.check(&[args.method])?;
    let terrain_wanted = scene.terrain.is_some();
    if args.method == Method::Elek3d {
        if args.backend == BackendChoice::Gpu && terrain_wanted {
            anyhow::bail!("`--method elek3d` draws terrain on the CPU only so far: use `--backend cpu` or `auto`, or `--no-terrain`");
        }
        if args.tables.is_some() {
            anyhow::bail!("`--tables` holds 4D tables: `--method elek3d` builds its own 3D ones");
        }
    }
    if args.method == Method::Hillaire2020 {
        if args.backend == BackendChoice::Gpu && terrain_wanted {
            anyhow::bail!("`--method hillaire2020` draws terrain on the CPU only so far: use `--backend cpu` or `auto`, or `--no-terrain`");
        }
        if args.tables.is_some() {
            anyhow::bail!("`--tables` holds 4D tables: `--method hillaire2020` builds its own (in milliseconds)");
        }
    }
    // The GPU marches clouds through the 4D tables' sky, over the planet's sphere or a
    // terrain (render::volumes' twin in firmament-gpu's shaders/render/volumes.wgsl).
    let clouds_cpu_only =
        !scene.clouds.is_empty() && (args.method != Method::Bruneton4d || args.aerial_volume);
    let backend = match Backend::open(args.backend, args.quiet)? {
        Backend::Gpu(_)
            if args.backend == BackendChoice::Auto
                && ((matches!(args.method, Method::Hillaire2020 | Method::Elek3d)
                    && terrain_wanted)
                    || args.aerial_volume) =>
        {
            if !args.quiet {
                eprintln!("note: the terrain of hillaire2020 and elek3d and --aerial-volume render on the CPU only so far: using the CPU");
            }
            Backend::Cpu
        }
        Backend::Gpu(_) if clouds_cpu_only && args.backend == BackendChoice::Gpu => {
            anyhow::bail!(
                "clouds ([[clouds]]) render on the GPU with `--method bruneton4d` and without `--aerial-volume` so far: `--backend cpu` or `auto` render them here"
            )
        }
        Backend::Gpu(_) if clouds_cpu_only => {
            if !args.quiet {
                eprintln!("note: clouds with hillaire2020, elek3d or `--aerial-volume` render on the CPU only so far: using the CPU");
            }
            Backend::Cpu
        }
        backend => backend,
    };
    let (terrain, mut atmosphere) = terrain_and_atmosphere(
        &scene,
        args.tables.clone(),
        &args.table_size,
        args.no_cache,
        args.quiet,
    )?;
    atmosphere.order_args = args.order_args;
    atmosphere.hillaire = args.hillaire;
    print_wavelengths(&atmosphere.model()?, args.quiet);
    let t = Instant::now();
    let mut sky = RenderSky::new(&backend, &atmosphere, args.method, args.quiet)?;
    if args.aerial_volume {
        sky = sky.with_aerial_volume(AerialVolumeConfig::default())?;
    }
    if !args.quiet && args.tables.is_some() {
        eprintln!(
            "tables: loaded{} in {:.2} s",
            if sky.on().is_empty() {
                ""
            } else {
                " and uploaded to the GPU (render shader compiled)"
            },
            t.elapsed().as_secs_f64()
        );
    }
    if !args.quiet && times.is_none() && args.method == Method::Bruneton4d {
        approximation_notes(sky.model(), &scene)?;
    }
    if let Some(times) = times {
        let t = Instant::now();
        let (rendered, _) = timelapse::run(
            &sky,
            &scene,
            terrain.as_ref(),
            &times,
            args.resume,
            files,
            args.no_cache,
            args.quiet,
        )?;
        if !args.quiet && rendered > 0 {
            eprintln!(
                "time-lapse: {:.2} s per frame",
                t.elapsed().as_secs_f64() / rendered as f64
            );
        }
        return Ok(());
    }
    let t = Instant::now();
    let (frame, ev100) = render_scene(&sky, &scene, terrain.as_ref(), args.no_cache, args.quiet)?;
    if !args.quiet {
        eprintln!(
            "render: {}×{} {:?}{} in {:.2} s (EV100 {:.1}{})",
            scene.image.width,
            scene.image.height,
            scene.camera.projection,
            sky.on(),
            t.elapsed().as_secs_f64(),
            ev100,
            if scene.output.ev100.is_none() {
                ", automatic"
            } else {
                ""
            }
        );
    }
    let notes = file_notes(&sky, &scene, terrain.as_ref(), &files, ev100)?;
    write_outputs(&frame, &scene, ev100, files, &notes, args.quiet)
}

/// The files' notes for a frame drawn from the tables of `sky`.
pub fn file_notes(
    sky: &RenderSky,
    scene: &Scene,
    terrain: Option<&Heightfield>,
    files: &FileOptions,
    ev100: f64,
) -> Result<FileNotes> {
    let method = format!("{}{}", sky.describe(), sky.on());
    let provenance = provenance(sky.model(), &method, Some(sky.tables_json()));
    notes_of(sky.model(), scene, terrain, files, ev100, provenance)
}

/// The files' notes: the provenance with the camera, the lights and the exposure as EXR
/// attributes, and the lamps of an environment map.
fn notes_of(
    model: &Model,
    scene: &Scene,
    terrain: Option<&Heightfield>,
    files: &FileOptions,
    ev100: f64,
    provenance: serde_json::Value,
) -> Result<FileNotes> {
    let camera = scene.camera_over(terrain, model.bottom_radius_m);
    let sources = sources_of_scene(model, scene)?;
    let extra = serde_json::json!({
        "camera": camera,
        "image": { "width": scene.image.width, "height": scene.image.height },
        "sun": match scene.astro()? {
            Some(_) => serde_json::json!({ "time": scene.time, "location": scene.location }),
            None => serde_json::json!({
                "zenith_deg": scene.sun.zenith_deg,
                "azimuth_deg": scene.sun.azimuth_deg,
            }),
        },
        "exposure": {
            "ev100": ev100,
            "automatic": scene.output.ev100.is_none(),
            "tonemap": scene.output.tonemap,
            "note": "EV100 and the tone curve apply to PNG files; EXR, HDR and DDS files hold linear values, Y in cd/m²",
        },
        "colour_space": files.gamut.name(),
    });
    let serde_json::Value::Object(extra) = extra else {
        unreachable!("an object")
    };
    let full = merged(provenance.clone(), extra);
    let all_round = matches!(
        scene.camera.projection,
        Projection::Equirect | Projection::Cubemap
    );
    let lamps = all_round.then(|| {
        let frame = MapFrame {
            projection: scene.camera.projection,
            heading_deg: scene.camera.heading_deg,
            layout: files.layout,
        };
        let radius = model.bottom_radius_m + camera.altitude_m;
        lamps(
            model,
            &sources.lights,
            radius,
            frame,
            scene.sun.disk,
            full.clone(),
        )
    });
    Ok(FileNotes {
        attributes: exr_attributes(&full),
        lamps,
    })
}

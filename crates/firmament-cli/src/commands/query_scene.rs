//! `firmament query --scene FILE`: the radiance a camera at the scene's observer sees in
//! each `--view`, everything in the scene included (its terrain lit and shadowed, the light
//! shafts, the ground, aerial perspective, the clouds; the sun's disk excluded), from the tables through
//! the renderer's own shading or from the reference path tracer with the same surfaces. The
//! JSON is `query`'s.

use anyhow::Result;
use firmament::math::direction_from_zenith_azimuth;
use firmament::reference::{self, ReferenceSettings};
use firmament::render::{ShadeScratch, Shader};
use firmament::scene::{Ray, Scene as RenderScene, SceneFile, Surface, Volume};
use serde_json::json;

use super::provenance::provenance;

use super::query::{parse_view, QueryArgs, ViewAnswer};
use super::render::{sources_of_scene, terrain_and_atmosphere};
use crate::common::print_wavelengths;
use crate::method::Method;

/// Run `query --scene`.
pub fn run(args: &QueryArgs, reference: Option<ReferenceSettings>) -> Result<serde_json::Value> {
    let path = args.scene.as_ref().expect("--scene");
    let mut scene = SceneFile::from_file(path)?;
    if let Some(w) = &args.atmosphere.wavelengths {
        scene.atmosphere.wavelengths = Some(w.clone());
    }
    if args.no_clouds {
        scene.clouds.clear();
    }
    let views: Vec<(f64, f64)> = (args.views.iter())
        .map(|v| parse_view(v))
        .collect::<Result<_>>()?;
    let (terrain, mut atmosphere) = terrain_and_atmosphere(
        &scene,
        args.atmosphere.tables.clone(),
        &args.atmosphere.table_size,
        args.atmosphere.no_cache,
        args.quiet,
    )?;
    atmosphere.hillaire = args.atmosphere.hillaire;
    // What the reference cannot trace is refused before the tables are computed.
    if reference.is_some() && scene.surface.as_ref().is_some_and(|s| s.glint) {
        anyhow::bail!("`--method reference` traces Lambertian surfaces only: the sun's glint on the sea is not in it (set `glint = false` in [surface] to compare the map)");
    }
    let model = atmosphere.model()?;
    let sources = sources_of_scene(&model, &scene)?;
    if reference.is_some() && (sources.lights.len() > 1 || sources.background.is_some()) {
        anyhow::bail!("`--method reference` traces the sun's light only so far: a [time] with the moon up or the sun down is not supported with it");
    }
    print_wavelengths(&model, args.quiet);
    // The reference's transmittances come from the 4D tables.
    let table_method = match args.method {
        Method::Reference => Method::Bruneton4d,
        m => m,
    };
    let sky = atmosphere.cpu_sky(table_method, args.quiet)?;
    let model = sky.model();
    let nm = model.wavelengths.nm().to_vec();
    let colour = model.colour_matrix();
    let camera = scene.camera_over(terrain.as_ref(), model.bottom_radius_m);
    let observer = firmament::math::Vec3::new(0.0, 0.0, model.bottom_radius_m + camera.altitude_m);
    let radius = terrain
        .as_ref()
        .map_or(model.bottom_radius_m, |t| t.radius_m);
    let planet = scene.build_surface(radius, &nm)?;
    let clouds = crate::common::scene_clouds(&scene, radius, args.atmosphere.no_cache, args.quiet)?;
    let mut render_scene = RenderScene::clear_sky(sky.method(), sources.lights[0].direction, false);
    render_scene.lights = sources.lights.clone();
    render_scene
        .lights
        .iter_mut()
        .for_each(|l| l.visible_disk = false);
    render_scene.background = sources.background.clone();
    if let Some(t) = &terrain {
        render_scene.add_terrain(t, t.radius_m);
    }
    if let Some(p) = &planet {
        render_scene.set_ground(p);
    }
    for c in &clouds {
        render_scene.volumes.push(Box::new(c));
    }
    let volumes: Vec<Box<dyn Volume + '_>> = clouds.iter().map(|c| Box::new(c) as _).collect();
    let shader = Shader::new(&render_scene, observer)?;
    let first_view = sky.method().view(observer, &render_scene.lights[0]);
    // The reference meets the terrain and the planet's map as Lambertian surfaces (the map's
    // sphere lies on its ground sphere and wins the tie).
    let mut surfaces: Vec<Box<dyn Surface + '_>> =
        terrain.iter().map(|t| Box::new(t) as _).collect();
    if let Some(p) = &planet {
        surfaces.push(Box::new(p));
    }
    let settings = reference.map(|s| ReferenceSettings {
        include_ground: true,
        ..s
    });
    // The reference meets the terrain in the atmosphere as it is (the tables' ground may be
    // lifted to the terrain's floor).
    let truth = match settings {
        Some(_) => Some(atmosphere.unlifted().model()?),
        None => None,
    };
    let n = nm.len();
    let mut scratch = ShadeScratch::default();
    let mut answers = Vec::new();
    for (i, &(zenith_deg, azimuth_deg)) in views.iter().enumerate() {
        let dir = direction_from_zenith_azimuth(zenith_deg.to_radians(), azimuth_deg.to_radians());
        let ray = Ray {
            origin: observer,
            dir,
        };
        let mut radiance = vec![0.0; n];
        shader.shade(&ray, &mut scratch, &mut radiance);
        // The air's transmittance to the first surface, or out of the atmosphere (the
        // clouds' not included).
        let mut transmittance = vec![0.0; n];
        match render_scene.nearest_hit(&ray, f64::INFINITY) {
            Some((_, hit)) => first_view.transmittance_to_point(hit.position, &mut transmittance),
            None => first_view.sky_radiance(
                dir,
                firmament::sky::Shadow::None,
                &mut vec![0.0; n],
                &mut transmittance,
            ),
        }
        let estimate = settings.as_ref().map(|s| {
            let sun = render_scene.lights[0].direction;
            let truth = truth.as_ref().expect("the reference's model");
            let e = reference::scene_radiance(
                truth, &volumes, &surfaces, observer, dir, sun, s, i as u64,
            );
            radiance.copy_from_slice(&e.radiance);
            e
        });
        answers.push(ViewAnswer::new(
            (zenith_deg, azimuth_deg),
            &colour,
            radiance,
            transmittance,
            estimate,
        ));
    }
    let sun = &render_scene.lights[0];
    let up = sun.direction.z.clamp(-1.0, 1.0);
    let method = match &settings {
        None => format!("views: the renderer's shading of the scene with {} (terrain, shadows, light shafts, ground, aerial perspective, clouds; the sun's disk excluded)", sky.name()),
        Some(s) => format!(
            "views: spectral Monte Carlo reference path tracer through the same scene (the terrain intersected as a Lambertian surface, the clouds by delta tracking), {} paths per wavelength and view, seed {} (view i uses stream key i); the sun's disk excluded",
            s.samples, s.seed
        ),
    };
    Ok(json!({
        "method": args.method.name(),
        "scene": path.display().to_string(),
        "wavelengths_nm": nm,
        "units": {
            "radiance": "W m-2 sr-1 nm-1",
            "luminance": "cd m-2 (CIE 1931 2 deg, 683 lm/W; spectrum linearly interpolated between samples)",
        },
        // Above the planet's sphere (the camera's is above the tables' ground).
        "altitude_m": camera.altitude_m + atmosphere.ground_lift_m.unwrap_or(0.0),
        "terrain_height_m": terrain.as_ref().map(|t| t.height_at(0.0, 0.0)),
        // The tables' ground above the planet's sphere (the terrain's floor), when lifted.
        "tables_ground_m": atmosphere.ground_lift_m,
        // The scene's cloud layers in the views (none with --no-clouds).
        "cloud_layers": clouds.len(),
        "sun": {
            "zenith_deg": up.acos().to_degrees(),
            "azimuth_deg": sun.direction.x.atan2(sun.direction.y).to_degrees().rem_euclid(360.0),
        },
        "solar_illuminance_toa_lux": colour.to_xyz(&sun.irradiance)[1],
        "views": answers,
        "notes": [method, "transmittance (per view): the air's, from the tables, to the first surface the view meets or out of the atmosphere"],
        "provenance": provenance(
            model,
            if settings.is_none() { sky.name() } else { "reference (Monte Carlo path tracer)" },
            Some(sky.tables_json()),
        ),
    }))
}

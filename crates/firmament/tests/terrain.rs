//! The terrain against independent computations: ray–heightfield hits against a fine march
//! (thin ridges included), a flat terrain against the sphere's ground, the lit segments
//! against shadow rays cast along the view ray, and a fully shadowed valley's light.

mod common;

use common::sky;

use firmament::atmosphere::Atmosphere;
use firmament::math::{direction_from_zenith_azimuth, Vec3};
use firmament::reference::rng::Rng;
use firmament::render::{ShadeScratch, Shader};
use firmament::scene::surface::lit_intervals;
use firmament::scene::terrain::grid::Grid;
use firmament::scene::terrain::{Heightfield, Materials, ReliefParams, TerrainConfig};
use firmament::scene::{sun_direction, Ray, Scene, Surface};
use firmament::sky::bruneton4d::{Bruneton4d, TableConfig};
use firmament::sky::{Shadow, SkyMethod};
use firmament::spectrum::Wavelengths;

const R: f64 = 6_360_000.0;

/// A rough relief 6 km across with a one-vertex-wide wall (a ridge thinner than a cell's
/// diagonal) through it.
fn rough(thin_wall: bool) -> Heightfield {
    let mut grid = firmament::scene::terrain::relief::relief(&ReliefParams {
        seed: 11,
        extent_m: 6000.0,
        resolution: 129,
        height_scale_m: 900.0,
        feature_size_m: 2500.0,
        floor_m: 50.0,
        valley_width_m: 0.0,
        valley_heading_deg: 0.0,
        centre_m: [0.0, 0.0],
    });
    if thin_wall {
        for j in 0..grid.ny {
            grid.values[j * grid.nx + 80] = 1500.0;
        }
    }
    Heightfield::new(grid, R, Materials::Uniform(vec![0.2; 3]))
}

/// The first t where `ray` is below the terrain, by 0.25 m steps refined by bisection.
fn marched_hit(hf: &Heightfield, ray: &Ray, max: f64) -> Option<f64> {
    // Below the terrain, on its grid (off it the sphere is another surface).
    let below = |t: f64| {
        let p = ray.origin + t * ray.dir;
        let (gx, gy) = hf.heights.cell_coords(R * p.x / p.z, R * p.y / p.z);
        hf.heights.contains(gx, gy) && p.length() - R < hf.height_below(p)
    };
    let step = 0.25;
    let mut t = step;
    while t < max {
        if below(t) {
            let (mut a, mut b) = (t - step, t);
            for _ in 0..40 {
                let m = 0.5 * (a + b);
                if below(m) {
                    b = m
                } else {
                    a = m
                }
            }
            return Some(b);
        }
        t += step;
    }
    None
}

fn random_ray(rng: &mut Rng, max_height: f64) -> Ray {
    let (x, y) = (
        rng.next_f64() * 6000.0 - 3000.0,
        rng.next_f64() * 6000.0 - 3000.0,
    );
    let h = 200.0 + rng.next_f64() * max_height;
    let origin = Vec3::new(x, y, R).normalize() * (R + h);
    // Downward to slightly upward, any azimuth.
    let zenith = (80.0 + rng.next_f64() * 25.0).to_radians();
    let azimuth = rng.next_f64() * std::f64::consts::TAU;
    Ray {
        origin,
        dir: direction_from_zenith_azimuth(zenith, azimuth),
    }
}

#[test]
fn heightfield_hits_match_a_fine_march_and_never_miss_thin_ridges() {
    let hf = rough(true);
    let mut rng = Rng::for_key(1, 2, 3, 4);
    let (mut hits, mut worst) = (0, 0.0f64);
    for k in 0..300 {
        let ray = random_ray(&mut rng, 1400.0);
        let above = ray.origin.length() - R > hf.height_below(ray.origin);
        if !above {
            continue;
        }
        let exact = hf.intersect(&ray, 9000.0).map(|h| h.distance_m);
        let marched = marched_hit(&hf, &ray, 9000.0);
        match (exact, marched) {
            (Some(a), Some(b)) => {
                hits += 1;
                worst = worst.max((a - b).abs());
            }
            (None, None) => {}
            other => panic!("ray {k}: exact {:?} vs marched {:?}", other.0, other.1),
        }
    }
    assert!(hits > 80, "{hits} hits");
    // The march resolves 0.25 m steps: the two agree to well under a step.
    assert!(worst < 0.05, "worst distance difference {worst} m");
    // Horizontal rays at the wall's foot all stop at the wall (x = vertex 80).
    let wall_x = -3000.0 + 80.0 * 6000.0 / 128.0;
    for k in 0..50 {
        let y = -2500.0 + 100.0 * k as f64;
        let origin = Vec3::new(wall_x - 700.0, y, R).normalize() * (R + 1400.0);
        let ray = Ray {
            origin,
            dir: Vec3::X,
        };
        let hit = hf.intersect(&ray, 2000.0).expect("the wall is hit");
        let p = hit.position;
        assert!(
            (R * p.x / p.z - wall_x).abs() < 47.0,
            "hit at u = {} (wall at {wall_x})",
            R * p.x / p.z
        );
    }
}

#[test]
fn a_flat_terrain_renders_as_the_sphere_ground() {
    let sky = sky();
    let model = sky.model();
    let flat = Grid {
        nx: 65,
        ny: 65,
        origin: [-20_000.0, -20_000.0],
        spacing_m: 40_000.0 / 64.0,
        axis: [1.0, 0.0],
        values: vec![0.0; 65 * 65],
    };
    let sun = sun_direction(70.0, 200.0);
    let plain = Scene::clear_sky(sky, sun, false);
    let mut terrain = Scene::clear_sky(sky, sun, false);
    terrain.surfaces.insert(
        0,
        Box::new(Heightfield::new(
            flat,
            model.bottom_radius_m,
            Materials::Uniform(model.ground_albedo.clone()),
        )),
    );
    let origin = Vec3::new(0.0, 0.0, model.bottom_radius_m + 300.0);
    let (a, b) = (
        Shader::new(&plain, origin).unwrap(),
        Shader::new(&terrain, origin).unwrap(),
    );
    let mut scratch = ShadeScratch::default();
    let mut worst = 0.0f64;
    for k in 0..60 {
        let dir = direction_from_zenith_azimuth(
            (60.0 + 0.5 * k as f64).to_radians(),
            (6.0 * k as f64).to_radians(),
        );
        let ray = Ray { origin, dir };
        let (mut la, mut lb) = ([0.0; 3], [0.0; 3]);
        a.shade(&ray, &mut scratch, &mut la);
        b.shade(&ray, &mut scratch, &mut lb);
        for c in 0..3 {
            worst = worst.max((la[c] - lb[c]).abs() / la[c]);
        }
    }
    assert!(worst < 1e-6, "worst relative difference {worst}");
}

/// A valley (the rough relief) under a low sun: the shadowed length of view rays from the
/// intervals against shadow rays cast every metre along them.
#[test]
fn lit_segments_match_shadow_rays_along_the_view() {
    let hf = rough(false);
    let light = sun_direction(84.0, 250.0);
    let mut rng = Rng::for_key(9, 8, 7, 6);
    let (mut tested, mut disagree, mut samples) = (0, 0usize, 0usize);
    let mut shadowed_total = 0.0;
    for _ in 0..120 {
        let ray = random_ray(&mut rng, 900.0);
        if ray.origin.length() - R <= hf.height_below(ray.origin) + 5.0 {
            continue;
        }
        let end = hf.intersect(&ray, 8000.0).map_or(8000.0, |h| h.distance_m);
        let mut shadowed = Vec::new();
        hf.shadowed_intervals(&ray, light, end, &mut shadowed);
        let mut lit = Vec::new();
        lit_intervals(&mut shadowed, end, &mut lit);
        tested += 1;
        let mut t = 0.5;
        while t < end - 0.5 {
            let p = ray.origin + t * ray.dir;
            t += 1.0;
            // The shadows are computed over the terrain's rectangle.
            let (gx, gy) = hf.heights.cell_coords(R * p.x / p.z, R * p.y / p.z);
            if !hf.heights.contains(gx, gy) {
                continue;
            }
            let truth = hf.occludes(p, light);
            let said = !lit.iter().any(|&(a, b)| t - 1.0 >= a && t - 1.0 <= b);
            samples += 1;
            shadowed_total += f64::from(u8::from(truth));
            if truth != said {
                disagree += 1;
            }
        }
    }
    assert!(tested > 60, "{tested} rays");
    let fraction = disagree as f64 / samples as f64;
    eprintln!("lit segments: {disagree} of {samples} samples disagree with shadow rays");
    let shadowed = shadowed_total / samples as f64;
    assert!(
        shadowed > 0.05,
        "only {shadowed} of the samples in shadow ({fraction} disagree)"
    );
    // The shadow's edge is interpolated within a cell (47 m): a small share disagrees.
    assert!(
        fraction < 0.01,
        "{disagree} of {samples} samples disagree ({fraction})"
    );
}

/// The shadow at the surface from the shadow field where its corners agree (and exact
/// rays on its edge) against exact shadow rays everywhere, at the ends of random rays on
/// the rough relief under a low and a high sun.
#[test]
fn surface_shadows_from_the_field_match_exact_rays() {
    let hf = rough(false);
    let mut rng = Rng::for_key(5, 6, 7, 8);
    for (zenith, azimuth) in [(84.0, 250.0), (60.0, 120.0)] {
        let light = sun_direction(zenith, azimuth);
        let field = hf.shadow_field(light);
        let (mut ends, mut disagree, mut shadowed) = (0, 0, 0);
        while ends < 2000 {
            let ray = random_ray(&mut rng, 900.0);
            if ray.origin.length() - R <= hf.height_below(ray.origin) + 5.0 {
                continue;
            }
            let Some(hit) = hf.intersect(&ray, 8000.0) else {
                continue;
            };
            let gr = firmament::scene::terrain::grid::GridRay {
                origin: ray.origin,
                dir: ray.dir,
                radius_m: R,
            };
            let exact = hf.end_in_shadow(&gr, light, hit.distance_m);
            let fielded = field.end_in_shadow(&hf, &gr, hit.distance_m);
            assert!(exact.is_some() && fielded.is_some());
            ends += 1;
            shadowed += usize::from(exact == Some(true));
            disagree += usize::from(exact != fielded);
        }
        eprintln!(
            "sun at {zenith}°: {disagree} of {ends} surface points disagree ({shadowed} in shadow)"
        );
        assert!(shadowed > 100, "{shadowed} of {ends} in shadow");
        assert!(disagree * 200 <= ends, "{disagree} of {ends} disagree");
    }
}

/// A wall of rock between the valley and a low sun: the ground behind it gets no direct
/// light and the air in front of it no single scattering, only the sky's light.
#[test]
fn a_fully_blocked_sun_leaves_only_the_sky_light() {
    let sky = sky();
    let model = sky.model();
    let r = model.bottom_radius_m;
    let n = 81;
    let spacing = 100.0;
    // Heights: 0 in the valley, a 3 km wall 2 km to the west (x < −2000).
    let values = (0..n * n)
        .map(|k| if (k % n) < 18 { 3000.0 } else { 0.0 })
        .collect();
    let grid = Grid {
        nx: n,
        ny: n,
        origin: [-4000.0, -4000.0],
        spacing_m: spacing,
        axis: [1.0, 0.0],
        values,
    };
    let albedo = 0.3;
    let mut hf = Heightfield::new(grid, r, Materials::Uniform(vec![albedo; 3]));
    // The tables' light alone: without the wall's change of the air's light.
    hf.air_light = false;
    // The sun 10° up in the west, behind the wall (which rises 56° seen from the valley).
    let sun = sun_direction(80.0, 270.0);
    let mut scene = Scene::clear_sky(sky, sun, false);
    scene.surfaces.insert(0, Box::new(hf));
    let origin = Vec3::new(500.0, 0.0, r).normalize() * (r + 20.0);
    let shader = Shader::new(&scene, origin).unwrap();
    let view = sky.view(origin, &scene.lights[0]);
    let mut scratch = ShadeScratch::default();
    for azimuth in [0.0, 45.0, 135.0, 180.0] {
        let ray = Ray {
            origin,
            dir: direction_from_zenith_azimuth(95f64.to_radians(), f64::to_radians(azimuth)),
        };
        let hit = scene.nearest_hit(&ray, f64::INFINITY).unwrap().1;
        let mut l = [0.0; 3];
        shader.shade(&ray, &mut scratch, &mut l);
        // Expected: the in-scattering with the whole ray in shadow, and the sky's light on
        // the ground only.
        let (mut s, mut t, mut direct, mut sky_irr) = ([0.0; 3], [0.0; 3], [0.0; 3], [0.0; 3]);
        view.sky_radiance_to_point(hit.position, Shadow::Lit(&[]), &mut s, &mut t);
        view.sun_and_sky_irradiance(hit.position, hit.normal, &mut direct, &mut sky_irr);
        let visible = scene.surfaces[0].sky_visibility(&hit);
        for c in 0..3 {
            let expected = s[c] + albedo / std::f64::consts::PI * visible * sky_irr[c] * t[c];
            assert!(
                (l[c] - expected).abs() <= 1e-9 * expected.abs().max(1e-12),
                "azimuth {azimuth} channel {c}: {} vs {expected}",
                l[c]
            );
            // And the direct light would have been large.
            assert!(direct[c] > 10.0 * sky_irr[c] * 0.01);
        }
    }
}

#[test]
fn terrain_config_refuses_bad_values_naming_the_field() {
    let bad = |f: &dyn Fn(&mut TerrainConfig), field: &str| {
        let mut c = TerrainConfig::default();
        f(&mut c);
        let e = match c.build(R, &[680.0, 550.0, 440.0]) {
            Ok(_) => panic!("accepted {field}"),
            Err(e) => e.to_string(),
        };
        assert!(e.contains(field), "{e}");
    };
    bad(&|c| c.extent_m = 0.0, "terrain.extent_m");
    bad(&|c| c.height_scale_m = -10.0, "terrain.height_scale_m");
    bad(&|c| c.resolution = 2, "terrain.resolution");
    bad(
        &|c| c.heightmap = Some("/nonexistent/heights.png".into()),
        "terrain.height_range_m",
    );
    bad(
        &|c| {
            c.heightmap = Some("/nonexistent/heights.png".into());
            c.height_range_m = Some([0.0, 1000.0]);
        },
        "/nonexistent/heights.png",
    );
    // An 8-bit PNG.
    let dir = std::env::temp_dir().join(format!("firmament-terrain-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let png = dir.join("grey8.png");
    image::GrayImage::new(8, 8).save(&png).unwrap();
    bad(
        &|c| {
            c.heightmap = Some(png.clone());
            c.height_range_m = Some([0.0, 1000.0]);
        },
        "16-bit greyscale",
    );
    // A 16-bit one is read: black at the bottom of the range, white at the top.
    let png16 = dir.join("grey16.png");
    let mut img = image::ImageBuffer::<image::Luma<u16>, Vec<u16>>::new(4, 3);
    img.put_pixel(3, 0, image::Luma([65535]));
    img.save(&png16).unwrap();
    let mut c = TerrainConfig {
        heightmap: Some(png16),
        height_range_m: Some([100.0, 1100.0]),
        extent_m: 300.0,
        ..TerrainConfig::default()
    };
    c.occlusion = false;
    let hf = c.build(R, &[550.0]).unwrap();
    // The top-right pixel is the north-east corner.
    assert!((hf.height_at(150.0, 100.0) - 1100.0).abs() < 1e-3);
    assert!((hf.height_at(-150.0, -100.0) - 100.0).abs() < 1e-3);
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn the_valley_scene_file_reads_with_its_terrain() {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/valley-noon.toml");
    let scene = firmament::scene::SceneFile::from_file(&path).unwrap();
    let terrain = scene.terrain.expect("[terrain]");
    assert_eq!(terrain, TerrainConfig::default());
}

/// Single scattering through the valley at golden hour, against the reference path tracer
/// with one scattering event: the terrain's shadows in the air (the light shafts, from the
/// shadow-height field) and on black ground (exact shadow rays) as ground truth has them.
/// Black terrain and ground, so the views are the air's single scattering alone.
#[test]
fn single_scattering_through_the_shafts_matches_the_reference() {
    use firmament::reference::{self, ReferenceSettings};
    let mut atmosphere = Atmosphere::earth();
    atmosphere.ground_albedo = firmament::atmosphere::Albedo::Grey(0.0);
    let model = atmosphere.resolve(&Wavelengths::rgb()).unwrap();
    // Default sizes: the small tables' own error near the horizon is 3–4 %.
    let config = TableConfig {
        orders: 1,
        order_tail: false,
        ..Default::default()
    };
    let sky = Bruneton4d::compute(model.clone(), &config).unwrap();
    let terrain = TerrainConfig {
        resolution: 257,
        albedo: Some(0.0),
        occlusion: false,
        // One order in the tables: no multiple scattering for the terrain to change.
        air_light: false,
        ..TerrainConfig::default()
    }
    .build(model.bottom_radius_m, model.wavelengths.nm())
    .unwrap();
    let surfaces: Vec<Box<dyn Surface + '_>> = vec![Box::new(&terrain)];
    let settings = ReferenceSettings {
        samples: 3000,
        include_ground: true,
        max_bounces: 1,
        ..Default::default()
    };
    let observer = Vec3::new(
        0.0,
        0.0,
        model.bottom_radius_m + terrain.height_at(0.0, 0.0) + 25.0,
    );
    let mut scratch = ShadeScratch::default();
    let mut shadowed_views = 0;
    // Golden hour: towards the sun over the ridges, along the shafts, across the valley;
    // noon: the slopes and the far mountains.
    let cases = [
        (
            (84.5, 237.0),
            [
                (86.0, 245.0),
                (88.5, 260.0),
                (90.2, 225.0),
                (92.0, 245.0),
                (82.0, 290.0),
                (90.2, 60.0),
            ],
        ),
        (
            (28.0, 175.0),
            [
                (84.0, 0.0),
                (88.5, 200.0),
                (90.2, 60.0),
                (92.0, 200.0),
                (96.0, 60.0),
                (70.0, 60.0),
            ],
        ),
    ];
    for (k, ((sz, sa), views)) in cases.into_iter().enumerate() {
        let sun = sun_direction(sz, sa);
        let mut scene = Scene::clear_sky(&sky, sun, false);
        scene.surfaces.insert(0, Box::new(&terrain));
        let shader = Shader::new(&scene, observer).unwrap();
        for (i, (z, a)) in views.into_iter().enumerate() {
            let dir = direction_from_zenith_azimuth(f64::to_radians(z), f64::to_radians(a));
            let ray = Ray {
                origin: observer,
                dir,
            };
            let mut l = [0.0; 3];
            shader.shade(&ray, &mut scratch, &mut l);
            let mut shadowed = Vec::new();
            scene.shadowed_intervals(&ray, sun, 20_000.0, &mut shadowed);
            shadowed_views += usize::from(!shadowed.is_empty());
            let key = (10 * k + i) as u64;
            let e = reference::scene_radiance(
                &model,
                &[],
                &surfaces,
                observer,
                dir,
                sun,
                &settings,
                key,
            );
            let nm = model.wavelengths.nm();
            let (lum, (ref_lum, ref_se)) = (
                firmament::spectrum::luminance_from_spectrum(nm, &l),
                e.luminance(nm),
            );
            let error = lum / ref_lum - 1.0;
            eprintln!(
                "single scattering, sun {sz},{sa}, view {z},{a}: {:+.2}% (reference noise {:.2}%)",
                100.0 * error,
                100.0 * ref_se / ref_lum
            );
            assert!(
                error.abs() < 0.03 + 3.0 * ref_se / ref_lum,
                "sun {sz},{sa} view {z},{a}: tables {lum} reference {ref_lum} ± {ref_se}"
            );
        }
    }
    assert!(
        shadowed_views >= 3,
        "only {shadowed_views} views cross a shadow"
    );
}

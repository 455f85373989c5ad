//! The planet's surface map on the GPU (`firmament_gpu::GpuPlanet`, render/planet.wgsl)
//! against the CPU's `PlanetSurface` as the scene's ground, frame by frame in luminance (the
//! parity tests' comparison, common/mod.rs): an all-sea planet and an image map, whose
//! texture holds the CPU's values exactly, to the parity tests' limits (mean ≤ 1 %, every
//! pixel ≤ 5 %), the glint included; the procedural Earth, whose coasts the texture blends
//! within a texel, in the mean (and the share of pixels over 5 % reported).

mod common;

use firmament::math::Vec3;
use firmament::render::{render, Frame, RenderSettings};
use firmament::scene::camera::orbit_fit_fov_deg;
use firmament::scene::planet::{PlanetSurface, SurfaceMap};
use firmament::scene::{sun_direction, Projection, Scene};
use firmament_gpu::{GpuPlanet, GpuSky, RenderInputs};

use common::*;

/// The CPU's and the GPU's frames of the orbit view over `planet`, sun at `sun`.
fn frames(name: &str, planet: &PlanetSurface, sun: Vec3, size: usize) -> Option<(Frame, Frame)> {
    let gpu = gpu(name)?;
    let _guard = serial();
    let sky = earth_rgb();
    let fov = orbit_fit_fov_deg(6_424_000.0, 36_360_000.0);
    let cam = camera(Projection::Orbit, 30_000_000.0, 0.0, 0.0, fov);
    let settings = RenderSettings {
        camera: &cam,
        width: size,
        height: size,
        white_balance: false,
    };
    let mut scene = Scene::clear_sky(sky, sun, true);
    scene.set_ground(planet);
    let cpu = render(&scene, &settings, &|_| {}, None).unwrap();
    let gpu_sky = GpuSky::from_sky(&gpu.ctx, sky).unwrap();
    let map = GpuPlanet::new(&gpu.ctx, planet).unwrap();
    let inputs = RenderInputs {
        planet: Some(&map),
        ..RenderInputs::default()
    };
    let frame = gpu
        .renderer
        .render_with(&gpu.ctx, &gpu_sky, &scene.lights, &settings, inputs)
        .unwrap();
    Some((cpu, frame))
}

fn planet(map: SurfaceMap, wind: Option<f64>) -> PlanetSurface {
    let sky = earth_rgb();
    PlanetSurface::new(
        sky.model.bottom_radius_m,
        map,
        20.0,
        30.0,
        sky.model.wavelengths.nm(),
        wind,
    )
}

fn compare(name: &str, cpu: &Frame, gpu: &Frame, sun: Vec3, size: usize) -> Parity {
    let sky = earth_rgb();
    let fov = orbit_fit_fov_deg(6_424_000.0, 36_360_000.0);
    let cam = camera(Projection::Orbit, 30_000_000.0, 0.0, 0.0, fov);
    let settings = RenderSettings {
        camera: &cam,
        width: size,
        height: size,
        white_balance: false,
    };
    let scene = Scene::clear_sky(sky, sun, true);
    measure(name, sky, &settings, &scene.lights, cpu, gpu, 0.0)
}

#[test]
fn an_all_sea_planet_and_its_glint_match_the_cpu() {
    let sun = sun_direction(40.0, 90.0);
    let sea = SurfaceMap::Procedural {
        seed: 1,
        ocean_fraction: 1.0,
    };
    let glinting = planet(sea.clone(), Some(7.0));
    let Some((cpu, gpu)) = frames("all sea", &glinting, sun, 96) else {
        return;
    };
    assert_parity("all sea", &compare("all sea", &cpu, &gpu, sun, 96));
    // The glint is there: the sea's light at the specular point is several times its matt
    // light (Fresnel ≈ 0.02 over facets of slope variance 0.039 against an albedo of 0.06).
    let (calm, _) = frames("all sea, no glint", &planet(sea, None), sun, 96).unwrap();
    let ratio = (gpu.image.data.iter().zip(&calm.image.data))
        .map(|(a, b)| luminance(a) / luminance(b).max(1e-9))
        .fold(0.0, f64::max);
    eprintln!("the glint: the largest ratio of a pixel with it to the pixel without: {ratio:.2}");
    assert!(ratio > 1.5, "{ratio}");
}

#[test]
fn an_image_map_matches_the_cpu() {
    // 48 × 24 pixels of colours from a hash: the texture is the image itself.
    let (w, h) = (48, 24);
    let rgb: Vec<[f32; 3]> = (0..w * h)
        .map(|i| {
            let x = (i as u32).wrapping_mul(2_654_435_761);
            [
                0.05 + 0.6 * (x & 0xff) as f32 / 255.0,
                0.05 + 0.6 * ((x >> 8) & 0xff) as f32 / 255.0,
                0.05 + 0.6 * ((x >> 16) & 0xff) as f32 / 255.0,
            ]
        })
        .collect();
    let map = SurfaceMap::Image {
        width: w,
        height: h,
        rgb,
    };
    let sun = sun_direction(60.0, 200.0);
    if let Some((cpu, gpu)) = frames("image map", &planet(map, None), sun, 96) {
        assert_parity("image map", &compare("image map", &cpu, &gpu, sun, 96));
    }
}

#[test]
fn the_procedural_earth_matches_the_cpu_in_the_mean() {
    let map = SurfaceMap::Procedural {
        seed: 0,
        ocean_fraction: 0.71,
    };
    let sun = sun_direction(50.0, 120.0);
    let size = 128;
    let Some((cpu, gpu)) = frames("procedural earth", &planet(map, Some(5.0)), sun, size) else {
        return;
    };
    let p = compare("procedural earth", &cpu, &gpu, sun, size);
    let over: usize = (0..size * size)
        .filter(|&i| {
            let c = luminance(&cpu.image.data[i]);
            c > 0.0 && (luminance(&gpu.image.data[i]) - c).abs() / c > 0.05
        })
        .count();
    let lit = (0..size * size)
        .filter(|&i| luminance(&cpu.image.data[i]) > 0.0)
        .count();
    eprintln!(
        "procedural earth: {over} of {lit} lit pixels over 5 % ({:.1} %)",
        100.0 * over as f64 / lit as f64
    );
    assert!(p.mean <= MEAN_TOLERANCE, "mean {:.3e}", p.mean);
    assert!(over * 10 < lit, "{over} of {lit} pixels over 5 %");
}

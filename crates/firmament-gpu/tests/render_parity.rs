//! CPU–GPU parity of whole frames: the same scenes rendered by
//! `firmament::render::render` and `firmament_gpu::GpuRenderer`, compared pixel by pixel in
//! luminance (Y of the linear sRGB, cd/m²). Criteria: mean relative difference ≤ 1 %, no
//! pixel above 5 %, over the pixels inside the projection, leaving out
//! - pixels within 2 pixel footprints of the sun disk's edge (a pixel centre on either side
//!   of the edge flips between disk and sky with rounding), and
//! - pixels whose CPU luminance is below 1e-6 of the largest CPU luminance over the pixels
//!   left (black space beside a planet, the night side).
//!
//! Tables are the CPU's (`Tables::compute`, small sizes), shared by both renderers.

mod common;

use firmament::atmosphere::Atmosphere;
use firmament::math::Vec3;
use firmament::render::{render, RenderSettings};
use firmament::scene::camera::orbit_fit_fov_deg;
use firmament::scene::{sun_direction, Camera, Light, Projection, Scene};
use firmament::sky::bruneton4d::{Bruneton4d, MieStorage, TableConfig, TableSizes};
use firmament::spectrum::Wavelengths;
use firmament_gpu::{GpuError, GpuRenderer, GpuSky};

use common::*;

/// Render `settings` on both sides and compare as the file header says.
fn compare(
    name: &str,
    sky: &Bruneton4d,
    settings: &RenderSettings,
    sun: Vec3,
    sun_disk: bool,
) -> Option<Parity> {
    let gpu = gpu(name)?;
    let _guard = serial();
    let scene = Scene::clear_sky(sky, sun, sun_disk);
    let cpu_frame = render(&scene, settings, &|_| {}, None).unwrap();
    let gpu_sky = GpuSky::from_sky(&gpu.ctx, sky).unwrap();
    let start = std::time::Instant::now();
    let gpu_frame = gpu
        .renderer
        .render(&gpu.ctx, &gpu_sky, &scene.lights, settings)
        .unwrap();
    let gpu_seconds = start.elapsed().as_secs_f64();
    Some(measure(
        name,
        sky,
        settings,
        &scene.lights,
        &cpu_frame,
        &gpu_frame,
        gpu_seconds,
    ))
}

fn check(name: &str, sky: &Bruneton4d, settings: &RenderSettings, sun: Vec3, sun_disk: bool) {
    if let Some(p) = compare(name, sky, settings, sun, sun_disk) {
        assert_parity(name, &p);
    }
}

#[test]
fn ground_level_perspective_at_noon_with_ground_and_sun() {
    // 2 m above the ground looking south-east, 20° up with a 90° field: ground, horizon and
    // the sun 55° high in the frame.
    let cam = camera(Projection::Perspective, 2.0, 135.0, 20.0, 90.0);
    let settings = RenderSettings {
        camera: &cam,
        width: 160,
        height: 120,
        white_balance: false,
    };
    check(
        "noon perspective",
        earth_rgb(),
        &settings,
        sun_direction(35.0, 135.0),
        true,
    );
}

#[test]
fn telephoto_on_the_low_sun_shows_the_limb_darkened_disk() {
    // A 2° field centred on the sun 3° above the horizon: the disk is ~17 pixels across,
    // with the ground below it.
    let cam = camera(Projection::Perspective, 2.0, 250.0, 2.5, 2.0);
    let settings = RenderSettings {
        camera: &cam,
        width: 64,
        height: 64,
        white_balance: true,
    };
    check(
        "sun disk telephoto",
        earth_rgb(),
        &settings,
        sun_direction(87.0, 250.0),
        true,
    );
}

#[test]
fn sunset_fisheye() {
    let cam = camera(Projection::Fisheye, 2.0, 0.0, 0.0, 60.0);
    let settings = RenderSettings {
        camera: &cam,
        width: 128,
        height: 128,
        white_balance: false,
    };
    check(
        "sunset fisheye",
        earth_rgb(),
        &settings,
        sun_direction(88.0, 270.0),
        true,
    );
}

#[test]
fn twilight_from_the_ground_itself() {
    // Altitude 0 (rays below the horizon see no ground point, as on the CPU) with the sun
    // 6° below the horizon: Earth's shadow and the faded single Mie.
    let cam = camera(Projection::Fisheye, 0.0, 0.0, 0.0, 60.0);
    let settings = RenderSettings {
        camera: &cam,
        width: 96,
        height: 96,
        white_balance: false,
    };
    check(
        "twilight fisheye at altitude 0",
        earth_rgb(),
        &settings,
        sun_direction(96.0, 80.0),
        true,
    );
}

#[test]
fn twilight_between_the_tables_sun_samples() {
    // The sun 5.5° and 6.5° below the horizon, between the μ_s samples at −7.2°, −6.0° and
    // −5.0°, where the tables blend along μ_s by the twilight rule (mu_s_blend.rs and its
    // twin mu_s_blend.wgsl; a linear blend reads +22 % there): from 10 km towards the
    // horizon, and from 1 km looking down at the ground, which the irradiance table's
    // twilight blend lights.
    for (name, altitude_m, pitch_deg, sun_zenith_deg) in [
        ("twilight at 10 km, sun -5.5", 10_000.0, 10.0, 95.5),
        (
            "twilight at 1 km looking down, sun -6.5",
            1_000.0,
            -30.0,
            96.5,
        ),
    ] {
        let cam = camera(Projection::Perspective, altitude_m, 80.0, pitch_deg, 90.0);
        let settings = RenderSettings {
            camera: &cam,
            width: 64,
            height: 64,
            white_balance: false,
        };
        check(
            name,
            earth_rgb(),
            &settings,
            sun_direction(sun_zenith_deg, 80.0),
            true,
        );
    }
}

#[test]
fn deep_twilight_below_the_tables_lowest_sun() {
    // The sun 21° below the horizon, under the tables' lowest (−12°), 2 m above the
    // ground: the sky and the ground's sky light fall on from the lowest tabulated sun
    // (sky/bruneton4d/twilight.rs and its twin twilight.wgsl), not cut to 0.
    let cam = camera(Projection::Fisheye, 2.0, 0.0, 0.0, 60.0);
    let settings = RenderSettings {
        camera: &cam,
        width: 96,
        height: 96,
        white_balance: false,
    };
    let sky = earth_rgb();
    assert!(sky.model.mu_s_min > (111.0f64).to_radians().cos());
    check(
        "deep twilight fisheye",
        sky,
        &settings,
        sun_direction(111.0, 80.0),
        false,
    );
}

#[test]
fn orbit_view_from_space() {
    // The whole planet from 30 000 km, sun 75° from the zenith of the point below: limb,
    // terminator, night side, black space.
    let fov = orbit_fit_fov_deg(6_424_000.0, 36_360_000.0);
    let cam = camera(Projection::Orbit, 30_000_000.0, 0.0, 0.0, fov);
    let settings = RenderSettings {
        camera: &cam,
        width: 128,
        height: 128,
        white_balance: false,
    };
    check(
        "orbit",
        earth_rgb(),
        &settings,
        sun_direction(75.0, 90.0),
        true,
    );
}

#[test]
fn low_orbit_perspective_at_the_limb() {
    // 400 km up looking at the horizon: the limb seen through the atmosphere from space.
    let cam = camera(Projection::Perspective, 400_000.0, 90.0, -20.0, 40.0);
    let settings = RenderSettings {
        camera: &cam,
        width: 96,
        height: 64,
        white_balance: false,
    };
    check(
        "low orbit limb",
        earth_rgb(),
        &settings,
        sun_direction(80.0, 60.0),
        true,
    );
}

#[test]
fn spectral_equirect() {
    let sky = sky("earth", Wavelengths::spectral(), 4, MieStorage::Separate);
    // Turned: the centre column faces 75° (--heading-deg).
    let cam = camera(Projection::Equirect, 100.0, 75.0, 0.0, 60.0);
    let settings = RenderSettings {
        camera: &cam,
        width: 128,
        height: 64,
        white_balance: true,
    };
    check(
        "spectral equirect",
        &sky,
        &settings,
        sun_direction(60.0, 120.0),
        true,
    );
}

#[test]
fn red_only_mie_cubemap_with_five_wavelengths() {
    // Two channel groups (three padding lanes), Cornette–Shanks, the ratio rule for Mie,
    // and a camera 10 km up.
    let sky = sky(
        "bruneton2008",
        Wavelengths::from_list(&[680.0, 550.0, 440.0, 400.0, 600.0]).unwrap(),
        2,
        MieStorage::RedOnly,
    );
    let cam = camera(Projection::Cubemap, 10_000.0, 0.0, 0.0, 60.0);
    let settings = RenderSettings {
        camera: &cam,
        width: 6 * 24,
        height: 24,
        white_balance: false,
    };
    check(
        "red-only cubemap",
        &sky,
        &settings,
        sun_direction(70.0, 30.0),
        false,
    );
}

#[test]
fn bands_of_rows_give_the_same_frame() {
    // A frame drawn in bands of 16 rows (as frames larger than one storage binding are)
    // equals the frame drawn at once.
    let Some(gpu) = gpu("bands_of_rows_give_the_same_frame") else {
        return;
    };
    let _guard = serial();
    let sky = earth_rgb();
    let cam = camera(Projection::Fisheye, 2.0, 0.0, 0.0, 60.0);
    let settings = RenderSettings {
        camera: &cam,
        width: 40,
        height: 40,
        white_balance: false,
    };
    let gpu_sky = GpuSky::from_sky(&gpu.ctx, sky).unwrap();
    let whole = gpu
        .renderer
        .render(
            &gpu.ctx,
            &gpu_sky,
            &[Light::sun(&sky.model, sun_direction(50.0, 10.0), true)],
            &settings,
        )
        .unwrap();
    let banded = GpuRenderer::new(&gpu.ctx)
        .unwrap()
        .with_max_band_bytes(40 * 16 * 16);
    let bands = banded
        .render(
            &gpu.ctx,
            &gpu_sky,
            &[Light::sun(&sky.model, sun_direction(50.0, 10.0), true)],
            &settings,
        )
        .unwrap();
    assert_eq!(whole.mask, bands.mask);
    assert_eq!(whole.image.data, bands.image.data);
}

#[test]
fn oversized_frames_and_invalid_cameras_are_refused() {
    let Some(gpu) = gpu("oversized_frames_and_invalid_cameras_are_refused") else {
        return;
    };
    let _guard = serial();
    let sky = earth_rgb();
    let gpu_sky = GpuSky::from_sky(&gpu.ctx, sky).unwrap();
    let good = camera(Projection::Perspective, 2.0, 0.0, 0.0, 60.0);
    // Ok(whether every pixel is inside the projection).
    let settings = |camera: &Camera, width, height| -> Result<bool, GpuError> {
        let s = RenderSettings {
            camera,
            width,
            height,
            white_balance: false,
        };
        gpu.renderer
            .render(
                &gpu.ctx,
                &gpu_sky,
                &[Light::sun(&sky.model, sun_direction(30.0, 0.0), true)],
                &s,
            )
            .map(|f| f.mask.iter().all(|&m| m))
    };
    // The largest frame the CPU accepts: 32768² pixels, 16 GiB of output.
    let limits = gpu.ctx.limits();
    if 32768u64 * 32768 * 16 > limits.max_buffer_size {
        let e = settings(&good, 32768, 32768).unwrap_err();
        eprintln!("{e}");
        assert!(
            matches!(e, GpuError::Limit { .. }) && e.to_string().contains("max_buffer_size"),
            "{e}"
        );
    } else {
        eprintln!("skipping the oversized frame: this device allocates 16 GiB buffers");
    }
    // Bands cannot be narrower than 16 rows: a cap below 16 rows of this width is refused.
    let capped = GpuRenderer::new(&gpu.ctx)
        .unwrap()
        .with_max_band_bytes(1024);
    let s = RenderSettings {
        camera: &good,
        width: 64,
        height: 32,
        white_balance: false,
    };
    let e = capped
        .render(
            &gpu.ctx,
            &gpu_sky,
            &[Light::sun(&sky.model, sun_direction(30.0, 0.0), true)],
            &s,
        )
        .map(|_| ())
        .unwrap_err();
    eprintln!("{e}");
    assert!(
        matches!(e, GpuError::Limit { .. }) && e.to_string().contains("with_max_band_bytes"),
        "{e}"
    );
    // What the CPU refuses.
    let e = settings(&good, 0, 10).unwrap_err();
    assert!(matches!(e, GpuError::Invalid(_)) && e.to_string().contains("width/height"));
    let e = settings(&good, 40000, 10).unwrap_err();
    assert!(e.to_string().contains("width/height"), "{e}");
    let bad_fov = Camera {
        fov_deg: 0.0,
        ..good.clone()
    };
    let e = settings(&bad_fov, 16, 16).unwrap_err();
    assert!(e.to_string().contains("fov_deg"), "{e}");
    let bad_altitude = Camera {
        altitude_m: f64::NAN,
        ..good.clone()
    };
    let e = settings(&bad_altitude, 16, 16).unwrap_err();
    assert!(e.to_string().contains("altitude_m"), "{e}");
    let cube = Camera {
        projection: Projection::Cubemap,
        ..good.clone()
    };
    let e = settings(&cube, 64, 16).unwrap_err();
    assert!(e.to_string().contains("cube map"), "{e}");
    // The renderer still works afterwards.
    assert!(settings(&good, 8, 8).unwrap());
}

#[test]
fn timing_reports_its_method() {
    let Some(gpu) = gpu("timing_reports_its_method") else {
        return;
    };
    let _guard = serial();
    let gpu_sky = GpuSky::from_sky(&gpu.ctx, earth_rgb()).unwrap();
    let cam = camera(Projection::Fisheye, 2.0, 0.0, 0.0, 60.0);
    let settings = RenderSettings {
        camera: &cam,
        width: 64,
        height: 64,
        white_balance: false,
    };
    let t = gpu
        .renderer
        .time_render(
            &gpu.ctx,
            &gpu_sky,
            &[Light::sun(
                &earth_rgb().model,
                sun_direction(50.0, 10.0),
                true,
            )],
            &settings,
            3,
        )
        .unwrap();
    eprintln!("64×64 fisheye: {:.3} ms ({})", t.seconds * 1e3, t.method);
    assert!(t.seconds > 0.0 && t.seconds.is_finite());
    assert_eq!(t.frames, 3);
}

#[test]
fn tables_kept_on_the_device_render_like_tables_read_back() {
    // GpuSky::precompute (no readback; red-only Mie stays in the full layout on the device)
    // against the same GPU tables read back into a Sky and uploaded again: the same frame.
    let Some(gpu) = gpu("tables_kept_on_the_device_render_like_tables_read_back") else {
        return;
    };
    let _guard = serial();
    let model = Atmosphere::preset("bruneton2008")
        .unwrap()
        .resolve(&Wavelengths::from_list(&[680.0, 550.0, 440.0, 400.0, 600.0]).unwrap())
        .unwrap();
    let config = TableConfig {
        sizes: TableSizes {
            scattering_r: 8,
            scattering_mu: 32,
            scattering_mu_s: 8,
            scattering_nu: 4,
            ..TableSizes::small()
        },
        orders: 2,
        mie: MieStorage::RedOnly,
        order_tail: true,
    };
    let precomputer = firmament_gpu::Precomputer::new(&gpu.ctx).unwrap();
    let on_device = GpuSky::precompute(&gpu.ctx, &precomputer, &model, &config).unwrap();
    let tables = precomputer.run(&gpu.ctx, &model, &config).unwrap();
    let read_back =
        GpuSky::from_sky(&gpu.ctx, &Bruneton4d::new(model.clone(), tables).unwrap()).unwrap();
    let cam = camera(Projection::Perspective, 300.0, 0.0, 5.0, 90.0);
    let settings = RenderSettings {
        camera: &cam,
        width: 48,
        height: 32,
        white_balance: true,
    };
    let lights = [Light::sun(&model, sun_direction(80.0, 10.0), true)];
    let a = gpu
        .renderer
        .render(&gpu.ctx, &on_device, &lights, &settings)
        .unwrap();
    let b = gpu
        .renderer
        .render(&gpu.ctx, &read_back, &lights, &settings)
        .unwrap();
    assert_eq!(a.mask, b.mask);
    assert_eq!(a.image.data, b.image.data);
    assert!(a.image.data.iter().any(|p| luminance(p) > 0.0));
}

/// The sun and the moon at `time` from 46.5° N, 8° E.
fn alps_at(time: &str) -> firmament::astro::Sky {
    let instant = firmament::astro::Instant::parse(time, "time").unwrap();
    let place = firmament::astro::Place::new(46.5, 8.0, 0.0).unwrap();
    firmament::astro::Sky::at(instant, place, &Default::default()).unwrap()
}

#[test]
fn telephoto_on_the_half_moon_shows_its_phase_and_earthshine() {
    // 2026-01-26 18:00 UTC from 46.5° N, 8° E: a 56 % moon 63° high, the sun 17° below the
    // horizon; a 1.2° field on the moon: the lit half, the terminator, earthshine, the
    // moonlit sky (the lights only: the stars and the night glow are CPU-side).
    let name = "half moon";
    let Some(gpu) = gpu(name) else { return };
    let _guard = serial();
    let sky = earth_rgb();
    let astro = alps_at("2026-01-26T18:00:00Z");
    let m = &astro.moon;
    let cam = camera(
        Projection::Perspective,
        2.0,
        m.azimuth_deg,
        90.0 - m.apparent_zenith_deg,
        1.2,
    );
    let settings = RenderSettings {
        camera: &cam,
        width: 96,
        height: 96,
        white_balance: false,
    };
    let mut scene = Scene::clear_sky(sky, Vec3::Z, false);
    scene.lights = firmament::scene::sky_lights::lights_of(&sky.model, &astro, true, true);
    assert_eq!(scene.lights.len(), 2);
    let cpu_frame = render(&scene, &settings, &|_| {}, None).unwrap();
    let gpu_sky = GpuSky::from_sky(&gpu.ctx, sky).unwrap();
    let gpu_frame = gpu
        .renderer
        .render(&gpu.ctx, &gpu_sky, &scene.lights, &settings)
        .unwrap();
    let p = measure(
        name,
        sky,
        &settings,
        &scene.lights,
        &cpu_frame,
        &gpu_frame,
        0.0,
    );
    assert_parity(name, &p);
    // The lit limb is far brighter than the dark half's earthshine, on both sides.
    let lum = |f: &firmament::render::Frame, x: usize, y: usize| {
        let q = f.image.data[y * 96 + x];
        0.2126 * q[0] + 0.7152 * q[1] + 0.0722 * q[2]
    };
    let (bright, dark) = (
        (0..96)
            .map(|x| lum(&gpu_frame, x, 48))
            .fold(0.0f32, f32::max),
        (0..96)
            .map(|x| lum(&gpu_frame, x, 48))
            .fold(f32::MAX, f32::min),
    );
    assert!(bright > 100.0 * dark, "{bright} vs {dark}");
}

#[test]
fn moonlit_night_fisheye_with_the_glow() {
    // 2026-01-03 20:00 UTC from 46.5° N, 8° E: the full moon 38° high, the sun 41° below
    // the horizon, the night sky's glow (van Rhijn airglow) through the air.
    let name = "moonlit night";
    let Some(gpu) = gpu(name) else { return };
    let _guard = serial();
    let sky = earth_rgb();
    let astro = alps_at("2026-01-03T20:00:00Z");
    let cam = camera(Projection::Fisheye, 2.0, 0.0, 0.0, 60.0);
    let settings = RenderSettings {
        camera: &cam,
        width: 96,
        height: 96,
        white_balance: false,
    };
    let sources = firmament::scene::sky_lights::sources_of(&sky.model, &astro, true, true);
    let mut scene = Scene::clear_sky(sky, Vec3::Z, false);
    scene.lights = sources.lights;
    scene.background = sources.background;
    assert!(scene.background.is_some());
    let cpu_frame = render(&scene, &settings, &|_| {}, None).unwrap();
    let gpu_sky = GpuSky::from_sky(&gpu.ctx, sky).unwrap();
    let inputs = firmament_gpu::RenderInputs {
        background: scene.background.as_ref(),
        ..Default::default()
    };
    let gpu_frame = gpu
        .renderer
        .render_with(&gpu.ctx, &gpu_sky, &scene.lights, &settings, inputs)
        .unwrap();
    let p = measure(
        name,
        sky,
        &settings,
        &scene.lights,
        &cpu_frame,
        &gpu_frame,
        0.0,
    );
    assert_parity(name, &p);
}

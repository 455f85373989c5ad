//! The sky on the CPU, step by step: an atmosphere, its precomputed tables, the radiance,
//! luminance and colour of a few directions, the sun's light and the sky's on the ground,
//! and a small equirectangular map written as a PNG (tone-mapped) and an EXR (physical).
//!
//! ```text
//! cargo run --release -p firmament --example sky_query -- [OUT_DIR] [--tables FILE]
//! ```
//!
//! Without `--tables` it precomputes small tables (a second or two in release); with
//! `--tables` it reads a file written by `firmament bake --out FILE` (the `earth` preset
//! and `rgb` wavelengths, the ones this example resolves), which is faster and finer.
//! Units throughout: radiance W·m⁻²·sr⁻¹·nm⁻¹, irradiance W·m⁻²·nm⁻¹ (per channel of the
//! wavelength grid), luminance cd/m², illuminance lux, positions planet-centred metres.

use std::path::PathBuf;

use firmament::atmosphere::Atmosphere;
use firmament::io::{write_exr, write_png_srgb8, ExrPrecision};
use firmament::math::{direction_from_zenith_azimuth, Vec3};
use firmament::render::{self, tonemap, RenderSettings, ToneCurve};
use firmament::scene::{sun_direction, Camera, Light, Projection, Scene};
use firmament::sky::bruneton4d::{file, Bruneton4d, TableConfig, TableSizes};
use firmament::sky::{Shadow, SkyMethod};
use firmament::spectrum::gamut::Gamut;
use firmament::spectrum::Wavelengths;
use firmament::spectrum::{luminance_from_spectrum, spectrum_to_xyz, xyz_to_linear_srgb};

fn main() -> firmament::Result<()> {
    let mut out_dir = std::env::temp_dir();
    let mut tables_file = None;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--tables" => tables_file = Some(PathBuf::from(args.next().expect("--tables FILE"))),
            _ => out_dir = PathBuf::from(a),
        }
    }

    // 1. The atmosphere: a preset (or `Atmosphere::from_file` for a TOML file), resolved for
    //    a wavelength grid into a `Model` of per-channel coefficients. `rgb` is three
    //    wavelengths (680, 550, 440 nm) and fast; `Wavelengths::spectral()` (16
    //    samples, more work) gives the right colours at sunset.
    let model = Atmosphere::preset("earth")?.resolve(&Wavelengths::rgb())?;
    let nm = model.wavelengths.nm().to_vec();

    // 2. The sky method: Bruneton's 4D tables, read from a file or precomputed here.
    //    `TableConfig::default()` is Bruneton 2017's sizes with 4 orders (10–20 s on two
    //    cores); small tables with 3 orders (plus the geometric tail of the higher
    //    orders) are enough for a look.
    let sky = match tables_file {
        Some(path) => {
            let tables = file::read(&path)?;
            // Refuses tables baked for another atmosphere or wavelength grid.
            Bruneton4d::new(model, tables)?
        }
        None => {
            let t0 = std::time::Instant::now();
            let config = TableConfig {
                sizes: TableSizes::small(),
                orders: 3,
                ..TableConfig::default()
            };
            let sky = Bruneton4d::compute(model, &config)?;
            println!("tables precomputed in {:.2} s", t0.elapsed().as_secs_f64());
            sky
        }
    };

    // 3. One observer and one light. The world is planet-centred: the observer stands above
    //    the +z pole, where x is east, y north and z up, and azimuths run clockwise from
    //    north. The sun 30° from the zenith in the south.
    let altitude_m = 1.5;
    let observer = Vec3::new(0.0, 0.0, sky.model.bottom_radius_m + altitude_m);
    let (sun_zenith_deg, sun_azimuth_deg) = (30.0, 180.0);
    let sun = Light::sun(
        &sky.model,
        sun_direction(sun_zenith_deg, sun_azimuth_deg),
        true,
    );
    // A view caches what every question from this observer under this light shares.
    let view = sky.view(observer, &sun);

    // 4. Sky radiance along a few rays: spectral radiance per channel, its luminance and
    //    CIE xy chromaticity (the three channels read as a coarse spectrum), and linear sRGB
    //    scaled so that its Y is the luminance. The sun's disk is not part of it.
    println!("sun at zenith {sun_zenith_deg}°, azimuth {sun_azimuth_deg}°; wavelengths {nm:?} nm");
    println!("zenith° azimuth°  radiance W·m⁻²·sr⁻¹·nm⁻¹        cd/m²     x      y    linear sRGB");
    let n = sky.channels();
    let (mut radiance, mut transmittance) = (vec![0.0; n], vec![0.0; n]);
    for (zenith_deg, azimuth_deg) in [
        (0.0f64, 0.0f64),
        (45.0, 180.0),
        (45.0, 0.0),
        (60.0, 90.0),
        (85.0, 0.0),
        (89.0, 180.0),
    ] {
        let dir = direction_from_zenith_azimuth(zenith_deg.to_radians(), azimuth_deg.to_radians());
        view.sky_radiance(dir, Shadow::None, &mut radiance, &mut transmittance);
        let xyz = spectrum_to_xyz(&nm, &radiance);
        let sum = xyz[0] + xyz[1] + xyz[2];
        let rgb = xyz_to_linear_srgb(xyz);
        println!(
            "{zenith_deg:7.1} {azimuth_deg:8.1}  {:<30} {:8.0} {:.3} {:.3}  [{:.0}, {:.0}, {:.0}]",
            format!("{:.4?}", radiance),
            xyz[1],
            xyz[0] / sum,
            xyz[1] / sum,
            rgb[0],
            rgb[1],
            rgb[2],
        );
    }

    // 5. The sun's light at the observer: the transmittance of the air towards it, the
    //    direct normal illuminance, and the direct and sky (diffuse) irradiance on a
    //    horizontal surface (normal +z), W·m⁻²·nm⁻¹ per channel and lux.
    let mut sun_transmittance = vec![0.0; n];
    view.transmittance_to_light(observer, &mut sun_transmittance);
    let direct_normal: Vec<f64> = (sun.irradiance.iter().zip(&sun_transmittance))
        .map(|(e, t)| e * t)
        .collect();
    let (mut direct, mut diffuse) = (vec![0.0; n], vec![0.0; n]);
    view.sun_and_sky_irradiance(observer, Vec3::Z, &mut direct, &mut diffuse);
    let lux = |e: &[f64]| luminance_from_spectrum(&nm, e);
    println!("sun transmittance {sun_transmittance:.3?}");
    println!(
        "sun: {:.0} lx outside the air, {:.0} lx direct normal at the ground",
        lux(&sun.irradiance),
        lux(&direct_normal)
    );
    println!(
        "horizontal surface: sun {:.0} lx {direct:.3?} W·m⁻²·nm⁻¹, sky {:.0} lx {diffuse:.3?} W·m⁻²·nm⁻¹",
        lux(&direct),
        lux(&diffuse)
    );

    // 6. An image: a scene (the sky method, the planet's ground, the sun with its disk) seen
    //    by a camera. An equirectangular map: north at the centre column, east at three
    //    quarters of the width, the zenith along the top row.
    let scene = Scene::clear_sky(&sky, sun.direction, true);
    let camera = Camera {
        projection: Projection::Equirect,
        altitude_m,
        heading_deg: 0.0,
        pitch_deg: 0.0,
        roll_deg: 0.0,
        fov_deg: 60.0,
    };
    let settings = RenderSettings {
        camera: &camera,
        width: 256,
        height: 128,
        white_balance: false,
    };
    // `render` runs rows in parallel; the closure hears the fraction done.
    let frame = render::render(&scene, &settings, &|_| {}, None)?;
    // The frame is linear Rec. 709 with Y in cd/m²: an EXR keeps those values...
    std::fs::create_dir_all(&out_dir).map_err(|e| firmament::Error::File {
        path: out_dir.display().to_string(),
        reason: e.to_string(),
    })?;
    let exr = out_dir.join("sky_query.exr");
    write_exr(&exr, &frame.in_gamut(Gamut::Rec709), ExrPrecision::F32)?;
    // ...and a PNG needs an exposure (here a light meter's, from the log-average luminance)
    // and a tone curve.
    let ev100 = tonemap::auto_ev100(frame.log_average_luminance());
    let rgb8 = frame.to_srgb8_dithered(
        tonemap::exposure_from_ev100(ev100, ToneCurve::Aces),
        ToneCurve::Aces,
    );
    let png = out_dir.join("sky_query.png");
    write_png_srgb8(&png, settings.width, settings.height, &rgb8)?;
    println!(
        "wrote {} and {} (EV100 {ev100:.1})",
        png.display(),
        exr.display()
    );
    Ok(())
}

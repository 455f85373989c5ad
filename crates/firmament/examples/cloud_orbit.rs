//! Clouds seen from orbit: the renderer's density filtered over a pixel's footprint
//! (`scene::clouds::lod`) against the same pixel resolved, for a planetary cumulus field
//! (`weather_wrap = "planet"`) seen from a satellite 700 km up, 48 pixels within 30° of the
//! nadir, at two pixel sizes (10 km and 1.5 km at the nadir).
//!
//! - "filtered": the pixel's central ray through the filtered density (what `render` does);
//! - "resolved": the mean of the renderer's march over N×N rays spread over the pixel,
//!   through the noise unfiltered (the same marcher; its own error is measured elsewhere);
//! - "reference": the mean of the path tracer over the same N×N rays (delta tracking through
//!   the unfiltered noise, every order of scattering), so the filter and the marcher are
//!   both measured against ground truth.
//!
//! Pixels are classed by the share of their rays whose optical depth through the layer
//! exceeds 1: clear (< 10 %), broken, overcast (> 90 %). Prints a markdown table for
//! docs/accuracy.md ("Clouds from orbit").
//!
//! `cargo run --release -p firmament --example cloud_orbit [PATHS_PER_RAY] [N] [slab]`
//! (default 64 paths per ray and wavelength, 8×8 rays per pixel; `slab`: a uniform slab of
//! optical thickness 10 instead; the tables from the user's cache).

#[path = "common/cloud_sky.rs"]
mod cloud_sky;

use firmament::math::Vec3;
use firmament::reference::{self, ReferenceSettings};
use firmament::render::{ShadeScratch, Shader};
use firmament::scene::clouds::{cloud_media, CloudKind, CloudLayerConfig};
use firmament::scene::clouds::{ViewFootprint, WeatherWrap};
use firmament::scene::{sun_direction, Ray, Scene, Volume};

const ALTITUDE_M: f64 = 700e3;

/// `n` directions over a cap of `cap_deg` around the nadir (a Fibonacci spiral).
fn directions(n: usize, cap_deg: f64) -> Vec<Vec3> {
    let cos_cap = cap_deg.to_radians().cos();
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..n)
        .map(|i| {
            let z = 1.0 - (1.0 - cos_cap) * (i as f64 + 0.5) / n as f64;
            let s = (1.0 - z * z).max(0.0).sqrt();
            let phi = golden * i as f64;
            Vec3::new(s * phi.cos(), s * phi.sin(), -z)
        })
        .collect()
}

/// N×N directions spread over a square pixel of `angle` (rad) around `d`.
fn pixel_rays(d: Vec3, angle: f64, n: usize) -> Vec<Vec3> {
    let u = d.cross(Vec3::X).normalize();
    let v = d.cross(u);
    let mut out = Vec::with_capacity(n * n);
    for j in 0..n {
        for i in 0..n {
            let (a, b) = (
                ((i as f64 + 0.5) / n as f64 - 0.5) * angle,
                ((j as f64 + 0.5) / n as f64 - 0.5) * angle,
            );
            out.push((d + a * u + b * v).normalize());
        }
    }
    out
}

fn percentile(v: &mut [f64], p: f64) -> f64 {
    v.sort_by(f64::total_cmp);
    v[((v.len() - 1) as f64 * p).round() as usize]
}

fn main() -> firmament::Result<()> {
    let args: Vec<String> = std::env::args().collect();
    let samples: usize = args
        .get(1)
        .map_or(64, |s| s.parse().expect("paths per ray"));
    let n: usize = args.get(2).map_or(8, |s| s.parse().expect("rays per side"));
    let (model, sky, noise) = cloud_sky::earth_rgb_with_noise()?;
    let radius = model.bottom_radius_m;
    let colour = model.colour_matrix();
    let settings = ReferenceSettings {
        samples,
        max_bounces: 4000,
        include_ground: true,
        ..ReferenceSettings::default()
    };
    // A third argument `slab`: a uniform slab of optical thickness 10 instead (the orbit
    // geometry's own check, nothing to filter).
    let layer = match args.get(3).map(|s| s.as_str()) {
        Some("slab") => CloudLayerConfig {
            bottom_m: Some(1000.0),
            top_m: Some(2000.0),
            extinction_per_m: Some(0.01),
            ..CloudLayerConfig::of_kind(CloudKind::Uniform)
        },
        _ => CloudLayerConfig {
            weather_wrap: WeatherWrap::Planet,
            ..CloudLayerConfig::of_kind(CloudKind::Cumulus)
        },
    };
    let media = cloud_media(std::slice::from_ref(&layer), radius, (0.0, 0.0), &noise)?;
    let origin = Vec3::new(0.0, 0.0, radius + ALTITUDE_M);
    let sun = sun_direction(30.0, 180.0);
    let volumes: Vec<Box<dyn Volume + '_>> = vec![Box::new(&media[0])];
    let mut resolved_scene = Scene::clear_sky(&sky, sun, false);
    resolved_scene.volumes.push(Box::new(&media[0]));
    let resolved_shader = Shader::new(&resolved_scene, origin)?;
    let luminance = |l: &[f64]| colour.to_xyz(l)[1];

    println!("| pixel at nadir | class | n | filtered vs resolved: median \\|e\\| | p95 | bias | filtered vs reference: median \\|e\\| | p95 | bias | resolved vs reference: median \\|e\\| | bias | ref. noise |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|");
    for pixel_km in [10.0, 1.5] {
        let angle = pixel_km * 1e3 / ALTITUDE_M;
        let mut filtered_medium =
            cloud_media(std::slice::from_ref(&layer), radius, (0.0, 0.0), &noise)?;
        filtered_medium[0].layer.set_view(
            ViewFootprint {
                eye: origin,
                pixel_angle_rad: angle,
            },
            None,
        );
        let mut filtered_scene = Scene::clear_sky(&sky, sun, false);
        filtered_scene.volumes.push(Box::new(&filtered_medium[0]));
        let filtered_shader = Shader::new(&filtered_scene, origin)?;
        let mut classes: std::collections::BTreeMap<&str, Vec<[f64; 4]>> = Default::default();
        for (p, d) in directions(48, 30.0).into_iter().enumerate() {
            let rays = pixel_rays(d, angle, n);
            let shade = |shader: &Shader, dir: Vec3| {
                let mut l = [0.0; 3];
                shader.shade(&Ray { origin, dir }, &mut ShadeScratch::default(), &mut l);
                luminance(&l)
            };
            let filtered = shade(&filtered_shader, d);
            let resolved = rays
                .iter()
                .map(|&r| shade(&resolved_shader, r))
                .sum::<f64>()
                / rays.len() as f64;
            let cloudy = rays
                .iter()
                .filter(|&&r| {
                    media[0].optical_depth(&Ray { origin, dir: r }, 0.0, f64::INFINITY, 0) > 1.0
                })
                .count() as f64
                / rays.len() as f64;
            // The reference's estimates are kept in the temporary directory.
            let key = format!(
                "orbit {pixel_km} {p} {n} {samples} {:?}",
                media[0].layer.params
            );
            let file = std::env::temp_dir().join(format!(
                "firmament-cloud-orbit-{:016x}.json",
                firmament::atmosphere::model::fnv1a(key.as_bytes())
            ));
            let (want, se): (f64, f64) = match std::fs::read(&file)
                .ok()
                .and_then(|b| serde_json::from_slice(&b).ok())
            {
                Some(t) => t,
                None => {
                    let pairs: Vec<(Vec3, Vec3)> = rays.iter().map(|&r| (origin, r)).collect();
                    let est = reference::render_pixels(
                        &model,
                        &volumes,
                        &[],
                        &pairs,
                        0,
                        sun,
                        &settings,
                        &|| {},
                    );
                    let m = est.len() as f64;
                    let (mut l, mut s2) = (0.0, 0.0);
                    for e in &est {
                        let (y, s) = colour.luminance_and_stderr(&e.radiance, &e.stderr);
                        l += y / m;
                        s2 += (s / m).powi(2);
                    }
                    std::fs::write(&file, serde_json::to_vec(&(l, s2.sqrt())).unwrap()).ok();
                    (l, s2.sqrt())
                }
            };
            let class = if cloudy < 0.1 {
                "clear"
            } else if cloudy > 0.9 {
                "overcast"
            } else {
                "broken"
            };
            if std::env::var_os("CLOUD_ORBIT_VERBOSE").is_some() {
                eprintln!(
                    "{pixel_km} km | pixel {p} | cloudy {cloudy:.2} | filtered {filtered:.4e} resolved {resolved:.4e} reference {want:.4e} ± {:.1} %",
                    100.0 * se / want
                );
            }
            let e = [
                filtered / resolved - 1.0,
                filtered / want - 1.0,
                resolved / want - 1.0,
                se / want,
            ];
            classes.entry(class).or_default().push(e);
            classes.entry("all").or_default().push(e);
        }
        for (class, errs) in classes {
            let column = |k: usize| errs.iter().map(|e| e[k]).collect::<Vec<f64>>();
            let stats = |k: usize| {
                let v = column(k);
                let mut abs: Vec<f64> = v.iter().map(|e| e.abs()).collect();
                let bias = v.iter().sum::<f64>() / v.len() as f64;
                (
                    100.0 * percentile(&mut abs, 0.5),
                    100.0 * percentile(&mut abs, 0.95),
                    100.0 * bias,
                )
            };
            let (a, b, c) = (stats(0), stats(1), stats(2));
            let mut noise = column(3);
            println!(
                "| {pixel_km} km | {class} | {} | {:.1} % | {:.1} % | {:+.1} % | {:.1} % | {:.1} % | {:+.1} % | {:.1} % | {:+.1} % | {:.1} % |",
                errs.len(),
                a.0,
                a.1,
                a.2,
                b.0,
                b.1,
                b.2,
                c.0,
                c.2,
                100.0 * percentile(&mut noise, 0.5)
            );
        }
    }
    Ok(())
}

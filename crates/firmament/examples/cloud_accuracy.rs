//! The clouds' fast path (the renderer's marcher: octaves, the light march, the ambient
//! term, the ground under the clouds) against the reference path tracer (delta tracking
//! through the same volumes, every order of scattering), over ≥ 40 directions per view:
//! uniform slabs of optical thickness 5 and 20 under the sun at zenith angles 30° and 70°,
//! and a field of cumulus; from the ground looking up, from above looking down, and (slab)
//! from under the slab looking at the ground. Each direction is put in a class by what it
//! sees (sky through a gap, a cloud's base, a cloud's top, the ground lit or in a cloud's
//! shadow); printed as a markdown table of the luminance error per class: median |e|, p95
//! |e| and the bias (mean e), for docs/accuracy.md.
//!
//! `cargo run --release -p firmament --example cloud_accuracy [SAMPLES] [slab|cumulus|all]`
//! (default 1024 paths per wavelength, all; the tables come from the user's cache).

#[path = "common/cloud_sky.rs"]
mod cloud_sky;

use firmament::math::Vec3;
use firmament::reference::{self, ReferenceSettings};
use firmament::render::{ShadeScratch, Shader};
use firmament::scene::clouds::{cloud_media, CloudKind, CloudLayerConfig, CloudMedium};
use firmament::scene::{sun_direction, Ray, Scene, Volume};

/// A view: where from, which directions, how to class each.
struct View {
    name: &'static str,
    origin_alt_m: f64,
    /// Directions: a spiral over the cap of `cap_deg` around the zenith (up) or the nadir.
    up: bool,
    cap_deg: f64,
}

/// `n` directions over a cap of half-angle `cap_deg` around +z (up) or −z, evenly spread
/// (a Fibonacci spiral, equal solid angle per direction).
fn directions(n: usize, cap_deg: f64, up: bool) -> Vec<Vec3> {
    let cos_cap = cap_deg.to_radians().cos();
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..n)
        .map(|i| {
            let z = 1.0 - (1.0 - cos_cap) * (i as f64 + 0.5) / n as f64;
            let s = (1.0 - z * z).max(0.0).sqrt();
            let phi = golden * i as f64;
            Vec3::new(s * phi.cos(), s * phi.sin(), if up { z } else { -z })
        })
        .collect()
}

fn percentile(v: &mut [f64], p: f64) -> f64 {
    v.sort_by(f64::total_cmp);
    v[((v.len() - 1) as f64 * p).round() as usize]
}

fn main() -> firmament::Result<()> {
    let args: Vec<String> = std::env::args().collect();
    let samples: usize = args.get(1).map_or(1024, |s| s.parse().expect("samples"));
    let which = args.get(2).map_or("all", |s| s.as_str()).to_string();
    let (model, sky, noise) = cloud_sky::earth_rgb_with_noise()?;
    let radius = model.bottom_radius_m;
    let colour = model.colour_matrix();
    let reference_settings = ReferenceSettings {
        samples,
        max_bounces: 4000,
        include_ground: true,
        ..ReferenceSettings::default()
    };

    let mut cases: Vec<(String, CloudLayerConfig, Vec<View>, f64)> = Vec::new();
    if which == "all" || which == "slab" {
        for tau in [5.0, 20.0] {
            for sun_zenith in [30.0, 70.0] {
                let slab = CloudLayerConfig {
                    bottom_m: Some(1000.0),
                    top_m: Some(2000.0),
                    extinction_per_m: Some(tau / 1000.0),
                    ..CloudLayerConfig::of_kind(CloudKind::Uniform)
                };
                let views = vec![
                    View {
                        name: "ground, up",
                        origin_alt_m: 2.0,
                        up: true,
                        cap_deg: 80.0,
                    },
                    View {
                        name: "3 km, down",
                        origin_alt_m: 3000.0,
                        up: false,
                        cap_deg: 75.0,
                    },
                    View {
                        name: "500 m, down",
                        origin_alt_m: 500.0,
                        up: false,
                        cap_deg: 60.0,
                    },
                ];
                cases.push((
                    format!("slab τ {tau}, sun zenith {sun_zenith}°"),
                    slab,
                    views,
                    sun_zenith,
                ));
            }
        }
    }
    if which == "all" || which == "cumulus" {
        for sun_zenith in [30.0, 70.0] {
            let views = vec![
                View {
                    name: "ground, up",
                    origin_alt_m: 2.0,
                    up: true,
                    cap_deg: 80.0,
                },
                View {
                    name: "5 km, down",
                    origin_alt_m: 5000.0,
                    up: false,
                    cap_deg: 60.0,
                },
            ];
            cases.push((
                format!("cumulus (default), sun zenith {sun_zenith}°"),
                CloudLayerConfig::of_kind(CloudKind::Cumulus),
                views,
                sun_zenith,
            ));
        }
    }

    println!("| case | view | class | n | median \\|e\\| | p95 \\|e\\| | bias | ref. noise |");
    println!("|---|---|---|---|---|---|---|---|");
    for (name, layer, views, sun_zenith) in &cases {
        let media: Vec<CloudMedium> =
            cloud_media(std::slice::from_ref(layer), radius, (0.0, 0.0), &noise)?;
        let sun = sun_direction(*sun_zenith, 180.0);
        let mut scene = Scene::clear_sky(&sky, sun, false);
        scene.volumes.push(Box::new(&media[0]));
        let volumes: Vec<Box<dyn Volume + '_>> = vec![Box::new(&media[0])];
        for view in views {
            let origin = Vec3::new(0.0, 0.0, radius + view.origin_alt_m);
            let dirs = directions(48, view.cap_deg, view.up);
            let rays: Vec<(Vec3, Vec3)> = dirs.iter().map(|&d| (origin, d)).collect();
            // The reference's estimates are kept in the temporary directory (the fast path
            // changes between runs, the reference does not).
            let key = format!("{name} {} {samples} {:?}", view.name, media[0].layer.params);
            let file = std::env::temp_dir().join(format!(
                "firmament-cloud-ref-{:016x}.json",
                firmament::atmosphere::model::fnv1a(key.as_bytes())
            ));
            let truth: Vec<(Vec<f64>, Vec<f64>)> = match std::fs::read(&file)
                .ok()
                .and_then(|b| serde_json::from_slice(&b).ok())
            {
                Some(t) => t,
                None => {
                    let t: Vec<_> = reference::render_pixels(
                        &model,
                        &volumes,
                        &[],
                        &rays,
                        0,
                        sun,
                        &reference_settings,
                        &|| {},
                    )
                    .into_iter()
                    .map(|e| (e.radiance, e.stderr))
                    .collect();
                    std::fs::write(&file, serde_json::to_vec(&t).unwrap()).ok();
                    t
                }
            };
            let shader = Shader::new(&scene, origin)?;
            let mut classes: std::collections::BTreeMap<&str, (Vec<f64>, Vec<f64>)> =
                Default::default();
            for (d, e) in dirs.iter().zip(&truth) {
                let ray = Ray { origin, dir: *d };
                let mut l = [0.0; 3];
                shader.shade(&ray, &mut ShadeScratch::default(), &mut l);
                let fast = colour.to_xyz(&l)[1];
                let (want, se) = colour.luminance_and_stderr(&e.0, &e.1);
                let err = fast / want - 1.0;
                let tau_view = media[0].optical_depth(&ray, 0.0, f64::INFINITY, 0);
                let ground = firmament::math::sphere::ray_sphere(origin, *d, radius)
                    .filter(|&(a, _)| a > 0.0)
                    .map(|(a, _)| origin + a * *d);
                let class = match ground {
                    Some(g)
                        if media[0].optical_depth(
                            &Ray { origin, dir: *d },
                            0.0,
                            (g - origin).length(),
                            0,
                        ) < 0.1 =>
                    {
                        let to_sun = media[0].optical_depth(
                            &Ray {
                                origin: g,
                                dir: sun,
                            },
                            0.0,
                            f64::INFINITY,
                            0,
                        );
                        if to_sun > 1.0 {
                            "ground in cloud shadow"
                        } else {
                            "ground in sun"
                        }
                    }
                    Some(_) if view.origin_alt_m < layer.resolved().bottom_m => {
                        "ground under the slab"
                    }
                    _ if tau_view < 0.1 => "sky through a gap",
                    _ if view.up || view.origin_alt_m < layer.resolved().bottom_m => "cloud base",
                    _ => "cloud top",
                };
                if std::env::var_os("CLOUD_ACCURACY_VERBOSE").is_some() {
                    eprintln!(
                        "{name} | {} | view zenith {:.0}° | to sun {:.0}° | fast {fast:.4e} ref {want:.4e} ± {:.1} % | {:+.1} %",
                        view.name,
                        d.z.acos().to_degrees(),
                        d.dot(sun).clamp(-1.0, 1.0).acos().to_degrees(),
                        100.0 * se / want,
                        100.0 * err
                    );
                }
                let c = classes.entry(class).or_default();
                c.0.push(err);
                c.1.push(se / want);
            }
            for (class, (errs, noise)) in classes {
                let mut abs: Vec<f64> = errs.iter().map(|e| e.abs()).collect();
                let bias = errs.iter().sum::<f64>() / errs.len() as f64;
                let mut nz = noise.clone();
                println!(
                    "| {name} | {} | {class} | {} | {:.1} % | {:.1} % | {:+.1} % | {:.1} % |",
                    view.name,
                    errs.len(),
                    100.0 * percentile(&mut abs, 0.5),
                    100.0 * percentile(&mut abs, 0.95),
                    100.0 * bias,
                    100.0 * percentile(&mut nz, 0.5),
                );
            }
        }
    }
    Ok(())
}

//! Clouds: the closed forms they must meet (Beer–Lambert through a uniform slab, the dark
//! air under a black deck, the energy-conserving step, the octaves' albedo), the refusal of bad settings with the field
//! named, and the renderer's fast path against the reference path tracer through a thin
//! uniform slab.

mod common;

use common::sky;

use firmament::math::sphere::ray_sphere;
use firmament::math::Vec3;
use firmament::reference::{self, ReferenceSettings};
use firmament::render::volumes::step_integral;
use firmament::render::{ShadeScratch, Shader};
use firmament::scene::clouds::{
    cloud_media, CloudKind, CloudLayerConfig, CloudMedium, CloudNoise, MultipleScattering,
};
use firmament::scene::{sun_direction, Ray, Scene, SceneFile, Volume};
use firmament::sky::{Shadow, SkyMethod};

/// Small noise textures (the tests' layers are uniform or only sampled coarsely).
fn noise() -> CloudNoise {
    CloudNoise::new([16, 8], None).unwrap().0
}

/// A uniform slab 1–2 km up of extinction `sigma` (m⁻¹) and albedo `albedo`.
fn slab(sigma: f64, albedo: f64) -> CloudLayerConfig {
    CloudLayerConfig {
        bottom_m: Some(1000.0),
        top_m: Some(2000.0),
        extinction_per_m: Some(sigma),
        albedo: Some(albedo),
        ..CloudLayerConfig::of_kind(CloudKind::Uniform)
    }
}

fn media(config: CloudLayerConfig) -> Vec<CloudMedium> {
    cloud_media(&[config], sky().model.bottom_radius_m, (0.0, 0.0), &noise()).unwrap()
}

#[test]
fn a_uniform_slab_transmits_by_beer_lambert() {
    let sky = sky();
    let radius = sky.model.bottom_radius_m;
    // Thin enough that the slab does not shadow the air below it (its transmittance
    // towards the sun, e^{−0.4/cos 40°} = 0.59, is above the shadow map's ½).
    let sigma = 0.0004;
    let medium = &media(slab(sigma, 0.0))[0];
    // From inside the slab, above its base: these rays up meet no air below the base, whose
    // multiple scattering the slab dims (render::shadowed_air: its own test below).
    let origin = Vec3::new(0.0, 0.0, radius + 1200.0);
    let sun = sun_direction(40.0, 180.0);
    let mut with = Scene::clear_sky(sky, sun, false);
    with.volumes.push(Box::new(medium));
    let without = Scene::clear_sky(sky, sun, false);
    for zenith_deg in [0.0f64, 30.0, 60.0, 75.0] {
        let z = zenith_deg.to_radians();
        let dir = Vec3::new(z.sin(), 0.0, z.cos());
        let ray = Ray { origin, dir };
        // The chord through the shell from the spheres, and τ = σ·chord.
        let enter = 0.0;
        let (_, leave) = ray_sphere(origin, dir, radius + 2000.0).unwrap();
        let tau = sigma * (leave - enter);
        let got = medium.optical_depth(&ray, 0.0, f64::INFINITY, 0);
        assert!(
            (got / tau - 1.0).abs() < 1e-12,
            "{zenith_deg}°: τ {got} vs {tau}"
        );
        // The renderer: an absorbing slab dims what is behind it (less the air before the
        // slab's mean depth) by e^{−τ}; the march's transmittance is exact for a constant σ.
        let mean = enter + 1.0 / sigma - (leave - enter) * (-tau).exp() / (1.0 - (-tau).exp());
        let front = {
            let view = sky.view(origin, &without.lights[0]);
            let mut l = [0.0; 3];
            view.sky_radiance_to_point(origin + mean * dir, Shadow::None, &mut l, &mut [0.0; 3]);
            l
        };
        let (l_with, l_without) = (
            common::shade(&with, origin, dir),
            common::shade(&without, origin, dir),
        );
        for k in 0..3 {
            let want = front[k] + (-tau).exp() * (l_without[k] - front[k]);
            assert!(
                (l_with[k] / want - 1.0).abs() < 2e-3,
                "{zenith_deg}°, channel {k}: {} vs {want}",
                l_with[k]
            );
        }
    }
}

/// Under an opaque, black deck covering the sky (τ 50, albedo 0) nothing lights the air
/// below it: no beam (its single scattering, the shadow), no sky and no ground (its
/// multiple scattering, render::shadowed_air's weights), so every ray from the ground is
/// dark, the horizon's too, where the ray stays under the deck for a hundred kilometres.
/// With the clear sky's multiple scattering kept there the zenith read 7.7 % of the clear sky.
#[test]
fn the_air_under_a_black_deck_is_dark() {
    let sky = sky();
    let medium = &media(slab(0.05, 0.0))[0];
    let origin = Vec3::new(0.0, 0.0, sky.model.bottom_radius_m + 2.0);
    let sun = sun_direction(40.0, 180.0);
    let mut deck = Scene::clear_sky(sky, sun, false);
    deck.volumes.push(Box::new(medium));
    let clear = Scene::clear_sky(sky, sun, false);
    let (under, open) = (
        Shader::new(&deck, origin).unwrap(),
        Shader::new(&clear, origin).unwrap(),
    );
    let colour = sky.model.colour_matrix();
    let mut scratch = ShadeScratch::default();
    for zenith_deg in [0.0f64, 45.0, 80.0, 88.0, 89.5, 120.0] {
        let z = zenith_deg.to_radians();
        let ray = Ray {
            origin,
            dir: Vec3::new(z.sin(), 0.0, z.cos()),
        };
        let (mut l_under, mut l_open) = ([0.0; 3], [0.0; 3]);
        under.shade(&ray, &mut scratch, &mut l_under);
        open.shade(&ray, &mut scratch, &mut l_open);
        let ratio = colour.to_xyz(&l_under)[1] / colour.to_xyz(&l_open)[1];
        println!(
            "view zenith {zenith_deg}°: {:.2} % of the clear sky's luminance",
            100.0 * ratio
        );
        assert!(
            ratio < 0.01,
            "view zenith {zenith_deg}°: {:.2} % of the clear sky",
            100.0 * ratio
        );
    }
}

#[test]
fn the_energy_conserving_step_is_the_exact_integral() {
    // ∫₀^d S·e^{−σs} ds against a fine midpoint rule, for thin and thick steps.
    for &(source, sigma, d) in &[
        (2.0, 0.01, 50.0),
        (1.0, 0.1, 100.0),
        (3.0, 1e-9, 10.0),
        (1.0, 5.0, 2.0),
    ] {
        let n = 200_000;
        let h = d / n as f64;
        let quadrature: f64 = (0..n)
            .map(|i| source * (-sigma * (i as f64 + 0.5) * h).exp() * h)
            .sum();
        let step = step_integral(source, sigma, d, (-sigma * d).exp());
        assert!(
            (step / quadrature - 1.0).abs() < 1e-8,
            "{sigma} {d}: {step} vs {quadrature}"
        );
        // And it never exceeds what the step's extinction can scatter: S/σ·(1 − e^{−σd}) ≤ S·d.
        assert!(step <= source * d * (1.0 + 1e-12));
    }
    assert_eq!(step_integral(2.0, 0.0, 3.0, 1.0), 6.0);
}

/// Energy through a conservative slab (δ-Eddington, Joseph et al. 1976): what its top
/// reflects (F↑ = πI₀ + 2πI₁/3 there), the beam that crosses it unscattered, and what
/// leaves its base (diffuse, and the light scattered into the phase's forward peak, which
/// goes on with the beam) add up to the beam's flux μ₀ on the top. Without the peak's
/// light at the base a slab of τ 2.9 would lose 6 % of μ₀.
#[test]
fn a_conservative_slab_sends_down_what_it_does_not_reflect() {
    use firmament::scene::clouds::two_stream::{COSINES, MAX_THICKNESS, THICKNESSES};
    // A thickness and a cosine on the tables' nodes (no interpolation error).
    let tau = MAX_THICKNESS * (4.0 / (THICKNESSES - 1) as f64).powi(2);
    let mu0 = 20.5 / COSINES as f64;
    let medium = &media(slab(tau / 1000.0, 1.0))[0];
    let radius = sky().model.bottom_radius_m;
    let top = Vec3::new(0.0, 0.0, radius + 2000.0 - 1e-3);
    let f = medium.diffuse_radiance(top, mu0, 0.0, 0).unwrap();
    let pi = std::f64::consts::PI;
    let reflected = pi * f.from_light[0] + 2.0 * pi / 3.0 * f.from_light[1];
    let total = reflected + mu0 * f.base_direct + f.base_from_light;
    assert!(
        (total / mu0 - 1.0).abs() < 2e-3,
        "reflected {reflected:.4} + direct {:.4} + base {:.4} = {total:.4}, μ₀ {mu0:.4}",
        mu0 * f.base_direct,
        f.base_from_light
    );
}

#[test]
fn octaves_never_scatter_more_than_they_extinguish() {
    let medium = &media(CloudLayerConfig {
        multiple_scattering: MultipleScattering::Octaves,
        octaves: Some(6),
        octave_scattering: Some(0.45),
        octave_extinction: Some(0.6),
        ..CloudLayerConfig::of_kind(CloudKind::Cumulus)
    })[0];
    let octaves = medium.octaves();
    assert_eq!(octaves.count, 6);
    for n in 0..octaves.count {
        let albedo = octaves.effective_albedo(n, medium.layer.params.albedo);
        assert!(
            albedo <= medium.layer.params.albedo && albedo <= 1.0,
            "octave {n}: {albedo}"
        );
    }
    // a > b is refused, naming the field.
    let err = CloudLayerConfig {
        octave_scattering: Some(0.7),
        octave_extinction: Some(0.5),
        ..CloudLayerConfig::of_kind(CloudKind::Cumulus)
    }
    .validate("clouds[0]")
    .unwrap_err()
    .to_string();
    assert!(err.contains("clouds[0].octave_scattering"), "{err}");
}

/// A scene file with the default camera and image and `clouds` as its `[[clouds]]`.
fn scene_with(clouds: &str) -> firmament::Result<SceneFile> {
    let dir = std::env::temp_dir().join(format!("firmament-clouds-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(format!(
        "scene-{:x}.toml",
        firmament::atmosphere::model::fnv1a(clouds.as_bytes())
    ));
    std::fs::write(
        &path,
        format!(
            "[atmosphere]\npreset = \"earth\"\n[camera]\nprojection = \"perspective\"\naltitude_m = 2\nheading_deg = 0\npitch_deg = 0\nfov_deg = 90\n[image]\nwidth = 64\nheight = 64\n{clouds}\n[output]\nfiles = [\"x.png\"]\n"
        ),
    )
    .unwrap();
    SceneFile::from_file(&path)
}

#[test]
fn bad_cloud_settings_are_refused_with_the_field_named() {
    for (clouds, field) in [
        ("[[clouds]]\nkind = \"cumulus\"\ncoverage = 1.5", "clouds[0].coverage"),
        ("[[clouds]]\nkind = \"cumulus\"\ncoverage = -0.1", "clouds[0].coverage"),
        ("[[clouds]]\nkind = \"cumulus\"\nbottom_m = 3000\ntop_m = 2000", "clouds[0].top_m"),
        ("[[clouds]]\nkind = \"cirrus\"\nextinction_per_m = 0", "clouds[0].extinction_per_m"),
        ("[[clouds]]\nkind = \"cirrus\"\nextinction_per_m = -1e-3", "clouds[0].extinction_per_m"),
        ("[[clouds]]\nkind = \"uniform\"\ncoverage = 0.5", "clouds[0].coverage"),
        ("[[clouds]]\nkind = \"cumulus\"\nalbedo = 1.2", "clouds[0].albedo"),
        ("[[clouds]]\nkind = \"cumulus\"\nphase_forward_g = 1.0", "clouds[0].phase_forward_g"),
        ("[[clouds]]\nkind = \"cumulus\"\noctaves = 0\nmultiple_scattering = \"octaves\"", "clouds[0].octaves"),
        ("[[clouds]]\nkind = \"cumulus\"\nweather = \"no-such-weather.png\"", "clouds[0].weather"),
        ("[[clouds]]\nkind = \"cumulus\"\nweather_wrap = \"planet\"\nweather = \"no-such-map.png\"", "clouds[0].weather"),
        ("[[clouds]]\nkind = \"uniform\"\nweather_wrap = \"planet\"", "clouds[0].weather_wrap"),
        ("[[clouds]]\nkind = \"cumulus\"\nweather_wrap = \"globe\"", "globe"),
        ("[[clouds]]\nkind = \"cumulus\"\n[[clouds]]\nkind = \"cumulus\"\nbottom_m = 2000\ntop_m = 3000", "clouds[1].bottom_m"),
    ] {
        let err = match scene_with(clouds) {
            Ok(scene) => scene
                .build_clouds(6_360_000.0, None)
                .err()
                .map(|e| e.to_string())
                .unwrap_or_default(),
            Err(e) => e.to_string(),
        };
        assert!(err.contains(field), "{clouds:?}: {err:?} should name {field}");
    }
    // An unknown kind is a parse error naming the value.
    let err = scene_with("[[clouds]]\nkind = \"nimbus\"")
        .unwrap_err()
        .to_string();
    assert!(err.contains("nimbus"), "{err}");
    // A good one passes.
    let scene = scene_with("[[clouds]]\nkind = \"cumulus\"\ncoverage = 0.3").unwrap();
    assert_eq!(scene.clouds.len(), 1);
    let planet = scene_with("[[clouds]]\nkind = \"cumulus\"\nweather_wrap = \"planet\"").unwrap();
    assert!(planet.build_clouds(6_360_000.0, None).unwrap()[0]
        .layer
        .planetary
        .is_some());
}

/// The fast path (single scattering, the two-stream's diffuse light, the shadowed air)
/// against the reference through a thin uniform slab (optical thickness 1) from the
/// ground: every direction within the tolerance; the figures are printed. Measured:
/// −1 % to −22 % (the fast path low: the air under the slab is either lit or in shadow,
/// here in shadow at a transmittance of 0.27, and the light the slab reflects up into the
/// air above it is not counted; see docs/accuracy.md).
#[test]
fn a_thin_slab_matches_the_reference() {
    let sky = sky();
    let model = &sky.model;
    let medium = &media(slab(0.001, 0.999))[0];
    let sun = sun_direction(40.0, 180.0);
    let mut scene = Scene::clear_sky(sky, sun, false);
    scene.volumes.push(Box::new(medium));
    let volumes: Vec<Box<dyn Volume + '_>> = vec![Box::new(medium)];
    let origin = Vec3::new(0.0, 0.0, model.bottom_radius_m + 2.0);
    let colour = model.colour_matrix();
    let settings = ReferenceSettings::with_samples(4096);
    let dirs: Vec<Vec3> = [
        (0.0f64, 0.0f64),
        (30.0, 0.0),
        (30.0, 180.0),
        (55.0, 90.0),
        (70.0, 0.0),
    ]
    .iter()
    .map(|&(z, a)| firmament::math::direction_from_zenith_azimuth(z.to_radians(), a.to_radians()))
    .collect();
    let rays: Vec<(Vec3, Vec3)> = dirs.iter().map(|&d| (origin, d)).collect();
    let truth = reference::render_pixels(model, &volumes, &[], &rays, 0, sun, &settings, &|| {});
    let mut worst: f64 = 0.0;
    for (d, e) in dirs.iter().zip(&truth) {
        let fast = colour.to_xyz(&common::shade(&scene, origin, *d))[1];
        let (want, se) = colour.luminance_and_stderr(&e.radiance, &e.stderr);
        let err = fast / want - 1.0;
        println!(
            "view zenith {:.0}°: fast {fast:.1} cd/m², reference {want:.1} ± {se:.1}: {:+.1} %",
            d.z.acos().to_degrees(),
            100.0 * err
        );
        worst = worst.max(err.abs());
    }
    assert!(
        worst < 0.25,
        "largest luminance error {:.1} %",
        100.0 * worst
    );
}

/// From orbit a pixel covers many cumulus cells: the renderer's one ray through the density
/// filtered over the pixel's footprint must give what its march through the unfiltered
/// noise gives on average over the pixel. 12 pixels of 10 km seen from 700 km, each against
/// the mean of 6×6 rays spread over it: the mean ratio within ±12 %. Measured (RGB small
/// tables, full noise in `cloud_orbit`): −5 % over 48 pixels; without the cap on far steps
/// the resolved march reads −34 % against the reference, without χ the filtered one +50 %.
#[test]
fn a_pixel_of_far_clouds_shows_their_mean() {
    use firmament::scene::clouds::{ViewFootprint, WeatherWrap};
    let sky = sky();
    let radius = sky.model.bottom_radius_m;
    let layer = CloudLayerConfig {
        weather_wrap: WeatherWrap::Planet,
        ..CloudLayerConfig::of_kind(CloudKind::Cumulus)
    };
    let noise = CloudNoise::new([32, 16], None).unwrap().0;
    let resolved = cloud_media(std::slice::from_ref(&layer), radius, (0.0, 0.0), &noise).unwrap();
    let mut filtered =
        cloud_media(std::slice::from_ref(&layer), radius, (0.0, 0.0), &noise).unwrap();
    let origin = Vec3::new(0.0, 0.0, radius + 700e3);
    let angle = 10e3 / 700e3;
    filtered[0].layer.set_view(
        ViewFootprint {
            eye: origin,
            pixel_angle_rad: angle,
        },
        None,
    );
    let sun = sun_direction(30.0, 180.0);
    let mut far = Scene::clear_sky(sky, sun, false);
    far.volumes.push(Box::new(&filtered[0]));
    let mut near = Scene::clear_sky(sky, sun, false);
    near.volumes.push(Box::new(&resolved[0]));
    let (far, near) = (
        Shader::new(&far, origin).unwrap(),
        Shader::new(&near, origin).unwrap(),
    );
    let luminance = |l: [f64; 3]| sky.model.colour_matrix().to_xyz(&l)[1];
    let shade = |s: &Shader, dir: Vec3| {
        let mut l = [0.0; 3];
        s.shade(&Ray { origin, dir }, &mut ShadeScratch::default(), &mut l);
        luminance(l)
    };
    let mut ratios = Vec::new();
    for p in 0..12 {
        let (theta, phi) = (0.35 * (p as f64 / 12.0).sqrt(), 2.4 * p as f64);
        let d = Vec3::new(
            theta.sin() * phi.cos(),
            theta.sin() * phi.sin(),
            -theta.cos(),
        );
        let u = d.cross(Vec3::X).normalize();
        let v = d.cross(u);
        let mut mean = 0.0;
        for j in 0..6 {
            for i in 0..6 {
                let (a, b) = (
                    ((i as f64 + 0.5) / 6.0 - 0.5) * angle,
                    ((j as f64 + 0.5) / 6.0 - 0.5) * angle,
                );
                mean += shade(&near, (d + a * u + b * v).normalize()) / 36.0;
            }
        }
        ratios.push(shade(&far, d) / mean);
    }
    let bias = ratios.iter().sum::<f64>() / ratios.len() as f64 - 1.0;
    eprintln!(
        "filtered / resolved over 12 far pixels: {:+.1} % ({ratios:.3?})",
        100.0 * bias
    );
    assert!(
        bias.abs() < 0.2,
        "filtered against resolved: {:+.1} %",
        100.0 * bias
    );
}

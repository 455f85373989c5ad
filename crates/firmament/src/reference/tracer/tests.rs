use super::free_path::profile_bound;
use super::*;
use crate::atmosphere::Atmosphere;
use crate::spectrum::Wavelengths;

#[test]
fn profile_bound_is_an_upper_bound() {
    let profiles = [
        DensityProfile::exponential(8000.0),
        DensityProfile::tent(10_000.0, 25_000.0, 40_000.0),
        DensityProfile::uniform(),
    ];
    for p in &profiles {
        for i in 0..200 {
            let h0 = i as f64 * 300.0;
            let h1 = h0 + 2500.0;
            let bound = profile_bound(p, h0, h1);
            for j in 0..=50 {
                let h = h0 + (h1 - h0) * j as f64 / 50.0;
                assert!(p.density(h) <= bound * (1.0 + 1e-12), "{p:?} {h} {bound}");
            }
        }
    }
}

#[test]
fn optical_depth_matches_exact_vertical_and_dense_slant_columns() {
    let model = Atmosphere::earth().resolve(&Wavelengths::rgb()).unwrap();
    let settings = ReferenceSettings::default();
    for k in 0..3 {
        let ch = Channel::new(&model, &[], &[], k, &settings);
        let frame = Frame::below(
            Vec3::new(0.0, 0.0, model.bottom_radius_m),
            model.bottom_radius_m,
        );
        // Vertical from the ground: exact columns.
        let o = Vec3::new(0.0, 0.0, 0.0);
        let x0 = frame.x(o);
        let (t_end, _) = ch.boundary(x0, frame.b(o, Vec3::new(0.0, 0.0, 1.0)));
        let tau = ch.optical_depth(x0, frame.b(o, Vec3::new(0.0, 0.0, 1.0)), t_end);
        let exact = model.optical_depths_vertical(0.0).total[k];
        assert!((tau / exact - 1.0).abs() < 1e-4, "{tau} {exact}");
        // Horizontal from 1 km: against Model's 4096-segment integration.
        let o = Vec3::new(0.0, 0.0, 1000.0);
        let d = Vec3::X;
        let (x0, b) = (frame.x(o), frame.b(o, d));
        let (t_end, ground) = ch.boundary(x0, b);
        assert!(!ground);
        let tau = ch.optical_depth(x0, b, t_end);
        let mut cols = vec![0.0; model.constituents.len()];
        model.columns_along_ray(model.bottom_radius_m + 1000.0, 0.0, t_end, 4096, &mut cols);
        let mut want = vec![0.0; 3];
        model.optical_depth_from_columns(&cols, &mut want);
        assert!((tau / want[k] - 1.0).abs() < 2e-4, "{tau} {}", want[k]);
    }
}

/// The kink-split Gauss–Legendre optical depth with the default segments against 256
/// segments, over random rays (all altitudes, dense near the horizon) in three presets:
/// relative error ≤ 1e-5 (measured: ≤ 1e-6 for bruneton2008, ≤ 1e-8 for earth, whose
/// ozone tent kinks made the unsplit rule converge only as 1/n²).
#[test]
fn optical_depth_converges_with_the_default_segments() {
    for preset in ["earth", "hazy", "bruneton2008"] {
        let model = Atmosphere::preset(preset)
            .unwrap()
            .resolve(&Wavelengths::rgb())
            .unwrap();
        let fine = ReferenceSettings {
            transmittance_segments: 256,
            ..Default::default()
        };
        let mut rng = Rng::for_key(1, 2, 3, 4);
        for k in 0..3 {
            let (chf, ch) = (
                Channel::new(&model, &[], &[], k, &fine),
                Channel::new(&model, &[], &[], k, &ReferenceSettings::default()),
            );
            let mut worst: f64 = 0.0;
            for _ in 0..3000 {
                let h = 60_000.0 * rng.next_f64().powi(3);
                let p = Vec3::new(0.0, 0.0, model.bottom_radius_m + h);
                let frame = Frame::below(p, model.bottom_radius_m);
                let o = frame.offset(p);
                let mu = if rng.next_f64() < 0.5 {
                    2.0 * rng.next_f64() - 1.0
                } else {
                    0.3 * (rng.next_f64() - 0.5)
                };
                let d = Vec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
                let (x0, b) = (frame.x(o), frame.b(o, d));
                let (t_end, ground) = chf.boundary(x0, b);
                let want = chf.optical_depth(x0, b, t_end);
                let got = ch.optical_depth(x0, b, t_end);
                if !ground && want < 30.0 {
                    worst = worst.max((got - want).abs() / want.max(1e-300));
                }
            }
            assert!(
                worst <= 1e-5,
                "{preset} channel {k}: relative error {worst:e}"
            );
        }
    }
}

// Surfaces besides the ground sphere: each test compares against something the tracer does
// not compute through the surface code (the analytic ground, a thinner slab, closed forms,
// the frame without the surface).

mod surfaces {
    use std::sync::atomic::{AtomicUsize, Ordering};

    use crate::atmosphere::{Albedo, Atmosphere, LimbDarkening, Model, SolarSpectrum, Sun};
    use crate::math::Vec3;
    use crate::medium::{Coefficient, Constituent, ConstituentKind, DensityProfile, PhaseFunction};
    use crate::reference::{self, RadianceEstimate, ReferenceSettings};
    use crate::render::RenderSettings;
    use crate::scene::{Camera, Light, Projection, Ray, Sphere, Surface, SurfaceHit};
    use crate::spectrum::Wavelengths;

    /// Planet radius of the plane-parallel slabs (curvature drop over 10 km: 5e-5 m).
    const R_PP: f64 = 1e12;

    /// A plane-parallel slab of uniform density, `thickness_m` thick with extinction
    /// `sigma_per_m` (single-scattering albedo `omega`, isotropic), one wavelength (500 nm),
    /// 1 W·m⁻²·nm⁻¹ from a uniform sun disk of 0.01° radius.
    fn slab(thickness_m: f64, sigma_per_m: f64, omega: f64, ground_albedo: f64) -> Model {
        Atmosphere {
            name: "slab".into(),
            description: "plane-parallel test slab".into(),
            bottom_radius_m: R_PP,
            top_radius_m: R_PP + thickness_m,
            ground_albedo: Albedo::Grey(ground_albedo),
            min_sun_elevation_deg: -10.0,
            sun: Sun {
                angular_radius_deg: 0.01,
                spectrum: SolarSpectrum::Table {
                    wavelengths_nm: vec![500.0],
                    values: vec![1.0],
                },
                limb_darkening: LimbDarkening::None,
            },
            constituents: vec![Constituent {
                name: "slab".into(),
                kind: ConstituentKind::Aerosols,
                density: DensityProfile::uniform(),
                scattering: Coefficient::Constant {
                    value_per_m: omega * sigma_per_m,
                },
                absorption: Coefficient::Constant {
                    value_per_m: (1.0 - omega) * sigma_per_m,
                },
                phase: PhaseFunction::Isotropic,
            }],
        }
        .resolve(&Wavelengths::from_list(&[500.0]).unwrap())
        .unwrap()
    }

    fn settings(samples: usize, seed: u64) -> ReferenceSettings {
        ReferenceSettings {
            samples,
            seed,
            include_ground: true,
            ..Default::default()
        }
    }

    /// The unit direction at `elevation_deg` above the horizon, `azimuth_deg` from +y
    /// towards +x, in the frame of the point on the +z axis.
    fn dir(elevation_deg: f64, azimuth_deg: f64) -> Vec3 {
        let (e, a) = (elevation_deg.to_radians(), azimuth_deg.to_radians());
        Vec3::new(e.cos() * a.sin(), e.cos() * a.cos(), e.sin())
    }

    fn ball(centre: Vec3, radius_m: f64, albedo: f64, channels: usize) -> Box<dyn Surface> {
        Box::new(Sphere {
            centre,
            radius_m,
            albedo: vec![albedo; channels],
            casts_shadows: true,
        })
    }

    /// |a − b| within `k` combined standard errors, per channel.
    fn agree(label: &str, a: &RadianceEstimate, b: &RadianceEstimate, k: f64) {
        for c in 0..a.radiance.len() {
            let se = a.stderr[c].hypot(b.stderr[c]);
            let diff = (a.radiance[c] - b.radiance[c]).abs();
            assert!(
                diff <= k * se,
                "{label} channel {c}: {} vs {} (±{se:e}, {:.1}σ)",
                a.radiance[c],
                b.radiance[c],
                diff / se
            );
        }
    }

    /// A sphere that counts how often the tracer reflects on it.
    struct Counted<'a>(Sphere, &'a AtomicUsize);

    impl Surface for Counted<'_> {
        fn intersect(&self, ray: &Ray, max_distance_m: f64) -> Option<SurfaceHit> {
            self.0.intersect(ray, max_distance_m)
        }
        fn albedo(&self, hit: &SurfaceHit, out: &mut [f64]) {
            self.1.fetch_add(1, Ordering::Relaxed);
            self.0.albedo(hit, out);
        }
    }

    /// A sphere equal to the planet's ground (the model's albedo, no shadows of its own)
    /// changes nothing, seen directly or met by the multiply scattered paths of a sky
    /// view, though the tracer reflects on it (it wins the tie with the analytic ground:
    /// each of the ground view's samples is reflected on it first).
    #[test]
    fn a_sphere_equal_to_the_ground_changes_nothing() {
        let model = Atmosphere::earth().resolve(&Wavelengths::rgb()).unwrap();
        let reflections = AtomicUsize::new(0);
        let surfaces: Vec<Box<dyn Surface>> =
            vec![Box::new(Counted(Sphere::ground(&model), &reflections))];
        let camera = Vec3::new(0.0, 0.0, model.bottom_radius_m + 1000.0);
        let sun = dir(35.0, 90.0);
        let s = settings(4000, 5);
        for (label, view) in [("ground", dir(-30.0, 200.0)), ("sky", dir(20.0, 45.0))] {
            let plain = reference::scene_radiance(&model, &[], &[], camera, view, sun, &s, 1);
            let with = reference::scene_radiance(&model, &[], &surfaces, camera, view, sun, &s, 2);
            agree(label, &plain, &with, 3.0);
        }
        let reflections = reflections.load(Ordering::Relaxed);
        assert!(
            reflections >= 3 * 4000,
            "{reflections} reflections on the sphere"
        );
    }

    /// A sphere of radius R_g + 5 km over a slab 10 km thick is a ground raised into the
    /// slab: it seals off the air below, so the scene equals a slab 5 km thick with the
    /// sphere's albedo on its ground (the same air above; in the plane-parallel limit the
    /// 5 km of radius are nothing), seen from above (reflections seen directly, shadow rays
    /// from the air) and from inside looking up (the sky lit from a surface below). The
    /// model's own ground, under the sphere, is black; without the sphere the scene is far
    /// off.
    #[test]
    fn a_raised_ground_equals_a_thinner_slab() {
        let (sigma, omega, albedo) = (0.5 / 5000.0, 0.9, 0.8);
        let thick = slab(10_000.0, sigma, omega, 0.0);
        let thin = slab(5000.0, sigma, omega, albedo);
        let raised = [ball(Vec3::ZERO, R_PP + 5000.0, albedo, 1)];
        let sun = dir(35.0, 90.0);
        let s = settings(4000, 11);
        let at = |h: f64| Vec3::new(0.0, 0.0, R_PP + h);
        for (label, h, view) in [
            ("down", 4999.0, dir(-40.0, 30.0)),
            ("up", 1000.0, dir(25.0, 200.0)),
        ] {
            let want = reference::scene_radiance(&thin, &[], &[], at(h), view, sun, &s, 1);
            let (camera, view) = (at(h + 5000.0), view);
            let got = reference::scene_radiance(&thick, &[], &raised, camera, view, sun, &s, 2);
            agree(label, &got, &want, 3.0);
            let bare = reference::scene_radiance(&thick, &[], &[], camera, view, sun, &s, 2);
            let (a, b) = (got.radiance[0], bare.radiance[0]);
            assert!(
                (a - b).abs() > 10.0 * got.stderr[0].hypot(bare.stderr[0]),
                "{label}: {a} {b}"
            );
        }
    }

    /// A black ball shades what lies behind it from the sun, against closed forms in
    /// plane-parallel slabs. In the air: single scattering along a horizontal ray through
    /// a slab of σ = 1e-4 m⁻¹ (ω = 1, isotropic) whose stretch t ∈ [4, 6] km crosses the
    /// ball's shadow, L = σ_s/(4π)·E·T_sun/σ·Σ_lit (e^{−σa} − e^{−σb}) (12 % less than with
    /// no ball). On the ground: a purely absorbing slab (τ = 0.2), whose ground in view
    /// returns ρ/π·E·μ_s·T_sun·T_view without the ball and exactly nothing in its shadow;
    /// the ball's lit side, ρ/π·E·(n·l)·T_sun·T_view with its own normal n at the hit.
    #[test]
    fn a_ball_shades_the_air_and_the_ground_behind_it() {
        let sun = dir(50.0, 0.0);
        let (h, sigma) = (10_000.0, 1e-4);
        let air = slab(h, sigma, 1.0, 0.0);
        let single = ReferenceSettings {
            max_bounces: 1,
            ..settings(4000, 3)
        };
        let camera = Vec3::new(0.0, 0.0, R_PP + 2000.0);
        let view = Vec3::X;
        let shade = [ball(camera + 5000.0 * view + 4000.0 * sun, 1000.0, 0.0, 1)];
        let t_sun = (-sigma * (h - 2000.0) / sun.z).exp();
        let scale = sigma / (4.0 * std::f64::consts::PI) * t_sun / sigma;
        let lit = |a: f64, b: f64| (-sigma * a).exp() - (-sigma * b).exp();
        for (label, surfaces, want) in [
            ("no ball", &[][..], scale),
            (
                "ball",
                &shade[..],
                scale * (lit(0.0, 4000.0) + lit(6000.0, f64::INFINITY)),
            ),
        ] {
            let e = reference::scene_radiance(&air, &[], surfaces, camera, view, sun, &single, 0);
            let (got, se) = (e.radiance[0], e.stderr[0]);
            assert!(
                (got - want).abs() <= 3.0 * se + 2e-3 * want,
                "{label}: {got} ± {se} vs {want}"
            );
        }

        let (sigma, rho) = (2e-5, 0.5);
        let absorbing = slab(h, sigma, 0.0, rho);
        let camera = Vec3::new(0.0, 0.0, R_PP + 1000.0);
        let view = dir(-45.0, 90.0);
        let ground = Vec3::new(1000.0, 0.0, R_PP);
        let shade = [ball(ground + 5000.0 * sun, 1000.0, 0.0, 1)];
        let s = ReferenceSettings {
            max_bounces: 1,
            ..settings(64, 3)
        };
        let lit = reference::scene_radiance(&absorbing, &[], &[], camera, view, sun, &s, 0);
        let direct = |z: f64, cos: f64, t: f64| {
            rho / std::f64::consts::PI * cos * (-sigma * (h - z) / sun.z).exp() * (-sigma * t).exp()
        };
        let want = direct(0.0, sun.z, 1000.0 * 2f64.sqrt());
        assert!(
            (lit.radiance[0] / want - 1.0).abs() < 1e-3,
            "{} vs {want}",
            lit.radiance[0]
        );
        let shaded = reference::scene_radiance(&absorbing, &[], &shade, camera, view, sun, &s, 0);
        assert_eq!(shaded.radiance[0], 0.0, "the ground in the ball's shadow");
        // A white ball to the south, its north face towards the camera and the sun, seen
        // below its middle (n·l = 0.27, where the local vertical would give 0.77).
        let (centre, radius) = (camera + Vec3::new(0.0, -3000.0, 0.0), 500.0);
        let view = Vec3::new(250.0, -3000.0, -200.0).normalize();
        let oc = camera - centre;
        let (b, c) = (oc.dot(view), oc.dot(oc) - radius * radius);
        let t = -b - (b * b - c).sqrt();
        let n = (oc + t * view) / radius;
        let want = direct(camera.z - R_PP + t * view.z, n.dot(sun), t);
        let white = [ball(centre, radius, rho, 1)];
        let e = reference::scene_radiance(&absorbing, &[], &white, camera, view, sun, &s, 0);
        assert!(
            (e.radiance[0] / want - 1.0).abs() < 1e-3,
            "the ball's lit side: {} vs {want} (n·l = {})",
            e.radiance[0],
            n.dot(sun)
        );
    }

    /// In `render_frame` the sun's disk, seen in the middle pixel of a narrow view, is
    /// hidden by a ball in front of it: what is left is the ball's side away from the sun
    /// and the air before it, far below the disk.
    #[test]
    fn render_frame_hides_the_sun_disk_behind_a_surface() {
        let model = Atmosphere::earth().resolve(&Wavelengths::rgb()).unwrap();
        let camera = Camera {
            projection: Projection::Perspective,
            altitude_m: 1000.0,
            heading_deg: 30.0,
            pitch_deg: 20.0,
            roll_deg: 0.0,
            fov_deg: 2.0,
        };
        let rs = RenderSettings {
            camera: &camera,
            width: 3,
            height: 3,
            white_balance: false,
        };
        let centre = camera
            .prepare(model.bottom_radius_m, 3, 3)
            .ray(1.5, 1.5)
            .unwrap();
        let sun = Light::sun(&model, centre.dir, true);
        let s = settings(16, 1);
        let front = [ball(centre.origin + 2000.0 * centre.dir, 100.0, 0.5, 3)];
        let luminance = |surfaces: &[Box<dyn Surface>]| {
            let (frame, _) =
                reference::render_frame(&model, &[], surfaces, &rs, &sun, &s, &|_| {}, None)
                    .unwrap();
            let y = |p: [f32; 3]| 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
            (y(frame.image.data[4]), y(frame.image.data[0]))
        };
        let (disk, sky) = luminance(&[]);
        let (hidden, ball_edge) = luminance(&front);
        assert!(
            disk > 1e3 * sky,
            "the disk in view: {disk} vs the sky beside it {sky}"
        );
        assert!(
            hidden < 1e-3 * disk,
            "the disk behind the ball: {hidden} vs {disk}"
        );
        assert!(
            ball_edge < sky,
            "the ball's shaded side {ball_edge} vs the sky {sky}"
        );
    }
}

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
        let ch = Channel::new(&model, &[], k, &settings);
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
                Channel::new(&model, &[], k, &fine),
                Channel::new(&model, &[], k, &ReferenceSettings::default()),
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

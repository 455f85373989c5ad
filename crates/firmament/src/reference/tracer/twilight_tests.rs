//! Twilight sampling (`lit`, `guide`) against what it must equal: single scattering
//! integrated deterministically along the view ray through the planet's shadow, and the
//! plain estimator (NEE at the collisions, phase sampling) with all orders.

use super::*;
use crate::atmosphere::Atmosphere;
use crate::reference::{self, RadianceEstimate};
use crate::spectrum::Wavelengths;

fn dir(elevation_deg: f64, azimuth_deg: f64) -> Vec3 {
    let (e, a) = (elevation_deg.to_radians(), azimuth_deg.to_radians());
    Vec3::new(e.cos() * a.cos(), e.cos() * a.sin(), e.sin())
}

/// Single scattering seen from `camera` along unit `view`, the sun a point in `sun`:
/// ∫ T(0,t) Σᵢ σ_s,ᵢ pᵢ T_sun(t) E dt by the midpoint rule on `steps` equal steps, with
/// the tracer's own deterministic optical depths (T_sun = 0 in the planet's shadow).
fn single_scattering(ch: &Channel, camera: Vec3, view: Vec3, sun: Vec3, steps: usize) -> f64 {
    let frame = Frame::below(camera, ch.bottom);
    let o = frame.offset(camera);
    let (x0, b) = (frame.x(o), frame.b(o, view));
    let (t_end, _) = ch.boundary(x0, b);
    let mut scratch = ch.scratch();
    let dt = t_end / steps as f64;
    let mut sum = 0.0;
    for i in 0..steps {
        let t = (i as f64 + 0.5) * dt;
        let p = o + t * view;
        let tr_sun = ch.transmittance(&frame, p, sun);
        if tr_sun <= 0.0 {
            continue;
        }
        let (_, ss) = ch.coefficients(&frame, p, ch.alt(x0, b, t), &mut scratch);
        if ss > 0.0 {
            let tr = (-ch.optical_depth(x0, b, t)).exp();
            sum += tr * ss * ch.phase(&scratch, ss, view.dot(sun)) * tr_sun * dt;
        }
    }
    sum * ch.solar
}

/// Single scattering of `earth` under a point-like sun (radius 1e-6 rad, no limb
/// darkening), daylight and twilight, from the ground and from 10 km: the flight's
/// distance pdf and its defensive mixture give the integral within the noise.
#[test]
fn lit_single_scattering_matches_the_integral_through_the_shadow() {
    let mut model = Atmosphere::earth().resolve(&Wavelengths::rgb()).unwrap();
    model.sun_angular_radius_rad = 1e-6;
    model.limb_darkening = crate::atmosphere::LimbDarkening::None;
    let settings = ReferenceSettings {
        samples: 4096,
        max_bounces: 1,
        ..Default::default()
    };
    // (altitude m, sun elevation °, view elevation °, view azimuth from the sun °)
    let cases = [
        (0.0, 30.0, 90.0, 0.0),
        (0.0, -6.0, 10.0, 0.0),
        (0.0, -6.0, 90.0, 0.0),
        (10_000.0, -6.0, 2.0, 0.0),
        (10_000.0, -6.0, 30.0, 90.0),
    ];
    for (alt, sun_deg, el, az) in cases {
        let camera = Vec3::new(0.0, 0.0, model.bottom_radius_m + alt);
        let (sun, view) = (dir(sun_deg, 0.0), dir(el, az));
        let e = reference::sky_radiance(&model, camera, view, sun, &settings);
        for k in 0..model.channels() {
            let ch = Channel::new(&model, &[], &[], k, &settings);
            let want = single_scattering(&ch, camera, view, sun, 6000);
            let (got, se) = (e.radiance[k], e.stderr[k]);
            assert!(
                want > 0.0 && (got - want).abs() <= 4.0 * se + 2e-3 * want,
                "alt {alt} m, sun {sun_deg}°, view ({el}°, {az}°), channel {k}: \
                 {got} ± {se} against {want}"
            );
            assert!(se < 0.02 * want, "noise {se} of {want}");
        }
    }
}

/// All orders at a twilight view and at daylight: twilight sampling (the flights' NEE and
/// the guided directions) against the plain estimator, within their joint noise (0.5–5 %
/// per channel; the plain one has 4× the paths at −3° and is still the noisier).
#[test]
fn lit_sampling_agrees_with_the_plain_estimator() {
    let model = Atmosphere::earth().resolve(&Wavelengths::rgb()).unwrap();
    let plain = |samples| ReferenceSettings {
        samples,
        seed: 3,
        lit_sampling: false,
        ..Default::default()
    };
    let lit = |samples| ReferenceSettings {
        samples,
        seed: 4,
        ..Default::default()
    };
    // (altitude m, sun elevation °, view elevation °, azimuth °, plain paths, lit paths)
    let cases = [
        (10_000.0, -3.0, 90.0, 0.0, 32_768, 8192),
        (1000.0, -3.0, 10.0, 180.0, 32_768, 8192),
        (0.0, 30.0, 30.0, 90.0, 4096, 2048),
    ];
    for (alt, sun_deg, el, az, n_plain, n_lit) in cases {
        let camera = Vec3::new(0.0, 0.0, model.bottom_radius_m + alt);
        let (sun, view) = (dir(sun_deg, 0.0), dir(el, az));
        let a: RadianceEstimate =
            reference::sky_radiance(&model, camera, view, sun, &plain(n_plain));
        let b = reference::sky_radiance(&model, camera, view, sun, &lit(n_lit));
        for k in 0..model.channels() {
            let joint = a.stderr[k].hypot(b.stderr[k]);
            assert!(
                (a.radiance[k] - b.radiance[k]).abs() <= 4.0 * joint,
                "alt {alt} m, sun {sun_deg}°, view ({el}°, {az}°), channel {k}: plain {} ± {}, \
                 lit {} ± {}",
                a.radiance[k],
                a.stderr[k],
                b.radiance[k],
                b.stderr[k]
            );
            assert!(joint < 0.06 * a.radiance[k], "joint noise {joint}");
        }
    }
}

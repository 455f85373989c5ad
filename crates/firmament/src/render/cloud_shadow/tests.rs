//! The clouds' shadow map's tests: its cover under a low sun, the far air's mean fraction,
//! the near air's lit share, the merging, the square's growth and the penumbra.

use super::*;

/// A map over a base `base_height_m` up lit by `light`: every texel's depth `tau`, every
/// block's mean transmittance `mean`.
fn uniform_map(light: Vec3, planet: f64, base_height_m: f64, tau: f32, mean: f32) -> CloudShadow {
    CloudShadow {
        light,
        angular_radius_rad: 0.00465,
        base_radius_m: planet + base_height_m,
        planet_radius_m: planet,
        half_m: map_half_extent_m(light, base_height_m),
        tau: vec![tau; TEXELS * TEXELS],
        coarse: vec![mean; COARSE_TEXELS * COARSE_TEXELS],
        extends: true,
    }
}

/// Under the default scene's low sun (5.5° high) and cumulus base (3.2 km), the ground
/// and the air below the base within [`MAX_SHADOW_DISTANCE_M`] of the observer find
/// their shadow in the map: their rays to the sun meet the base up to 33 km towards it
/// (with a 40 km map, those beyond 7 km towards the sun did not, and stayed lit).
#[test]
fn the_map_covers_the_near_air_under_a_low_sun() {
    let planet = 6_360_000.0;
    let e = 5.5f64.to_radians();
    let light = Vec3::new(
        e.cos() * 237f64.to_radians().sin(),
        e.cos() * 237f64.to_radians().cos(),
        e.sin(),
    );
    let map = uniform_map(light, planet, 3200.0, 1.0, 0.5);
    let r = 0.999 * MAX_SHADOW_DISTANCE_M;
    for k in 0..16 {
        let a = k as f64 * std::f64::consts::TAU / 16.0;
        for h in [0.0, 1000.0, 3000.0] {
            // On the sphere of height h, r from the observer's place.
            let x = Vec3::new(r * a.sin(), r * a.cos(), planet).normalize() * (planet + h);
            let tau = map.optical_depth(x);
            assert!(
                tau.is_some_and(|t| (t - 1.0).abs() < 1e-9),
                "{a} {h}: {tau:?}"
            );
        }
    }
    // At or above the base: not the map's.
    assert!(map
        .optical_depth(Vec3::new(0.0, 0.0, planet + 3200.5))
        .is_none());
}

/// A ray from 2 m above the ground rising 1.1° (below a 1.5 km base for 60 km), under a
/// light 50° high: (the planet's radius, the light, the ray).
fn skimming_ray() -> (f64, Vec3, Ray) {
    let planet = 6_360_000.0;
    let e = 50f64.to_radians();
    let light = Vec3::new(0.0, e.cos(), e.sin());
    let ray = Ray {
        origin: Vec3::new(0.0, 0.0, planet + 2.0),
        dir: Vec3::new(0.7, 0.7, 0.02).normalize(),
    };
    (planet, light, ray)
}

/// Beyond [`MAX_SHADOW_DISTANCE_M`] the air is in shadow over the fraction of its
/// length that the blocks' mean transmittance leaves unlit (a broken field: half; an
/// overcast: all; clear: none), in a few stretches, and none of it nearer where the
/// texels are lit: no blotches where the mean hovers about ½ (the threshold at ½ drew
/// them near the horizon of the noon cumulus scene).
#[test]
fn the_far_air_is_shadowed_by_the_mean_fraction() {
    let (planet, light, ray) = skimming_ray();
    let limit = ray_sphere(ray.origin, ray.dir, planet + 1500.0).unwrap().1;
    assert!(limit > 3.0 * MAX_SHADOW_DISTANCE_M);
    for (mean, want) in [(0.5, 0.5), (0.0, 1.0), (1.0, 0.0), (0.2, 0.8)] {
        let map = uniform_map(light, planet, 1500.0, 0.0, mean);
        let mut out = Vec::new();
        map.shadowed_intervals(&ray, f64::INFINITY, &mut out);
        let shadowed: f64 = out.iter().map(|(a, b)| b - a).sum();
        let far = limit - MAX_SHADOW_DISTANCE_M;
        assert!(
            (shadowed - want * far).abs() < 1e-3 * far,
            "mean {mean}: {shadowed} of {far} m"
        );
        assert!(out.iter().all(|&(a, _)| a >= MAX_SHADOW_DISTANCE_M - 1e-6));
        assert!(out.len() <= 8, "{} stretches", out.len());
    }
}

/// Near the observer each step of the air is in shadow over 1 − T of its length (T its
/// transmittance towards the light; within [`SHADOW_SNAP`] of 0 or 1, all or none): under
/// a uniform layer of τ 1 the near air keeps e^{−1} of its single scattering, not none
/// (a shadow wherever T < ½).
#[test]
fn the_near_air_keeps_its_lit_share() {
    let (planet, light, ray) = skimming_ray();
    let share = |tau: f64| 1.0 - (-tau).exp();
    for (tau, want) in [
        (1.0, share(1.0)),
        (0.02, 0.0),
        (4.0, 1.0),
        (0.3, share(0.3)),
    ] {
        // The far pieces lit (their mean 1).
        let map = uniform_map(light, planet, 1500.0, tau as f32, 1.0);
        let mut out = Vec::new();
        map.shadowed_intervals(&ray, f64::INFINITY, &mut out);
        let shadowed: f64 = out.iter().map(|(a, b)| b - a).sum();
        let near = MAX_SHADOW_DISTANCE_M;
        assert!(
            (shadowed - want * near).abs() < 1e-6 * near,
            "τ {tau}: {shadowed} of {near} m"
        );
    }
}

/// Merging keeps the lit length (the shadow shrunk by half the gap at each end) and
/// merges only gaps under [`MERGE_FRACTION`] of their distance: near the observer a
/// 250 m gap stays.
#[test]
fn merging_keeps_the_lit_length() {
    let mut v = vec![
        (500.0, 600.0),
        (850.0, 900.0),
        (2000.0, 2100.0),
        (2150.0, 2400.0),
        (20_000.0, 20_500.0),
        (20_600.0, 21_000.0),
        (21_000.0, 22_000.0),
    ];
    let shadow = |v: &[(f64, f64)]| v.iter().map(|(a, b)| b - a).sum::<f64>();
    let before = shadow(&v);
    merge_close(&mut v, 0, MERGE_FRACTION);
    assert_eq!(
        v,
        vec![
            (500.0, 600.0),
            (850.0, 900.0),
            (2025.0, 2375.0),
            (20_075.0, 21_975.0)
        ]
    );
    assert!((shadow(&v) - before).abs() < 1e-9);
}

/// The square widens as the light sinks, from 40 km (125 m texels) under a high sun to
/// 80 km; below the horizon the widest.
#[test]
fn the_square_widens_as_the_light_sinks() {
    let at = |elevation_deg: f64| {
        let e = elevation_deg.to_radians();
        map_half_extent_m(Vec3::new(0.0, e.cos(), e.sin()), 3200.0)
    };
    assert_eq!(at(90.0), MIN_HALF_EXTENT_M);
    assert!((at(60.0) - (MIN_HALF_EXTENT_M + 3200.0 / 3f64.sqrt())).abs() < 1e-6);
    assert!(at(30.0) < at(10.0) && at(10.0) < at(5.5) && at(5.5) < HALF_EXTENT_M);
    assert_eq!(at(1.0), HALF_EXTENT_M);
    assert_eq!(at(-1.0), HALF_EXTENT_M);
}

/// Under a 5.5° sun a cloud's shadow edge across the light's azimuth is a penumbra of
/// kilometres on the ground: the disk's taps match a brute-force mean of the map's
/// transmittance over 5 000 directions filling the disk, across a one-texel edge,
/// within 0.04 (measured 0.032: the midpoint rule's 14 taps over a step), rising
/// steadily; under a 60° sun the one tap is the centre's.
#[test]
fn the_penumbra_is_the_disks_mean() {
    let (planet, h, e) = (6_360_000.0, 2800.0, 5.5f64.to_radians());
    let light = Vec3::new(e.cos(), 0.0, e.sin());
    let mut map = uniform_map(light, planet, h, 0.0, 1.0);
    // Opaque where the planar x is negative.
    map.tau
        .chunks_mut(TEXELS)
        .for_each(|r| r[..TEXELS / 2].fill(20.0));
    let t1 = (Vec3::Z - light * light.z).normalize();
    let t2 = light.cross(t1);
    let alpha = map.angular_radius_rad;
    let mut ramp = Vec::new();
    for offset in [
        -1500.0, -1000.0, -700.0, -300.0, 0.0, 300.0, 700.0, 1000.0, 1500.0,
    ] {
        let x = Vec3::new(offset - h / e.tan(), 0.0, planet);
        let (mut sum, mut count) = (0.0, 0.0);
        for (i, j) in (0..80).flat_map(|i| (0..80).map(move |j| (i, j))) {
            let (u, v) = ((i as f64 - 39.5) / 40.0, (j as f64 - 39.5) / 40.0);
            if u * u + v * v <= 1.0 {
                let d = (light + alpha * (u * t1 + v * t2)).normalize();
                let tau = map.texel_depth(map.entry_texel_along(x, d, TEXELS).unwrap());
                sum += (-tau.unwrap()).exp();
                count += 1.0;
            }
        }
        let got = (-map.disk_optical_depth(x).unwrap()).exp();
        let want = sum / count;
        assert!((got - want).abs() < 0.04, "{offset} m: {got} vs {want}");
        ramp.push(got);
    }
    // A ramp, not a step: the disk spreads the edge over ±h·α/sin²e (1.36 km).
    assert!(ramp[0] < 0.02 && ramp[8] > 0.98 && ramp[2] > 0.1 && ramp[6] < 0.9);
    assert!(ramp.windows(2).all(|w| w[1] > w[0]), "{ramp:?}");
    let high = Vec3::new(0.5, 0.0, 0.75f64.sqrt());
    let mut map = uniform_map(high, planet, h, 0.0, 1.0);
    map.tau
        .iter_mut()
        .enumerate()
        .for_each(|(i, t)| *t = (i % 7) as f32);
    let x = Vec3::new(123.0, -45.0, planet);
    assert_eq!(map.disk_optical_depth(x), map.optical_depth(x));
}

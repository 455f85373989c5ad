//! No silently wrong numbers: energy conservation over random (and extreme) accepted
//! atmospheres, the twilight falling on below the tables' lowest sun, and the atmospheres
//! the tables cannot resolve refused.

use firmament::atmosphere::{Albedo, Atmosphere};
use firmament::math::{direction_from_zenith_azimuth, Vec3};
use firmament::medium::{Coefficient, DensityProfile};
use firmament::scene::Light;
use firmament::sky::bruneton4d::{Bruneton4d, TableConfig, TableSizes};
use firmament::sky::{Shadow, SkyMethod};
use firmament::spectrum::{luminance_from_spectrum, Wavelengths};

/// SplitMix64 (Steele, Lea & Flood 2014): a seeded stream of uniforms in [0, 1).
struct Rng(u64);

impl Rng {
    fn uniform(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        (z ^ (z >> 31)) as f64 / u64::MAX as f64
    }

    /// Log-uniform in [a, b].
    fn log_uniform(&mut self, a: f64, b: f64) -> f64 {
        (a.ln() + self.uniform() * (b.ln() - a.ln())).exp()
    }
}

fn small_tables(atmosphere: &Atmosphere) -> Bruneton4d {
    let model = atmosphere.resolve(&Wavelengths::rgb()).unwrap();
    let config = TableConfig {
        sizes: TableSizes::small(),
        orders: 4,
        ..Default::default()
    };
    Bruneton4d::compute(model, &config).unwrap()
}

/// `earth` with the ozone column, the haze's turbidity and scale height, the ground albedo
/// and the shell's thickness drawn at random; the first draws are the extremes (10¹² DU of
/// ozone, the thickest haze the tables take, a white ground, thin and thick shells).
fn random_earth(rng: &mut Rng, case: usize) -> Atmosphere {
    let mut a = Atmosphere::earth();
    let (ozone_du, beta, haze_m, albedo, shell_m) = match case {
        0 => (1e12, 0.04, 1200.0, 0.1, 60e3),
        // The thickest haze the tables take (τ_s ≈ 2.9 at 440 nm: `thickness`).
        1 => (300.0, 1.0, 1200.0, 1.0, 60e3),
        2 => (300.0, 0.04, 1200.0, 1.0, 20e3),
        3 => (0.0, 0.5, 2000.0, 1.0, 160e3),
        _ => {
            let haze_m = rng.log_uniform(500.0, 5000.0);
            (
                rng.log_uniform(1.0, 1e5),
                rng.log_uniform(1e-3, 1.0),
                haze_m,
                rng.uniform(),
                // Within what is accepted: at most 200 haze layers, 20 of the air's.
                rng.log_uniform(20e3, (150.0 * haze_m).clamp(20e3, 160e3)),
            )
        }
    };
    a.top_radius_m = a.bottom_radius_m + shell_m;
    a.ground_albedo = Albedo::Grey(albedo);
    for c in &mut a.constituents {
        match &mut c.absorption {
            Coefficient::OzoneColumn { column_du } => *column_du = ozone_du,
            Coefficient::Angstrom { beta: b, .. } => *b = beta,
            _ => {}
        }
        if let Coefficient::Angstrom { beta: b, .. } = &mut c.scattering {
            *b = beta;
            c.density = DensityProfile::exponential(haze_m);
        }
    }
    a.validate().expect("an accepted atmosphere");
    a
}

#[test]
fn sky_irradiance_stays_below_the_sun_outside_and_radiance_bounded() {
    let mut rng = Rng(0x5eed);
    for case in 0..7 {
        let atmosphere = random_earth(&mut rng, case);
        let sky = small_tables(&atmosphere);
        let model = &sky.model;
        let n = model.channels();
        let e_toa = &model.solar_irradiance;
        // Single scattering along any ray is at most E·p_max·(1 − T) ≤ E·p_max; the higher
        // orders are a field whose irradiance is at most E, so at most E/π per steradian
        // were it isotropic: E·(p_max + 1) leaves room for its anisotropy.
        let p_max = model
            .groups
            .phase
            .iter()
            .map(|p| p.eval(1.0))
            .fold(0.0, f64::max);
        for j in 0..4 {
            // First from the ground under a 30° sun (the case), then at random.
            let (zenith, altitude) = match j {
                0 => (30f64.to_radians(), 0.0),
                _ => (
                    (rng.uniform() * 100.0).to_radians(),
                    rng.uniform() * 0.5 * (model.top_radius_m - model.bottom_radius_m),
                ),
            };
            let observer = Vec3::new(0.0, 0.0, model.bottom_radius_m + altitude);
            let light = Light::sun(model, direction_from_zenith_azimuth(zenith, 0.0), false);
            let view = sky.view(observer, &light);
            let (mut direct, mut diffuse) = (vec![0.0; n], vec![0.0; n]);
            view.sun_and_sky_irradiance(observer, Vec3::Z, &mut direct, &mut diffuse);
            // The sky alone: with the sun's beam added the sum can pass E·μ_s in a thick
            // shell, whose irradiance rows (20 km apart at 160 km) blend the ground's sky
            // into the direct beam aloft.
            for k in 0..n {
                assert!(
                    diffuse[k] <= e_toa[k] && diffuse[k] >= 0.0,
                    "case {case} ({atmosphere:?}): sky {diffuse:?} above the TOA {e_toa:?} at zenith {zenith}, altitude {altitude}",
                );
            }
            let (mut radiance, mut t) = (vec![0.0; n], vec![0.0; n]);
            // Views 7° off the 15° grid, none on the horizon: a view exactly along it from
            // inside a thick haze reads above this bound (τ ≈ 6, 2 km up: single scattering
            // 0.31 W·m⁻²·sr⁻¹·nm⁻¹ at 440 nm against E·p ≈ 0.1, 38 with the orders), the
            // lookup's seam between rays that meet the ground and rays that do not; left
            // for the parameterisation's work (docs/accuracy.md).
            for i in 0..12 {
                let dir = direction_from_zenith_azimuth(
                    (15.0 * i as f64 + 7.0).to_radians(),
                    (37.0 * i as f64).to_radians(),
                );
                view.sky_radiance(dir, Shadow::None, &mut radiance, &mut t);
                for k in 0..n {
                    assert!(
                        radiance[k].is_finite()
                            && radiance[k] >= 0.0
                            && radiance[k] <= e_toa[k] * (p_max + 1.0),
                        "case {case}: radiance {radiance:?} beyond E·(p_max + 1), p_max {p_max}, sun zenith {zenith}, altitude {altitude}, view {i}",
                    );
                }
            }
        }
    }
}

/// The zenith's luminance and the sky's illuminance from the ground under a sun at
/// `elevation_deg`.
fn zenith_and_sky(sky: &Bruneton4d, elevation_deg: f64) -> (f64, f64) {
    let model = &sky.model;
    let n = model.channels();
    let nm = model.wavelengths.nm();
    let observer = Vec3::new(0.0, 0.0, model.bottom_radius_m + 2.0);
    let zenith = (90.0 - elevation_deg).to_radians();
    let light = Light::sun(model, direction_from_zenith_azimuth(zenith, 0.0), false);
    let view = sky.view(observer, &light);
    let (mut radiance, mut t) = (vec![0.0; n], vec![0.0; n]);
    view.sky_radiance(Vec3::Z, Shadow::None, &mut radiance, &mut t);
    let (mut direct, mut diffuse) = (vec![0.0; n], vec![0.0; n]);
    view.sun_and_sky_irradiance(observer, Vec3::Z, &mut direct, &mut diffuse);
    (
        luminance_from_spectrum(nm, &radiance),
        luminance_from_spectrum(nm, &diffuse),
    )
}

#[test]
fn the_twilight_falls_on_below_the_tables_lowest_sun() {
    // Tables that end at −12° (Bruneton 2017's), so the fall below them is exercised
    // between −12° and −30°, and checked against tables that reach −18°.
    for lowest in [-12.0, -18.0] {
        let mut atmosphere = Atmosphere::earth();
        atmosphere.min_sun_elevation_deg = lowest;
        let sky = small_tables(&atmosphere);
        let mut last = (f64::INFINITY, f64::INFINITY);
        for step in 0..=48 {
            let elevation = -6.0 - 0.5 * step as f64;
            let (zenith, illuminance) = zenith_and_sky(&sky, elevation);
            assert!(
                zenith > 0.0 && zenith < last.0 && illuminance > 0.0 && illuminance < last.1,
                "tables to {lowest}°, sun {elevation}°: zenith {zenith:.3e} cd/m² (before {:.3e}), sky {illuminance:.3e} lx (before {:.3e})",
                last.0,
                last.1
            );
            last = (zenith, illuminance);
        }
        // Far below, nothing left worth a pixel: under 10⁻⁶ of the zenith at −6°.
        let (deep, _) = zenith_and_sky(&sky, -40.0);
        assert!(deep < 1e-6 * zenith_and_sky(&sky, -6.0).0, "{deep:e}");
    }
}

#[test]
fn a_shell_the_quadratures_cannot_resolve_or_too_thick_for_its_air_is_refused() {
    let mut a = Atmosphere::earth();
    a.top_radius_m = 1e12;
    let e = a.validate().unwrap_err().to_string();
    assert!(e.contains("top_radius_m") && e.contains("'mie'"), "{e}");
    // Titan's size with Earth's air under a 600 km top: the 1.2 km haze is 500 times
    // thinner than the shell.
    a.bottom_radius_m = 2_575e3;
    a.top_radius_m = 3_175e3;
    let e = a.validate().unwrap_err().to_string();
    assert!(e.contains("at most bottom_radius_m + 200"), "{e}");
    // Without the haze, refused for the air: 71 scale heights, the orders gain energy.
    a.constituents.retain(|c| c.name != "mie");
    let e = a.validate().unwrap_err().to_string();
    assert!(
        e.contains("20 × the thickest") && e.contains("'rayleigh'"),
        "{e}"
    );
    // 160 km (19 scale heights) is accepted.
    let mut b = Atmosphere::earth();
    b.top_radius_m = b.bottom_radius_m + 160e3;
    b.validate().unwrap();
}

#[test]
fn nothing_comes_through_an_ozone_layer_of_opaque_optical_depth() {
    // 10¹² DU: τ ≈ 10⁶ at 440 nm, capped in the tables at 104; a difference of capped depths
    // gave e⁻⁴ through the layer and a sky of 0.9 W·m⁻²·nm⁻¹ with the sun at 10⁻⁴⁵.
    let sky = small_tables(&random_earth(&mut Rng(0), 0));
    let model = &sky.model;
    let observer = Vec3::new(0.0, 0.0, model.bottom_radius_m);
    let light = Light::sun(model, direction_from_zenith_azimuth(0.5, 0.0), false);
    let view = sky.view(observer, &light);
    let (mut radiance, mut t) = (vec![0.0; 3], vec![0.0; 3]);
    let dir = direction_from_zenith_azimuth(60f64.to_radians(), 0.0);
    view.sky_radiance(dir, Shadow::None, &mut radiance, &mut t);
    let (mut direct, mut diffuse) = (vec![0.0; 3], vec![0.0; 3]);
    view.sun_and_sky_irradiance(observer, Vec3::Z, &mut direct, &mut diffuse);
    for k in 0..3 {
        assert!(
            radiance[k] < 1e-30 && diffuse[k] < 1e-30,
            "{radiance:?} {diffuse:?}"
        );
    }
}

/// `hazy` with its haze's Ångström β set to `beta` (β = 0.2 is the preset: τ ≈ 0.36 at
/// 550 nm).
fn haze(beta: f64) -> Atmosphere {
    let mut a = Atmosphere::preset("hazy").unwrap();
    for c in &mut a.constituents {
        for coefficient in [&mut c.scattering, &mut c.absorption] {
            if let Coefficient::Angstrom { beta: b, .. } = coefficient {
                *b = beta;
            }
        }
    }
    a
}

/// Air too thick for the tables is refused with the reason (the reference takes it), air
/// that is thick but taken gets a note, the presets neither (`sky::bruneton4d::thickness`).
#[test]
fn air_too_thick_for_the_tables_is_refused_and_thick_air_noted() {
    use firmament::sky::bruneton4d::thickness;
    let resolve = |a: &Atmosphere| a.resolve(&Wavelengths::rgb()).unwrap();
    let thick = resolve(&haze(2.0));
    let config = TableConfig {
        sizes: TableSizes::small(),
        ..Default::default()
    };
    let Err(e) = Bruneton4d::compute(thick.clone(), &config) else {
        panic!("a haze of τ_s ≈ 4.3 was taken");
    };
    let e = e.to_string();
    assert!(
        e.contains("scattering optical depth") && e.contains("--method reference"),
        "{e}"
    );
    // The reference still answers.
    let settings = firmament::reference::ReferenceSettings::with_samples(64);
    let observer = Vec3::new(0.0, 0.0, thick.bottom_radius_m + 1.0);
    let r = firmament::reference::sky_radiance(&thick, observer, Vec3::Z, Vec3::Z, &settings);
    assert!(r.radiance.iter().all(|v| v.is_finite() && *v > 0.0));
    assert!(thickness::note(&resolve(&haze(0.5))).is_some());
    assert!(thickness::note(&resolve(&Atmosphere::earth())).is_none());
    assert!(small_tables(&haze(0.5)).model.channels() == 3);
}

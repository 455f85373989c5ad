//! Helpers shared by the library's integration tests: the small `earth` tables, one ray
//! through the render loop, and
//! an independent quadrature of single scattering to test the tables against.

#![allow(dead_code)] // each test file uses its own part

use std::sync::OnceLock;

use firmament::atmosphere::{Atmosphere, Model};
use firmament::math::sphere::distance_to_top_atmosphere_boundary;
use firmament::math::Vec3;
use firmament::render::{ShadeScratch, Shader};
use firmament::scene::{Ray, Scene};
use firmament::sky::bruneton4d::{Bruneton4d, TableConfig, TableSizes};
use firmament::spectrum::Wavelengths;

/// The `earth` atmosphere in RGB with small tables of `orders` scattering orders (and the
/// geometric tail), computed.
pub fn earth_small(orders: usize) -> Bruneton4d {
    let model = Atmosphere::earth().resolve(&Wavelengths::rgb()).unwrap();
    let config = TableConfig {
        sizes: TableSizes::small(),
        orders,
        ..Default::default()
    };
    Bruneton4d::compute(model, &config).unwrap()
}

/// [`earth_small`] with 4 orders, computed once per test binary.
pub fn sky() -> &'static Bruneton4d {
    static SKY: OnceLock<Bruneton4d> = OnceLock::new();
    SKY.get_or_init(|| earth_small(4))
}

/// The radiance (3 channels) `scene` renders along the ray from `origin` in direction `dir`.
pub fn shade(scene: &Scene, origin: Vec3, dir: Vec3) -> [f64; 3] {
    let mut l = [0.0; 3];
    Shader::new(scene, origin).unwrap().shade(
        &Ray { origin, dir },
        &mut ShadeScratch::default(),
        &mut l,
    );
    l
}

/// Single scattering of the sun (direction `sun`) towards `origin` along the ray in
/// direction `dir` (3 channels, no ground, to the top of the atmosphere), by the midpoint
/// rule: steps of `fine_step_m` over the first 200 km (where the light comes from), 200 m
/// beyond; the view transmittance accumulated step by step, the sun's from the model's
/// density columns. `step(m, dl)` receives each step's midpoint distance (m) and its
/// contribution per channel Σ_c ρ_c·β_c·P_c(ν)·T(0, m)·T_sun(m)·E·h.
pub fn single_scattering_steps(
    model: &Model,
    origin: Vec3,
    dir: Vec3,
    sun: Vec3,
    fine_step_m: f64,
    mut step: impl FnMut(f64, [f64; 3]),
) {
    let nu = dir.dot(sun);
    let r0 = origin.length();
    let length = distance_to_top_atmosphere_boundary(r0, dir.dot(origin) / r0, model.top_radius_m);
    let mut tau = [0.0f64; 3];
    let mut extinction = [0.0; 3];
    let mut s = 0.0;
    while s < length {
        let h = if s < 200e3 { fine_step_m } else { 200.0 }.min(length - s);
        let m = s + 0.5 * h;
        let p = origin + m * dir;
        let rp = p.length();
        let altitude = rp - model.bottom_radius_m;
        model.extinction_into(altitude, &mut extinction);
        let mu_s = p.dot(sun) / rp;
        let to_sun = distance_to_top_atmosphere_boundary(rp, mu_s, model.top_radius_m);
        let tau_sun = model.optical_depth_along_ray(rp, mu_s, to_sun);
        let mut dl = [0.0; 3];
        for k in 0..3 {
            let mut j = 0.0;
            for c in &model.constituents {
                j += c.density.density(altitude) * c.scattering[k] * c.phase.eval(nu);
            }
            let t = (-(tau[k] + 0.5 * h * extinction[k]) - tau_sun[k]).exp();
            dl[k] = h * j * t * model.solar_irradiance[k];
            tau[k] += h * extinction[k];
        }
        step(m, dl);
        s += h;
    }
}

/// The relative error of `view`'s sky radiance in direction `dir` (channel 0) against the
/// reference cut at `max_bounces` scattering events with `samples` paths, and the
/// reference's relative standard error: (table / reference − 1, σ / reference).
pub fn error_against_cut_reference(
    model: &Model,
    view: &dyn firmament::sky::SkyView,
    observer: Vec3,
    sun: Vec3,
    dir: Vec3,
    max_bounces: usize,
    samples: usize,
) -> (f64, f64) {
    let mut settings = firmament::reference::ReferenceSettings::with_samples(samples);
    settings.max_bounces = max_bounces;
    let reference = firmament::reference::sky_radiance(model, observer, dir, sun, &settings);
    let n = model.channels();
    let (mut l, mut t) = (vec![0.0; n], vec![0.0; n]);
    view.sky_radiance(dir, firmament::sky::Shadow::None, &mut l, &mut t);
    (
        l[0] / reference.radiance[0] - 1.0,
        reference.stderr[0] / reference.radiance[0],
    )
}

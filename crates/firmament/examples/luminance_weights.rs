//! What three (`rgb`) or sixteen (`spectral`) wavelengths get wrong in luminance and colour,
//! against 48-wavelength skies: per preset, the sky of the 4D tables (small sizes) at 360,
//! 370, …, 830 nm and at 365, 375, …, 835 nm (each holds the samples of one sparse grid, and
//! a wavelength's radiance does not depend on the others); the dense truth is the sky's factor
//! relative to the sun, L/E☉, interpolated onto 1 nm and integrated against the CIE 1931
//! functions times the full solar spectrum. Compared: the samples read as a piecewise-linear
//! spectrum (the old way), the generic fitted weights (`ColourMatrix::new`) and the model's
//! own (`Model::colour_matrix`). Prints a Markdown table for docs/accuracy.md.
//!
//! `cargo run --release -p firmament --example luminance_weights [-- PRESET ...]`

use firmament::atmosphere::{Atmosphere, Model};
use firmament::math::{direction_from_zenith_azimuth, Vec3};
use firmament::scene::light::Light;
use firmament::sky::bruneton4d::{Bruneton4d, TableConfig, TableSizes, Tables};
use firmament::sky::{Shadow, SkyMethod};
use firmament::spectrum::{self, ColourMatrix, Wavelengths};

/// One sky: the dense radiances and the solar samples of its grid.
struct Sky {
    sun_elevation_deg: f64,
    radiance: Vec<f64>,
    /// The sun's beam (irradiance through the air) rather than the sky.
    beam: bool,
}

/// The 48-wavelength skies of `atmosphere` on the grid starting at `first_nm`.
fn dense_skies(atmosphere: &Atmosphere, first_nm: f64) -> (Model, Vec<Sky>) {
    let nm: Vec<f64> = (0..48).map(|i| first_nm + 10.0 * i as f64).collect();
    let model = atmosphere
        .resolve(&Wavelengths::from_list(&nm).unwrap())
        .unwrap();
    let config = TableConfig {
        sizes: TableSizes::small(),
        ..TableConfig::default()
    };
    let tables = Tables::compute(&model, &config).unwrap();
    let sky = Bruneton4d::new(model.clone(), tables).unwrap();
    let n = nm.len();
    let mut out = Vec::new();
    for altitude_m in [0.0, 1_000.0, 10_000.0, 100_000.0] {
        let observer = Vec3::new(0.0, 0.0, model.bottom_radius_m + altitude_m);
        for sun_elevation_deg in [90.0, 60.0, 30.0, 10.0, 5.0, 2.0, 0.0, -3.0, -6.0] {
            let sun =
                direction_from_zenith_azimuth((90.0f64 - sun_elevation_deg).to_radians(), 0.0);
            let light = Light::sun(&model, sun, false);
            let view = sky.view(observer, &light);
            if sun_elevation_deg >= 0.0 {
                let (mut l, mut t) = (vec![0.0; n], vec![0.0; n]);
                view.sky_radiance(sun, Shadow::None, &mut l, &mut t);
                let beam: Vec<f64> = (t.iter().zip(&model.solar_irradiance))
                    .map(|(t, e)| t * e)
                    .collect();
                if beam.iter().all(|v| *v > 0.0) {
                    out.push(Sky {
                        sun_elevation_deg,
                        radiance: beam,
                        beam: true,
                    });
                }
            }
            for zenith_deg in (0..=12).map(|i| i as f64 * 15.0) {
                for azimuth_deg in (0..8).map(|i| i as f64 * 45.0) {
                    let dir = direction_from_zenith_azimuth(
                        zenith_deg.to_radians(),
                        azimuth_deg.to_radians(),
                    );
                    let (mut l, mut t) = (vec![0.0; n], vec![0.0; n]);
                    view.sky_radiance(dir, Shadow::None, &mut l, &mut t);
                    if l.iter().all(|v| *v > 0.0) {
                        out.push(Sky {
                            sun_elevation_deg,
                            radiance: l,
                            beam: false,
                        });
                    }
                }
            }
        }
    }
    (model, out)
}

/// The dense truth: L/E☉ interpolated onto 1 nm times the sun's full spectrum
/// (`Model::solar_shape`: ASTM G173 at full resolution, or the atmosphere's table).
fn truth(model: &Model, l: &[f64]) -> [f64; 3] {
    let nm = model.wavelengths.nm();
    let f: Vec<f64> = l
        .iter()
        .zip(&model.solar_irradiance)
        .map(|(l, e)| l / e)
        .collect();
    let sun = model.solar_shape();
    let mut xyz = [0.0; 3];
    for (lambda, e) in spectrum::weights::grid_nm().zip(&sun.on_grid) {
        let i = nm.partition_point(|&x| x <= lambda).clamp(1, nm.len() - 1);
        let t = ((lambda - nm[i - 1]) / (nm[i] - nm[i - 1])).clamp(0.0, 1.0);
        let fv = f[i - 1] + t * (f[i] - f[i - 1]);
        let cmf = spectrum::cie_1931_2deg(lambda);
        for c in 0..3 {
            xyz[c] += cmf[c] * e * fv * spectrum::LUMINOUS_EFFICACY_LM_W;
        }
    }
    xyz
}

/// CIE 1976 u′v′.
fn uv(xyz: [f64; 3]) -> [f64; 2] {
    let d = xyz[0] + 15.0 * xyz[1] + 3.0 * xyz[2];
    [4.0 * xyz[0] / d, 9.0 * xyz[1] / d]
}

/// median / p95 / max of |ΔY/Y| (%) and the median Δu′v′ (×10⁻³).
fn summary(mut e: Vec<f64>, mut duv: Vec<f64>) -> String {
    if e.is_empty() {
        return "–".into();
    }
    e.sort_by(f64::total_cmp);
    duv.sort_by(f64::total_cmp);
    let at = |v: &[f64], q: f64| v[((v.len() - 1) as f64 * q).round() as usize];
    format!(
        "{:.2} / {:.2} / {:.1} % · {:.1}",
        100.0 * at(&e, 0.5),
        100.0 * at(&e, 0.95),
        100.0 * e[e.len() - 1],
        1e3 * at(&duv, 0.5)
    )
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let presets: Vec<String> = if args.is_empty() {
        ["earth", "bruneton2008", "hazy", "mars", "frostbite2016"]
            .map(String::from)
            .to_vec()
    } else {
        args
    };
    println!("| preset | mode | method | sky, daylight (sun ≥ 5°): median / p95 / max ΔY · median Δu′v′ (10⁻³) | sky, twilight (sun 2° to −6°) | the sun's beam (sun 0° to 90°) |");
    println!("|---|---|---|---|---|---|");
    for preset in &presets {
        let atmosphere = Atmosphere::preset(preset).unwrap();
        for (mode, first_nm, sparse) in [
            ("rgb", 360.0, Wavelengths::rgb()),
            ("spectral", 365.0, Wavelengths::spectral()),
        ] {
            let (dense, skies) = dense_skies(&atmosphere, first_nm);
            let snm = sparse.nm();
            let index: Vec<usize> = snm
                .iter()
                .map(|l| dense.wavelengths.nm().iter().position(|d| d == l).unwrap())
                .collect();
            let sparse_model = atmosphere.resolve(&sparse).unwrap();
            let methods = [
                ("piecewise linear", ColourMatrix::piecewise_linear(snm)),
                ("generic fit", ColourMatrix::new(snm)),
                ("model fit", {
                    // The first call fits (later ones are cached): its cost, for BENCHMARKS.md.
                    let start = std::time::Instant::now();
                    let m = sparse_model.colour_matrix();
                    eprintln!(
                        "{preset} {mode}: Model::colour_matrix fitted in {:.1} ms",
                        1e3 * start.elapsed().as_secs_f64()
                    );
                    m
                }),
            ];
            for (name, matrix) in &methods {
                let mut errors: [(Vec<f64>, Vec<f64>); 3] = Default::default();
                for sky in &skies {
                    let samples: Vec<f64> = index.iter().map(|&i| sky.radiance[i]).collect();
                    let xyz = matrix.to_xyz(&samples);
                    let t = truth(&dense, &sky.radiance);
                    let set = &mut errors[if sky.beam {
                        2
                    } else {
                        usize::from(sky.sun_elevation_deg < 5.0)
                    }];
                    set.0.push((xyz[1] / t[1] - 1.0).abs());
                    let (a, b) = (uv(xyz), uv(t));
                    set.1
                        .push(((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt());
                }
                let [day, twilight, beam] = errors;
                println!(
                    "| {preset} | {mode} | {name} | {} | {} | {} |",
                    summary(day.0, day.1),
                    summary(twilight.0, twilight.1),
                    summary(beam.0, beam.1)
                );
            }
            let toa = |m: &ColourMatrix| m.to_xyz(&sparse_model.solar_irradiance)[1];
            eprintln!(
                "{preset} {mode}: solar illuminance {:.0} lx (piecewise linear {:.0}, dense truth {:.0})",
                toa(&methods[2].1),
                toa(&methods[0].1),
                truth(&dense, &dense.solar_irradiance)[1]
            );
        }
    }
}

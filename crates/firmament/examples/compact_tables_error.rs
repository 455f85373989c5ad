//! What storing the tables compactly costs: the sky's radiance, luminance, transmittance
//! and irradiance from f32 tables against the same tables written and read back with half
//! floats (`file::Encoding::Half`, the table cache's encoding), over a grid of observers,
//! suns and views; and, to justify keeping them f32, with the optical depth or the
//! irradiance table in half floats too. Prints a Markdown table for docs/accuracy.md.
//!
//! `cargo run --release -p firmament --example compact_tables_error [-- rgb] [-- PRESET]`

use firmament::atmosphere::Atmosphere;
use firmament::math::{direction_from_zenith_azimuth, Vec3};
use firmament::scene::light::Light;
use firmament::sky::bruneton4d::file::{self, Encoding};
use firmament::sky::bruneton4d::{compact, Bruneton4d, Table2, TableConfig, Tables};
use firmament::sky::{Shadow, SkyMethod};
use firmament::spectrum::{luminance_from_spectrum, Wavelengths};

/// `table` with every value through the compact encoding (one texel per `channels` values).
fn halved(table: &Table2) -> Table2 {
    let mut bytes = Vec::new();
    compact::encode(&table.data, table.channels, &mut bytes);
    Table2 {
        data: compact::decode(&bytes, table.data.len() / table.channels, table.channels),
        ..table.clone()
    }
}

/// Relative differences, summarised.
#[derive(Default)]
struct Errors(Vec<f64>);

impl Errors {
    fn push(&mut self, value: f64, reference: f64) {
        if reference > 0.0 {
            self.0.push(((value - reference) / reference).abs());
        }
    }
    fn summary(&mut self) -> String {
        self.0.sort_by(f64::total_cmp);
        let at = |q: f64| self.0[((self.0.len() - 1) as f64 * q).round() as usize];
        format!(
            "{:.1e} / {:.1e} / {:.1e}",
            at(0.5),
            at(0.99),
            self.0.last().copied().unwrap_or(0.0)
        )
    }
}

/// Luminance, radiance, transmittance and irradiance errors of `test` against `reference`.
fn compare(reference: &Bruneton4d, test: &Bruneton4d) -> [Errors; 5] {
    let model = &reference.model;
    let nm = model.wavelengths.nm();
    let n = nm.len();
    let mut errors: [Errors; 5] = Default::default();
    let [day, twilight, radiance, transmittance, irradiance] = &mut errors;
    for altitude_m in [0.0, 1_500.0, 10_000.0, 40_000.0, 200_000.0] {
        let observer = Vec3::new(0.0, 0.0, model.bottom_radius_m + altitude_m);
        for sun_elevation_deg in [60.0, 30.0, 10.0, 3.0, 0.0, -3.0, -6.0, -10.0] {
            let sun =
                direction_from_zenith_azimuth((90.0f64 - sun_elevation_deg).to_radians(), 0.0);
            let light = Light::sun(model, sun, false);
            let (a, b) = (
                reference.view(observer, &light),
                test.view(observer, &light),
            );
            let (mut ra, mut rb, mut ta, mut tb) =
                (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
            let (mut sa, mut sb) = (vec![0.0; n], vec![0.0; n]);
            a.sun_and_sky_irradiance(observer, Vec3::Z, &mut sa, &mut ra);
            b.sun_and_sky_irradiance(observer, Vec3::Z, &mut sb, &mut rb);
            for k in 0..n {
                irradiance.push(rb[k], ra[k]);
                irradiance.push(sb[k], sa[k]);
            }
            for zenith_deg in (0..=36).map(|i| i as f64 * 5.0) {
                for azimuth_deg in (0..12).map(|i| i as f64 * 30.0) {
                    let dir = direction_from_zenith_azimuth(
                        zenith_deg.to_radians(),
                        azimuth_deg.to_radians(),
                    );
                    a.sky_radiance(dir, Shadow::None, &mut ra, &mut ta);
                    b.sky_radiance(dir, Shadow::None, &mut rb, &mut tb);
                    let (la, lb) = (
                        luminance_from_spectrum(nm, &ra),
                        luminance_from_spectrum(nm, &rb),
                    );
                    if sun_elevation_deg >= 0.0 {
                        &mut *day
                    } else {
                        &mut *twilight
                    }
                    .push(lb, la);
                    for k in 0..n {
                        radiance.push(rb[k], ra[k]);
                        transmittance.push(tb[k], ta[k]);
                    }
                }
            }
        }
    }
    errors
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let wavelengths = if args.iter().any(|a| a == "rgb") {
        Wavelengths::rgb()
    } else {
        Wavelengths::spectral()
    };
    let preset = args
        .iter()
        .find(|a| *a != "rgb")
        .map_or("earth", |s| s.as_str());
    let model = Atmosphere::preset(preset)
        .unwrap()
        .resolve(&wavelengths)
        .unwrap();
    let config = TableConfig::default();
    let started = std::time::Instant::now();
    let tables = Tables::compute(&model, &config).unwrap();
    eprintln!("tables: {:.1} s", started.elapsed().as_secs_f64());
    let f32_bytes = file::to_bytes_encoded(&tables, Encoding::F32);
    let half_bytes = file::to_bytes_encoded(&tables, Encoding::Half);
    let half = file::from_bytes(&half_bytes, "(half)").unwrap();
    let mut depth_too = half.clone();
    depth_too.optical_depth = halved(&tables.optical_depth);
    depth_too.transmittance = depth_too.optical_depth.transmittance_of_optical_depth();
    let mut irradiance_too = half.clone();
    irradiance_too.irradiance = halved(&tables.irradiance);
    println!(
        "{preset}, {}, default sizes: {:.1} MB in f32, {:.1} MB compact\n",
        wavelengths.describe(),
        f32_bytes.len() as f64 / 1e6,
        half_bytes.len() as f64 / 1e6
    );
    println!("Relative errors against the f32 tables, median / p99 / max:\n");
    println!("| stored in half floats | luminance, sun ≥ 0° | luminance, sun −3 to −10° | radiance per wavelength | transmittance | irradiance (sun, sky) |");
    println!("|---|---|---|---|---|---|");
    let reference = Bruneton4d::new(model.clone(), tables).unwrap();
    for (name, test) in [
        ("4D tables half (the cache's)", half),
        ("… and optical depth half", depth_too),
        ("… and irradiance half", irradiance_too),
    ] {
        let test = Bruneton4d::new(model.clone(), test).unwrap();
        let mut e = compare(&reference, &test);
        println!(
            "| {name} | {} | {} | {} | {} | {} |",
            e[0].summary(),
            e[1].summary(),
            e[2].summary(),
            e[3].summary(),
            e[4].summary()
        );
    }
}

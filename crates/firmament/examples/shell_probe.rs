use firmament::atmosphere::Atmosphere;
use firmament::math::{direction_from_zenith_azimuth, Vec3};
use firmament::reference::{sky_radiance, ReferenceSettings};
use firmament::scene::light::Light;
use firmament::sky::bruneton4d::{Bruneton4d, TableConfig, TableSizes, Tables};
use firmament::sky::{Shadow, SkyMethod};
use firmament::spectrum::Wavelengths;

fn main() {
    let file = std::env::args().nth(1).unwrap();
    let alt: f64 = std::env::args()
        .nth(2)
        .map_or(1000.0, |s| s.parse().unwrap());
    let model = Atmosphere::from_file(std::path::Path::new(&file))
        .unwrap()
        .resolve(&Wavelengths::rgb())
        .unwrap();
    let base = TableSizes::default();
    let variants: Vec<(&str, TableSizes, usize)> = vec![
        ("default o1", base, 1),
        (
            "r×4 o1",
            TableSizes {
                scattering_r: base.scattering_r * 4,
                ..base
            },
            1,
        ),
        ("default o2", base, 2),
        (
            "r×4 o2",
            TableSizes {
                scattering_r: base.scattering_r * 4,
                irradiance_r: base.irradiance_r * 4,
                ..base
            },
            2,
        ),
        (
            "irr r×8 o2",
            TableSizes {
                irradiance_r: base.irradiance_r * 8,
                ..base
            },
            2,
        ),
        ("default o4", base, 4),
        (
            "r×4 o4",
            TableSizes {
                scattering_r: base.scattering_r * 4,
                irradiance_r: base.irradiance_r * 4,
                ..base
            },
            4,
        ),
    ];
    let skies: Vec<Bruneton4d> = variants
        .iter()
        .map(|(_, sizes, orders)| {
            let config = TableConfig {
                sizes: *sizes,
                orders: *orders,
                ..TableConfig::default()
            };
            Bruneton4d::new(model.clone(), Tables::compute(&model, &config).unwrap()).unwrap()
        })
        .collect();
    let observer = Vec3::new(0.0, 0.0, model.bottom_radius_m + alt);
    for sun_el in [10.0f64] {
        let sun = direction_from_zenith_azimuth((90.0 - sun_el).to_radians(), 0.0);
        let light = Light::sun(&model, sun, false);
        for el in [-3.0f64, 5.0] {
            let dir = direction_from_zenith_azimuth((90.0 - el).to_radians(), 30f64.to_radians());
            let mut single = ReferenceSettings::with_samples(20000);
            single.max_bounces = 1;
            let r1 = sky_radiance(&model, observer, dir, sun, &single);
            let rn = sky_radiance(
                &model,
                observer,
                dir,
                sun,
                &ReferenceSettings::with_samples(20000),
            );
            let mut two = ReferenceSettings::with_samples(20000);
            two.max_bounces = 2;
            let r2 = sky_radiance(&model, observer, dir, sun, &two);
            let mut line = format!(
                "sun {sun_el} view {el}: ref1 {:.4e}±{:.1}% refN {:.4e}±{:.1}% |",
                r1.radiance[1],
                100.0 * r1.stderr[1] / r1.radiance[1],
                rn.radiance[1],
                100.0 * rn.stderr[1] / rn.radiance[1]
            );
            for ((name, _, orders), sky) in variants.iter().zip(&skies) {
                let view = sky.view(observer, &light);
                let (mut l, mut t) = (vec![0.0; 3], vec![0.0; 3]);
                view.sky_radiance(dir, Shadow::None, &mut l, &mut t);
                let r = match orders {
                    1 => r1.radiance[1],
                    2 => r2.radiance[1],
                    _ => rn.radiance[1],
                };
                line += &format!(" {name} {:+.1}% |", (l[1] / r - 1.0) * 100.0);
            }
            println!("{line}");
        }
    }
}

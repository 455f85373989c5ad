//! A cloud layer seen from straight above: the vertical optical depth of each column over a
//! square around the observer's place, written as a grey PNG (white: τ ≥ 10), with the
//! fraction of the area whose column is cloudy (τ > 0.1) and the mean τ: what a layer's
//! coverage gives once the noise has carved it.
//!
//! `cargo run --release -p firmament --example cloud_field [KIND] [COVERAGE] [SIDE_KM] [OUT.png]`

use firmament::math::Vec3;
use firmament::scene::clouds::{cloud_media, CloudKind, CloudLayerConfig, CloudNoise};
use firmament::scene::clouds::{BASE_SHAPE_SIZE, EROSION_SIZE};
use firmament::scene::{Ray, Volume};

fn main() -> firmament::Result<()> {
    let args: Vec<String> = std::env::args().collect();
    let kind: CloudKind = serde_json::from_str(&format!(
        "\"{}\"",
        args.get(1).map_or("cumulus", |s| s.as_str())
    ))
    .expect("kind: cumulus, altostratus, cirrus or uniform");
    let coverage: Option<f64> = args.get(2).map(|s| s.parse().expect("coverage"));
    let side_m = args
        .get(3)
        .map_or(40.0, |s| s.parse::<f64>().expect("side (km)"))
        * 1000.0;
    let out = args.get(4).map_or("cloud_field.png", |s| s.as_str());
    let radius = 6_360_000.0;
    let config = CloudLayerConfig {
        coverage,
        ..CloudLayerConfig::of_kind(kind)
    };
    let cache = std::env::temp_dir().join("firmament-noise");
    let (noise, _) = CloudNoise::new([BASE_SHAPE_SIZE, EROSION_SIZE], Some(&cache))?;
    let media = cloud_media(&[config], radius, (0.0, 0.0), &noise)?;
    let medium = &media[0];
    let n = 400;
    let top = radius + medium.layer.params.top_m + 10.0;
    let mut pixels = vec![0u8; n * n];
    let (mut cloudy, mut sum) = (0usize, 0.0);
    for j in 0..n {
        for i in 0..n {
            let x = ((i as f64 + 0.5) / n as f64 - 0.5) * side_m;
            let y = (0.5 - (j as f64 + 0.5) / n as f64) * side_m;
            let origin = Vec3::new(x, y, top);
            let ray = Ray {
                origin,
                dir: -origin.normalize(),
            };
            let tau = medium.optical_depth(
                &ray,
                0.0,
                medium.layer.params.top_m - medium.layer.params.bottom_m + 20.0,
                0,
            );
            cloudy += (tau > 0.1) as usize;
            sum += tau;
            pixels[j * n + i] = (255.0 * (tau / 10.0).min(1.0).powf(0.5)) as u8;
        }
    }
    image::GrayImage::from_raw(n as u32, n as u32, pixels)
        .unwrap()
        .save(out)
        .expect("write the PNG");
    println!(
        "{kind:?} coverage {:.2}: cloudy columns (τ > 0.1) {:.1} %, mean τ {:.2}, over {:.0} km square; wrote {out}",
        medium.layer.params.coverage,
        100.0 * cloudy as f64 / (n * n) as f64,
        sum / (n * n) as f64,
        side_m / 1000.0
    );
    Ok(())
}

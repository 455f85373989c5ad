//! Time the default precomputation (quick look; the benchmark proper is `firmament bench`).
use firmament::atmosphere::Atmosphere;
use firmament::sky::bruneton4d::TableConfig;
use firmament::spectrum::Wavelengths;

fn main() {
    let wl = if std::env::args().any(|a| a == "spectral") {
        Wavelengths::spectral()
    } else {
        Wavelengths::rgb()
    };
    let model = Atmosphere::earth().resolve(&wl).unwrap();
    let t0 = std::time::Instant::now();
    let tables = firmament::sky::bruneton4d::precompute::precompute(
        &model,
        &TableConfig::default(),
        &|s, f| eprintln!("{:7.3}s {:5.1}% {s}", t0.elapsed().as_secs_f64(), f * 100.0),
        None,
    )
    .unwrap();
    eprintln!("total {:.3}s", t0.elapsed().as_secs_f64());
    for (i, m) in tables.order_means.iter().enumerate() {
        eprintln!("order {} mean {:?}", i + 1, m);
    }
}

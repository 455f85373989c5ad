//! Median GPU precomputation time over 5 runs (default table sizes, 4 orders, RGB), with the
//! adapter's name. `cargo run --release -p firmament-gpu --example gpu_precompute [preset]
//! [rgb|spectral|nm,nm,…]`.

use std::time::Instant;

use firmament::atmosphere::Atmosphere;
use firmament::sky::bruneton4d::TableConfig;
use firmament::spectrum::Wavelengths;
use firmament_gpu::GpuContext;
use firmament_gpu::Precomputer;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let preset = args.next().unwrap_or_else(|| "earth".into());
    let wavelengths = Wavelengths::parse(&args.next().unwrap_or_else(|| "rgb".into()))?;
    let model = Atmosphere::preset(&preset)?.resolve(&wavelengths)?;
    let config = TableConfig::default();
    let ctx = GpuContext::new()?;
    println!(
        "adapter: {} ({}, software: {})",
        ctx.adapter_name(),
        ctx.backend(),
        ctx.is_software()
    );
    let start = Instant::now();
    let precomputer = Precomputer::new(&ctx)?;
    println!(
        "pipeline creation: {:.1} ms",
        start.elapsed().as_secs_f64() * 1e3
    );
    // One warm-up run (driver caches, allocations), then 5 timed runs including readback.
    precomputer.run(&ctx, &model, &config)?;
    let mut times = Vec::new();
    for _ in 0..5 {
        let start = Instant::now();
        let tables = precomputer.run(&ctx, &model, &config)?;
        times.push(start.elapsed().as_secs_f64());
        std::hint::black_box(tables);
    }
    times.sort_by(f64::total_cmp);
    let s = config.sizes;
    println!(
        "precompute ({preset}, {} wavelengths, {} orders, scattering {}×{}×{}×{}): median {:.2} ms over {} runs (min {:.2} ms, max {:.2} ms)",
        model.channels(),
        config.orders,
        s.scattering_r,
        s.scattering_mu,
        s.scattering_mu_s,
        s.scattering_nu,
        times[times.len() / 2] * 1e3,
        times.len(),
        times[0] * 1e3,
        times[times.len() - 1] * 1e3
    );
    Ok(())
}

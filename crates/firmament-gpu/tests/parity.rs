//! CPU–GPU parity of the precomputed tables: every table texel by
//! texel within a relative tolerance over texels with non-negligible values (above 1e-4 of
//! the table's largest value), on whatever adapter is found (lavapipe in CI).

mod common;

use common::serial;
use firmament::atmosphere::{Atmosphere, Model};
use firmament::sky::bruneton4d::{MieStorage, Table4, TableConfig, TableSizes, Tables};
use firmament::spectrum::Wavelengths;
use firmament_gpu::{GpuContext, GpuError};

/// Texels below this fraction of the table maximum are not compared.
const NEGLIGIBLE: f64 = 1e-4;

/// The device, or None where there is none (saying that `test` is skipped).
fn context(test: &str) -> Option<&'static GpuContext> {
    common::gpu(test).map(|g| &g.ctx)
}

struct Stats {
    max_rel: f64,
    mean_rel: f64,
    compared: usize,
    /// Texel channels more than 1 % off.
    over_one_percent: usize,
}

fn compare(name: &str, cpu: &[f32], gpu: &[f32]) -> Stats {
    assert_eq!(cpu.len(), gpu.len(), "{name}: sizes differ");
    let max = cpu.iter().fold(0.0f64, |m, v| m.max(v.abs() as f64));
    let floor = max * NEGLIGIBLE;
    let (mut max_rel, mut sum, mut compared) = (0.0f64, 0.0, 0);
    let mut worst = 0;
    let mut over_one_percent = 0;
    for (i, (c, g)) in cpu.iter().zip(gpu).enumerate() {
        assert!(g.is_finite(), "{name}: non-finite GPU value at {i}");
        let c = *c as f64;
        if c.abs() <= floor {
            continue;
        }
        let rel = (*g as f64 - c).abs() / c.abs();
        if rel > max_rel {
            max_rel = rel;
            worst = i;
        }
        sum += rel;
        compared += 1;
        if rel > 1e-2 {
            over_one_percent += 1;
        }
    }
    let mean_rel = if compared > 0 {
        sum / compared as f64
    } else {
        0.0
    };
    eprintln!(
        "{name}: {compared}/{} texel channels compared, max rel {max_rel:.3e} (at {worst}: cpu {:e} gpu {:e}), mean rel {mean_rel:.3e}, {over_one_percent} over 1 %",
        cpu.len(),
        cpu.get(worst).copied().unwrap_or(0.0),
        gpu.get(worst).copied().unwrap_or(0.0)
    );
    Stats {
        max_rel,
        mean_rel,
        compared,
        over_one_percent,
    }
}

fn assert_within(name: &str, cpu: &[f32], gpu: &[f32], tolerance: f64) {
    let s = compare(name, cpu, gpu);
    assert_stats(name, &s, tolerance);
}

fn assert_stats(name: &str, s: &Stats, tolerance: f64) {
    assert!(s.compared > 0, "{name}: nothing to compare");
    assert!(
        s.max_rel <= tolerance,
        "{name}: max relative difference {:.3e} > {tolerance:e} (mean {:.3e}, {} texel channels over 1 %)",
        s.max_rel,
        s.mean_rel,
        s.over_one_percent
    );
}

/// A scattering table compared in two parts against `tolerance`: the sky rays exactly at
/// the horizon (the last μ row, which grazes the ground at its tangent point; its own
/// negligible-value floor, so its small values are not hidden by the table's maximum), and
/// every other texel. The horizon row was up to 9.6 % apart (blue, `earth`) while the
/// lookups interpolated T: there neighbouring transmittance texels differ by 10⁵–10⁶ and one
/// f32 ulp of μ moved the lookup ×10; with the optical depth interpolated it is ≤ 5e-4.
fn assert_scattering_within(name: &str, cpu: &Table4, gpu: &Table4, tolerance: f64) {
    let row = cpu.width() * cpu.channels;
    let horizon = |i: usize| (i / row) % cpu.nmu == cpu.nmu - 1;
    let split = |t: &Table4, keep: bool| -> Vec<f32> {
        t.data
            .iter()
            .enumerate()
            .map(|(i, v)| if horizon(i) == keep { *v } else { 0.0 })
            .collect()
    };
    let rest = compare(name, &split(cpu, false), &split(gpu, false));
    assert_stats(name, &rest, tolerance);
    let grazing = compare(
        &format!("{name}, horizon row"),
        &split(cpu, true),
        &split(gpu, true),
    );
    assert_stats(&format!("{name}, horizon row"), &grazing, tolerance);
}

fn model(preset: &str, wavelengths: Wavelengths) -> Model {
    Atmosphere::preset(preset)
        .unwrap()
        .resolve(&wavelengths)
        .unwrap()
}

fn both(test: &str, model: &Model, config: &TableConfig) -> Option<(Tables, Tables)> {
    let ctx = context(test)?;
    let _guard = serial();
    let cpu = Tables::compute(model, config).unwrap();
    let gpu = firmament_gpu::precompute(ctx, model, config).unwrap();
    Some((cpu, gpu))
}

fn check_layout(cpu: &Tables, gpu: &Tables) {
    assert_eq!(cpu.wavelengths_nm, gpu.wavelengths_nm);
    assert_eq!(cpu.atmosphere_hash, gpu.atmosphere_hash);
    assert_eq!(
        (
            cpu.transmittance.width,
            cpu.transmittance.height,
            cpu.transmittance.channels
        ),
        (
            gpu.transmittance.width,
            gpu.transmittance.height,
            gpu.transmittance.channels
        )
    );
    assert_eq!(
        (
            cpu.irradiance.width,
            cpu.irradiance.height,
            cpu.irradiance.channels
        ),
        (
            gpu.irradiance.width,
            gpu.irradiance.height,
            gpu.irradiance.channels
        )
    );
    assert_eq!(
        (
            cpu.single_rayleigh.nr,
            cpu.single_rayleigh.nmu,
            cpu.single_rayleigh.nmu_s,
            cpu.single_rayleigh.nnu,
            cpu.single_rayleigh.channels
        ),
        (
            gpu.single_rayleigh.nr,
            gpu.single_rayleigh.nmu,
            gpu.single_rayleigh.nmu_s,
            gpu.single_rayleigh.nnu,
            gpu.single_rayleigh.channels
        )
    );
    assert_eq!(cpu.single_mie.channels, gpu.single_mie.channels);
    assert_eq!(
        (
            cpu.multiple.nr,
            cpu.multiple.nmu,
            cpu.multiple.nmu_s,
            cpu.multiple.nnu,
            cpu.multiple.channels
        ),
        (
            gpu.multiple.nr,
            gpu.multiple.nmu,
            gpu.multiple.nmu_s,
            gpu.multiple.nnu,
            gpu.multiple.channels
        )
    );
    assert_eq!(cpu.mie_ratio, gpu.mie_ratio);
    assert_eq!(cpu.order_means.len(), gpu.order_means.len());
}

fn check_order_means(cpu: &Tables, gpu: &Tables, tolerance: f64) {
    for (o, (c, g)) in cpu.order_means.iter().zip(&gpu.order_means).enumerate() {
        for (k, (c, g)) in c.iter().zip(g).enumerate() {
            let rel = (g - c).abs() / c.abs().max(1e-30);
            eprintln!(
                "order {} mean, channel {k}: cpu {c:e} gpu {g:e} rel {rel:.2e}",
                o + 1
            );
            assert!(
                rel <= tolerance,
                "order {} mean channel {k}: {rel:e}",
                o + 1
            );
        }
    }
}

#[test]
fn transmittance_and_single_scattering_match_the_cpu() {
    let model = model("earth", Wavelengths::rgb());
    let config = TableConfig {
        sizes: TableSizes::small(),
        orders: 1,
        mie: MieStorage::Separate,
        order_tail: true,
    };
    let Some((cpu, gpu)) = both(
        "transmittance_and_single_scattering_match_the_cpu",
        &model,
        &config,
    ) else {
        return;
    };
    check_layout(&cpu, &gpu);
    assert_within(
        "transmittance",
        &cpu.transmittance.data,
        &gpu.transmittance.data,
        1e-3,
    );
    assert_scattering_within(
        "single rayleigh",
        &cpu.single_rayleigh,
        &gpu.single_rayleigh,
        1e-2,
    );
    assert_scattering_within("single mie", &cpu.single_mie, &gpu.single_mie, 1e-2);
    // Orders = 1: no indirect irradiance and no multiple scattering on either side.
    assert!(gpu.irradiance.data.iter().all(|&v| v == 0.0));
    assert!(gpu.multiple.data.iter().all(|&v| v == 0.0));
    check_order_means(&cpu, &gpu, 1e-2);
}

#[test]
fn all_orders_match_the_cpu() {
    let model = model("earth", Wavelengths::rgb());
    let config = TableConfig {
        sizes: TableSizes::small(),
        orders: 4,
        mie: MieStorage::Separate,
        order_tail: true,
    };
    let Some((cpu, gpu)) = both("all_orders_match_the_cpu", &model, &config) else {
        return;
    };
    check_layout(&cpu, &gpu);
    assert_within(
        "transmittance",
        &cpu.transmittance.data,
        &gpu.transmittance.data,
        1e-3,
    );
    assert_within(
        "irradiance (orders 1-3 + tail)",
        &cpu.irradiance.data,
        &gpu.irradiance.data,
        1e-2,
    );
    assert_scattering_within(
        "single rayleigh",
        &cpu.single_rayleigh,
        &gpu.single_rayleigh,
        1e-2,
    );
    assert_scattering_within(
        "multiple (orders 2-4 + tail)",
        &cpu.multiple,
        &gpu.multiple,
        1e-2,
    );
    assert_scattering_within("single mie", &cpu.single_mie, &gpu.single_mie, 1e-2);
    check_order_means(&cpu, &gpu, 1e-2);
}

/// Another phase function (Cornette–Shanks), five wavelengths (two channel groups, three
/// padding lanes) and the red-only Mie storage.
#[test]
fn channel_groups_and_red_only_mie_match_the_cpu() {
    let model = model(
        "bruneton2008",
        Wavelengths::from_list(&[680.0, 550.0, 440.0, 400.0, 600.0]).unwrap(),
    );
    let config = TableConfig {
        sizes: TableSizes::small(),
        orders: 2,
        mie: MieStorage::RedOnly,
        order_tail: true,
    };
    let Some((cpu, gpu)) = both(
        "channel_groups_and_red_only_mie_match_the_cpu",
        &model,
        &config,
    ) else {
        return;
    };
    check_layout(&cpu, &gpu);
    assert_within(
        "transmittance",
        &cpu.transmittance.data,
        &gpu.transmittance.data,
        1e-3,
    );
    assert_within(
        "irradiance",
        &cpu.irradiance.data,
        &gpu.irradiance.data,
        1e-2,
    );
    assert_scattering_within(
        "single molecular",
        &cpu.single_rayleigh,
        &gpu.single_rayleigh,
        1e-2,
    );
    assert_scattering_within("multiple (order 2)", &cpu.multiple, &gpu.multiple, 1e-2);
    assert_scattering_within(
        "single mie (red only)",
        &cpu.single_mie,
        &gpu.single_mie,
        1e-2,
    );
    check_order_means(&cpu, &gpu, 1e-2);
}

#[test]
fn tables_beyond_the_device_limits_are_refused() {
    let Some(ctx) = context("tables_beyond_the_device_limits_are_refused") else {
        return;
    };
    let _guard = serial();
    // 64 wavelengths and 64 Mi scattering texels: 16 GiB per table, valid for the CPU path.
    let nm: Vec<f64> = (0..64).map(|k| 380.0 + 6.0 * k as f64).collect();
    let model = model("earth", Wavelengths::from_list(&nm).unwrap());
    let sizes = TableSizes {
        scattering_r: 64,
        scattering_mu: 512,
        scattering_mu_s: 64,
        scattering_nu: 32,
        ..TableSizes::small()
    };
    let config = TableConfig {
        sizes,
        orders: 4,
        mie: MieStorage::Separate,
        order_tail: true,
    };
    config.validate().unwrap();
    match firmament_gpu::precompute(ctx, &model, &config) {
        Err(e @ GpuError::Limit { .. }) => {
            let m = e.to_string();
            eprintln!("{m}");
            assert!(
                m.contains("scattering table") && m.contains(ctx.adapter_name()),
                "{m}"
            );
        }
        other => panic!("expected a limit error, got {:?}", other.map(|_| ())),
    }
    // The context is still usable afterwards.
    let small = TableConfig {
        sizes: TableSizes::small(),
        orders: 1,
        mie: MieStorage::Separate,
        order_tail: true,
    };
    firmament_gpu::precompute(ctx, &self::model("earth", Wavelengths::rgb()), &small).unwrap();
}

#[test]
fn what_the_cpu_refuses_the_gpu_refuses() {
    let Some(ctx) = context("what_the_cpu_refuses_the_gpu_refuses") else {
        return;
    };
    let model = model("earth", Wavelengths::rgb());
    let bad_orders = TableConfig {
        sizes: TableSizes::small(),
        orders: 0,
        mie: MieStorage::Separate,
        order_tail: true,
    };
    let e = firmament_gpu::precompute(ctx, &model, &bad_orders).unwrap_err();
    assert!(
        matches!(e, GpuError::Invalid(_)) && e.to_string().contains("orders"),
        "{e}"
    );
    let odd_mu = TableConfig {
        sizes: TableSizes {
            scattering_mu: 63,
            ..TableSizes::small()
        },
        orders: 1,
        mie: MieStorage::Separate,
        order_tail: true,
    };
    let e = firmament_gpu::precompute(ctx, &model, &odd_mu).unwrap_err();
    assert!(e.to_string().contains("scattering_mu"), "{e}");
    let nm: Vec<f64> = (0..65).map(|k| 380.0 + 6.0 * k as f64).collect();
    let many = self::model("earth", Wavelengths::from_list(&nm).unwrap());
    let e = firmament_gpu::precompute(
        ctx,
        &many,
        &TableConfig {
            orders: 1,
            ..bad_orders
        },
    )
    .unwrap_err();
    assert!(e.to_string().contains("wavelengths"), "{e}");
}

/// The order tail capped by energy (`cap_by_energy`, and `order_tail_factors.wgsl`): under
/// a 160 km top with a white ground and a haze of τ ≈ 1.8 (Ångström β = 1, about the
/// thickest the tables accept) the tables' ratio of orders would take the sky's irradiance
/// above the sun outside the air at 680 nm; both sides stop it at the sun's. (With τ ≈ 0.9
/// it did so too until the view rays' samples were graded by optical depth
/// (`ray_grading.rs`): 50 even steps of up to 28 km through a 2 km haze overstated the
/// higher orders, q ≈ 0.95.)
#[test]
fn the_order_tail_is_capped_by_energy_as_on_the_cpu() {
    use firmament::atmosphere::Albedo;
    use firmament::medium::{Coefficient, DensityProfile};
    let mut a = Atmosphere::earth();
    a.top_radius_m = a.bottom_radius_m + 160e3;
    a.ground_albedo = Albedo::Grey(1.0);
    for c in &mut a.constituents {
        match &mut c.absorption {
            Coefficient::OzoneColumn { column_du } => *column_du = 0.0,
            Coefficient::Angstrom { beta, .. } => *beta = 1.0,
            _ => {}
        }
        if let Coefficient::Angstrom { beta, .. } = &mut c.scattering {
            *beta = 1.0;
            c.density = DensityProfile::exponential(2000.0);
        }
    }
    let model = a.resolve(&Wavelengths::rgb()).unwrap();
    let config = TableConfig {
        sizes: TableSizes::small(),
        orders: 4,
        mie: MieStorage::Separate,
        order_tail: true,
    };
    let Some((cpu, gpu)) = both(
        "the_order_tail_is_capped_by_energy_as_on_the_cpu",
        &model,
        &config,
    ) else {
        return;
    };
    let n = model.channels();
    for (name, t) in [("cpu", &cpu), ("gpu", &gpu)] {
        for k in 0..n {
            let max =
                (t.irradiance.data.iter().skip(k).step_by(n)).fold(0.0f32, |m, &v| m.max(v)) as f64;
            let sun = model.solar_irradiance[k];
            assert!(max <= sun * 1.001, "{name} channel {k}: {max} > {sun}");
            if k == 0 {
                // The cap is what holds it at 680 nm (1.49 W/m²/nm on both sides; 550 nm
                // reaches it on the CPU only, 1.64 on the GPU).
                assert!(
                    max > 0.99 * sun,
                    "{name}: {max} vs {sun}: the cap is not reached"
                );
            }
        }
    }
    // The two sides' tables are not compared here: in this shell their multiple scattering
    // disagrees with or without the tail (101 texel channels over 1 % with 32 μ_s samples,
    // irradiance within 3.3 %; with the 40 μ_s samples the capped irradiance differs by up
    // to ×2.3, mean 15 %), where `earth` agrees within 1 % (`all_orders_match_the_cpu`).
    // Open: docs/accuracy.md, "Energy conservation and what the tables refuse".
    let s = compare(
        "capped irradiance",
        &cpu.irradiance.data,
        &gpu.irradiance.data,
    );
    eprintln!(
        "capped irradiance, CPU against GPU: max {:.3}, mean {:.3}",
        s.max_rel, s.mean_rel
    );
}

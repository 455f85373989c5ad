//! Amortised table updates (Hillaire 2016 §2 "Our approach"): an atmosphere change stepped
//! over N frames ends with the tables of a direct precomputation, bit for bit, and every
//! frame before the swap reads the old set whole, every frame after it the new one.

use std::collections::hash_map::DefaultHasher;
use std::hash::{Hash, Hasher};
use std::sync::atomic::AtomicBool;
use std::sync::{Mutex, OnceLock};

use firmament::atmosphere::{Atmosphere, Model};
use firmament::math::Vec3;
use firmament::medium::{Coefficient, ConstituentKind};
use firmament::scene::{sun_direction, Light};
use firmament::sky::bruneton4d::amortised::RequestPolicy;
use firmament::sky::bruneton4d::precompute::{self, frame_schedule, PrecomputeJob};
use firmament::sky::bruneton4d::{
    AmortisedTables, Bruneton4d, MieStorage, TableConfig, TableSizes, Tables,
};
use firmament::sky::{Shadow, SkyMethod};
use firmament::spectrum::Wavelengths;
use firmament::Error;

/// `earth` with its aerosol load scaled by `factor` (both Ångström turbidities).
fn earth_aerosols(factor: f64) -> Model {
    let mut a = Atmosphere::earth();
    for c in &mut a.constituents {
        if c.kind == ConstituentKind::Aerosols {
            for coefficient in [&mut c.scattering, &mut c.absorption] {
                if let Coefficient::Angstrom { beta, .. } = coefficient {
                    *beta *= factor;
                }
            }
        }
    }
    a.resolve(&Wavelengths::rgb()).unwrap()
}

fn small() -> TableConfig {
    TableConfig {
        sizes: TableSizes::small(),
        orders: 4,
        mie: MieStorage::Separate,
        order_tail: true,
    }
}

/// Coarse tables for the tests of the request policies.
fn tiny() -> TableConfig {
    TableConfig {
        sizes: TableSizes {
            scattering_r: 8,
            scattering_mu: 32,
            scattering_mu_s: 16,
            ..TableSizes::small()
        },
        ..small()
    }
}

/// A hash of every value of the tables (the bits of the f32 and f64).
fn table_hash(t: &Tables) -> u64 {
    let mut h = DefaultHasher::new();
    for data in [
        &t.optical_depth.data,
        &t.transmittance.data,
        &t.irradiance.data,
        &t.single_rayleigh.data,
        &t.single_mie.data,
        &t.multiple.data,
    ] {
        data.len().hash(&mut h);
        data.iter().for_each(|v| v.to_bits().hash(&mut h));
    }
    for m in &t.order_means {
        m.iter().for_each(|v| v.to_bits().hash(&mut h));
    }
    h.finish()
}

/// Exact equality of every table.
fn assert_same_tables(a: &Tables, b: &Tables, what: &str) {
    assert_eq!(a.optical_depth, b.optical_depth, "{what}: optical depth");
    assert_eq!(a.transmittance, b.transmittance, "{what}: transmittance");
    assert_eq!(a.irradiance, b.irradiance, "{what}: irradiance");
    assert_eq!(
        a.single_rayleigh, b.single_rayleigh,
        "{what}: single Rayleigh"
    );
    assert_eq!(a.single_mie, b.single_mie, "{what}: single Mie");
    assert_eq!(a.multiple, b.multiple, "{what}: multiple scattering");
    assert_eq!(a.order_means, b.order_means, "{what}: order means");
    assert_eq!(a.atmosphere_hash, b.atmosphere_hash, "{what}: atmosphere");
}

/// The old (clear) and new (aerosols ×2) models with their direct small tables, computed
/// once for the tests that share them.
fn direct_small() -> &'static [(Model, Tables); 2] {
    static SETS: OnceLock<[(Model, Tables); 2]> = OnceLock::new();
    SETS.get_or_init(|| {
        [1.0, 2.0].map(|factor| {
            let model = earth_aerosols(factor);
            let tables = Tables::compute(&model, &small()).unwrap();
            (model, tables)
        })
    })
}

/// The sky 30° up towards a sun 60° from the zenith, from the ground.
fn sky_sample(sky: &dyn SkyMethod) -> Vec<f64> {
    let model = sky.model();
    let observer = Vec3::new(0.0, 0.0, model.bottom_radius_m + 10.0);
    let light = Light::sun(model, sun_direction(60.0, 180.0), true);
    let n = model.channels();
    let (mut radiance, mut transmittance) = (vec![0.0; n], vec![0.0; n]);
    sky.view(observer, &light).sky_radiance(
        sun_direction(60.0, 180.0),
        Shadow::None,
        &mut radiance,
        &mut transmittance,
    );
    radiance
}

#[test]
fn a_change_stepped_over_frames_ends_with_the_direct_tables_and_no_frame_sees_a_mix() {
    let [(old_model, old_tables), (new_model, new_tables)] = direct_small();
    let (old_hash, new_hash) = (table_hash(old_tables), table_hash(new_tables));
    assert_ne!(old_hash, new_hash, "the aerosol change changes the tables");
    let old_sky = sky_sample(&Bruneton4d::new(old_model.clone(), old_tables.clone()).unwrap());
    let new_sky = sky_sample(&Bruneton4d::new(new_model.clone(), new_tables.clone()).unwrap());

    let frames = 10;
    let front = Bruneton4d::new(old_model.clone(), old_tables.clone()).unwrap();
    let mut sky = AmortisedTables::new(front, frames).unwrap();
    sky.request(new_model.clone()).unwrap();
    let schedule = {
        let job = PrecomputeJob::new(new_model.clone(), &small()).unwrap();
        frame_schedule(job.units(), frames)
    };
    let held = sky.shared();
    for frame in 1..=frames + 2 {
        let report = sky.frame();
        let hash = table_hash(&sky.front().tables);
        if frame < frames {
            assert!(
                !report.swapped,
                "frame {frame}: swapped before the N-th frame"
            );
            assert_eq!(hash, old_hash, "frame {frame}: the old set, whole");
            assert_eq!(report.generation, 0);
            let p = report.running.expect("an update in flight");
            assert_eq!(p.frames_left, frames - frame);
            assert!(p.fraction > 0.0 && p.fraction < 1.0, "{p:?}");
        } else {
            assert_eq!(report.swapped, frame == frames, "frame {frame}");
            assert_eq!(hash, new_hash, "frame {frame}: the new set, whole");
            assert_eq!(report.generation, 1);
            assert!(report.running.is_none());
        }
        if frame <= frames {
            assert_eq!(
                report.units,
                schedule[frame - 1].len(),
                "frame {frame}: the planned units"
            );
        } else {
            assert_eq!(report.units, 0, "frame {frame}: idle");
        }
        // The views read the front: model and tables of one set.
        let want = if frame < frames { &old_sky } else { &new_sky };
        assert_eq!(&sky_sample(&sky), want, "frame {frame}: the view's set");
        assert_eq!(sky.model().hash, sky.front().tables.atmosphere_hash);
    }
    // Bit for bit the direct precomputation's tables.
    assert_same_tables(&sky.front().tables, new_tables, "after the swap");
    // A holder of the old set kept it whole.
    assert_eq!(table_hash(&held.tables), old_hash);
}

#[test]
fn any_grouping_of_the_units_gives_the_direct_tables() {
    let [_, (new_model, new_tables)] = direct_small();
    // Uneven steps, one unit at a time, then the rest at once.
    let mut job = PrecomputeJob::new(new_model.clone(), &small()).unwrap();
    for fraction in [0.013, 0.2, 0.21, 0.5, 0.77] {
        job.step_to(fraction);
        assert!(job.fraction() <= fraction + 1e-12, "{}", job.fraction());
    }
    for _ in 0..5 {
        job.run_unit();
    }
    let (_, tables) = job.finish();
    assert_same_tables(&tables, new_tables, "uneven steps");
    // The progress-reporting loop: stages in order, fractions from 0 to 1.
    let seen = Mutex::new(Vec::new());
    let tables = precompute::precompute(
        new_model,
        &small(),
        &|stage, f| seen.lock().unwrap().push((stage.to_string(), f)),
        None,
    )
    .unwrap();
    assert_same_tables(&tables, new_tables, "precompute");
    let seen = seen.into_inner().unwrap();
    assert_eq!(seen.first().unwrap(), &("transmittance".to_string(), 0.0));
    assert_eq!(seen.last().unwrap(), &("done".to_string(), 1.0));
    assert!(
        seen.windows(2).all(|w| w[0].1 <= w[1].1),
        "fractions increase"
    );
    assert!(seen
        .iter()
        .any(|(s, _)| s == "multiple scattering, order 4"));
}

#[test]
fn a_cancelled_precomputation_stops() {
    let cancel = AtomicBool::new(true);
    let e = precompute::precompute(&earth_aerosols(1.0), &tiny(), &|_, _| {}, Some(&cancel));
    assert!(matches!(e, Err(Error::Interrupted)), "{:?}", e.err());
}

#[test]
fn the_plan_gives_each_frame_about_one_nth_of_the_cost() {
    for wavelengths in [Wavelengths::rgb(), Wavelengths::spectral()] {
        let model = Atmosphere::earth().resolve(&wavelengths).unwrap();
        for config in [TableConfig::default(), small()] {
            let job = PrecomputeJob::new(model.clone(), &config).unwrap();
            let units = job.units();
            let total = job.total_weight();
            let largest = units.iter().map(|u| u.weight).fold(0.0, f64::max) / total;
            for frames in [10, 30] {
                let schedule = frame_schedule(units, frames);
                assert_eq!(schedule.len(), frames);
                assert_eq!(schedule.last().unwrap().end, units.len(), "ends at frame N");
                let worst = (schedule.iter())
                    .map(|r| units[r.clone()].iter().map(|u| u.weight).sum::<f64>() / total)
                    .fold(0.0, f64::max);
                println!(
                    "{} channels, {} r slices: {} units, largest {:.2} %; N = {frames}: worst frame {:.2} % (1/N = {:.2} %)",
                    model.channels(),
                    config.sizes.scattering_r,
                    units.len(),
                    100.0 * largest,
                    100.0 * worst,
                    100.0 / frames as f64
                );
                assert!(worst <= 1.0 / frames as f64 + largest + 1e-12);
                if config.sizes == TableSizes::default() {
                    // The one-unit granularity is a small part of a frame's share.
                    assert!(largest <= 0.25 / frames as f64, "largest unit {largest}");
                    assert!(worst <= 1.25 / frames as f64, "worst frame {worst}");
                }
            }
        }
    }
}

#[test]
fn a_request_while_an_update_runs_follows_the_policy() {
    let config = tiny();
    let [a, b, c] = [1.0, 2.0, 3.0].map(earth_aerosols);
    let frames = 4;
    // Queue: B finishes and is swapped in, then the newest request (C) runs; the
    // request for B's model in between was dropped.
    let mut sky = AmortisedTables::compute(a.clone(), &config, frames).unwrap();
    sky.request(b.clone()).unwrap();
    sky.frame();
    sky.request(a.clone()).unwrap();
    assert_eq!(sky.queued().map(|q| q.atmosphere_hash), Some(a.hash));
    sky.request(c.clone()).unwrap();
    assert_eq!(sky.queued().map(|q| q.atmosphere_hash), Some(c.hash));
    let mut fronts = Vec::new();
    for _ in 1..2 * frames {
        let r = sky.frame();
        fronts.push((r.atmosphere_hash, r.swapped));
    }
    // B's frames 2 to N, then C's 1 to N: (the front's model, swapped).
    let mut want = Vec::new();
    for k in 2..=frames {
        want.push(if k < frames {
            (a.hash, false)
        } else {
            (b.hash, true)
        });
    }
    for k in 1..=frames {
        want.push(if k < frames {
            (b.hash, false)
        } else {
            (c.hash, true)
        });
    }
    assert_eq!(fronts, want);
    assert_same_tables(
        &sky.front().tables,
        &Tables::compute(&c, &config).unwrap(),
        "queued update",
    );
    // Restart: the newest request starts over, and asking for the set in use drops the
    // update.
    let mut sky = AmortisedTables::compute(a.clone(), &config, frames)
        .unwrap()
        .with_policy(RequestPolicy::Restart);
    sky.request(b.clone()).unwrap();
    sky.frame();
    sky.request(a.clone()).unwrap();
    assert!(sky.progress().is_none(), "back to the set in use");
    sky.request(b.clone()).unwrap();
    sky.frame();
    sky.request(c.clone()).unwrap();
    let p = sky.progress().unwrap();
    assert_eq!(
        (p.atmosphere_hash, p.fraction, p.frames_left),
        (c.hash, 0.0, frames)
    );
    let swaps: Vec<bool> = (0..frames).map(|_| sky.frame().swapped).collect();
    assert_eq!(swaps, [false, false, false, true]);
    assert_eq!(sky.model().hash, c.hash);
    // The same model again starts nothing.
    sky.request(c.clone()).unwrap();
    assert!(sky.progress().is_none());
}

#[test]
fn requests_are_checked_at_once() {
    let config = tiny();
    let mut sky = AmortisedTables::compute(earth_aerosols(1.0), &config, 5).unwrap();
    let spectral = Atmosphere::earth()
        .resolve(&Wavelengths::spectral())
        .unwrap();
    let e = sky.request(spectral).unwrap_err();
    assert!(e.to_string().contains("wavelengths"), "{e}");
    // Air too thick for the tables: refused as `Tables::compute` refuses it.
    let thick = earth_aerosols(400.0);
    let direct = Tables::compute(&thick, &config).unwrap_err();
    let e = sky.request(thick).unwrap_err();
    assert_eq!(e.to_string(), direct.to_string());
    assert!(sky.progress().is_none());
    assert!(AmortisedTables::compute(earth_aerosols(1.0), &config, 0).is_err());
    assert!(sky.set_frames(0).is_err());
    // One frame: the whole update in the next frame.
    sky.set_frames(1).unwrap();
    sky.request(earth_aerosols(2.0)).unwrap();
    assert!(sky.frame().swapped);
}

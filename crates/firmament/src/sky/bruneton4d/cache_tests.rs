//! The cache's key (every input changes it) and its eviction (least recently used first,
//! within the limit, never the file just written).

use std::fs::{File, FileTimes};
use std::time::{Duration, SystemTime};

use super::*;
use crate::atmosphere::Atmosphere;
use crate::sky::bruneton4d::{MieStorage, TableSizes};
use crate::spectrum::Wavelengths;

fn earth(wavelengths: &Wavelengths) -> Model {
    Atmosphere::earth().resolve(wavelengths).unwrap()
}

#[test]
fn every_input_of_the_tables_changes_the_key() {
    let model = earth(&Wavelengths::rgb());
    let config = TableConfig::default();
    let base = key(file::VERSION, CODE_FINGERPRINT, &model, &config);
    assert_eq!(base, key(file::VERSION, CODE_FINGERPRINT, &model, &config));
    let mut keys = vec![("base", base)];
    let mut with_config = |name, f: &dyn Fn(&mut TableConfig)| {
        let mut c = config;
        f(&mut c);
        keys.push((name, key(file::VERSION, CODE_FINGERPRINT, &model, &c)));
    };
    with_config("transmittance_mu", &|c| c.sizes.transmittance_mu += 2);
    with_config("transmittance_r", &|c| c.sizes.transmittance_r += 2);
    with_config("scattering_r", &|c| c.sizes.scattering_r += 2);
    with_config("scattering_mu", &|c| c.sizes.scattering_mu += 2);
    with_config("scattering_mu_s", &|c| c.sizes.scattering_mu_s += 2);
    with_config("scattering_nu", &|c| c.sizes.scattering_nu += 2);
    with_config("irradiance_mu_s", &|c| c.sizes.irradiance_mu_s += 2);
    with_config("irradiance_r", &|c| c.sizes.irradiance_r += 2);
    with_config("small sizes", &|c| c.sizes = TableSizes::small());
    with_config("orders", &|c| c.orders = 5);
    with_config("mie", &|c| c.mie = MieStorage::RedOnly);
    with_config("order tail", &|c| c.order_tail = false);
    keys.push((
        "format version",
        key(file::VERSION + 1, CODE_FINGERPRINT, &model, &config),
    ));
    keys.push((
        "code",
        key(file::VERSION, "0123456789abcdef", &model, &config),
    ));
    let spectral = earth(&Wavelengths::spectral());
    keys.push((
        "wavelengths",
        key(file::VERSION, CODE_FINGERPRINT, &spectral, &config),
    ));
    let hazy = Atmosphere::preset("hazy")
        .unwrap()
        .resolve(&Wavelengths::rgb())
        .unwrap();
    keys.push((
        "atmosphere",
        key(file::VERSION, CODE_FINGERPRINT, &hazy, &config),
    ));
    let mut albedo = model.clone();
    albedo.ground_albedo[1] += 0.01;
    keys.push((
        "ground albedo",
        key(file::VERSION, CODE_FINGERPRINT, &albedo, &config),
    ));
    let lifted = Atmosphere::earth()
        .lifted(500.0, &Wavelengths::rgb())
        .unwrap()
        .resolve(&Wavelengths::rgb())
        .unwrap();
    keys.push((
        "ground lift",
        key(file::VERSION, CODE_FINGERPRINT, &lifted, &config),
    ));
    for (i, (a, ka)) in keys.iter().enumerate() {
        for (b, kb) in &keys[..i] {
            assert_ne!(ka, kb, "{a} and {b} share a key");
        }
    }
}

/// A fresh directory for one test.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!(
        "firmament-cache-test-{name}-{}",
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A file of `len` bytes last used `age_s` seconds ago.
fn file_used(dir: &Path, name: &str, len: usize, age_s: u64) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, vec![0u8; len]).unwrap();
    let t = SystemTime::now() - Duration::from_secs(age_s);
    File::options()
        .write(true)
        .open(&path)
        .unwrap()
        .set_times(FileTimes::new().set_accessed(t).set_modified(t))
        .unwrap();
    path
}

#[test]
fn eviction_removes_the_least_recently_used_beyond_the_limit() {
    let dir = scratch("evict");
    let oldest = file_used(&dir, "tables-1.firmlut", 400, 500);
    let older = file_used(&dir, "tables-2.firmlut", 400, 400);
    let recent = file_used(&dir, "tables-3.firmlut", 400, 10);
    let other = file_used(&dir, "notes.txt", 4000, 900);
    let stale = file_used(&dir, ".tables-4.firmlut.tmp-1", 400, 7200);
    let fresh_tmp = file_used(&dir, ".tables-5.firmlut.tmp-2", 400, 5);
    // Just written, but older than all by its times: kept anyway.
    let kept = file_used(&dir, "tables-6.firmlut", 400, 1000);
    let cache = TableCache {
        dir: dir.clone(),
        limit_bytes: 1000,
    };
    let mut removed = cache.evict(&kept);
    removed.sort();
    let mut expected = vec![oldest.clone(), older.clone(), stale.clone()];
    expected.sort();
    assert_eq!(removed, expected);
    for p in [&recent, &other, &fresh_tmp, &kept] {
        assert!(p.exists(), "{} removed", p.display());
    }
    // Within the limit: nothing more goes.
    assert!(cache.evict(&kept).is_empty());
    // A read marks a file as used: the older one by modification time is kept.
    let a = file_used(&dir, "tables-7.firmlut", 400, 300);
    let b = file_used(&dir, "tables-8.firmlut", 400, 200);
    File::open(&a)
        .unwrap()
        .set_times(FileTimes::new().set_accessed(SystemTime::now()))
        .unwrap();
    let removed = cache.evict(&recent);
    assert!(removed.contains(&b) && !removed.contains(&a), "{removed:?}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_store_is_read_back_and_a_corrupt_file_is_discarded() {
    let dir = scratch("store");
    let cache = TableCache {
        dir: dir.clone(),
        limit_bytes: 1 << 30,
    };
    let model = earth(&Wavelengths::rgb());
    let config = TableConfig {
        sizes: TableSizes {
            scattering_mu: 16,
            scattering_r: 4,
            scattering_mu_s: 8,
            scattering_nu: 4,
            ..TableSizes::small()
        },
        orders: 2,
        mie: MieStorage::Separate,
        order_tail: true,
    };
    assert!(matches!(
        cache.load(&model, &config),
        Loaded::Missing { .. }
    ));
    let tables = Tables::compute(&model, &config).unwrap();
    let stored = cache.store(&tables, &model, &config).unwrap();
    assert!(stored.evicted.is_empty());
    assert_eq!(stored.path, cache.path(&model, &config));
    match cache.load(&model, &config) {
        Loaded::Hit { tables: hit, path } => {
            assert_eq!(path, stored.path);
            assert_eq!(hit.multiple, stored.tables.multiple);
            assert_eq!(hit.optical_depth, tables.optical_depth);
        }
        other => panic!("{other:?}"),
    }
    // Another configuration is another file.
    let other = TableConfig {
        orders: 3,
        ..config
    };
    assert!(matches!(cache.load(&model, &other), Loaded::Missing { .. }));
    // A flipped byte: discarded and deleted.
    let mut bytes = std::fs::read(&stored.path).unwrap();
    let middle = bytes.len() / 2;
    bytes[middle] ^= 0x40;
    std::fs::write(&stored.path, &bytes).unwrap();
    match cache.load(&model, &config) {
        Loaded::Discarded { reason, .. } => assert!(reason.contains("checksum"), "{reason}"),
        other => panic!("{other:?}"),
    }
    assert!(!stored.path.exists());
    // A limit below one file: nothing written.
    let tiny = TableCache {
        dir: dir.clone(),
        limit_bytes: 1000,
    };
    assert!(tiny.store(&tables, &model, &config).is_err());
    assert!(!stored.path.exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

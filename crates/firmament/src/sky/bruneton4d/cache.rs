//! A directory of precomputed tables, so that a program asks for the same tables twice but
//! computes them once: files named by a key over everything that determines the tables,
//! stored compactly ([`Encoding::Half`]), written atomically, evicted oldest-used first
//! beyond a size limit, and read back only when whole and matching.
//!
//! It lives in the library, not the command-line program, because the key must name
//! everything the tables depend on, which only the library knows (the file format and
//! encoding, the model's resolved ground albedo and radii, the code that computes them:
//! [`CODE_FINGERPRINT`]), and because every program built on the library (an engine, a
//! script) then shares one cache with `firmament`. Where the cache is and how big it may
//! grow come from the environment ([`TableCache::from_env`]); whether to use it and what to
//! say about it are the caller's.
//!
//! Safety: a file is written to a temporary file in the same directory and renamed over its
//! name (`io::write_atomic`), so a reader sees a whole file or none, and two processes
//! computing the same tables at once both leave a valid file (the last rename wins). A file
//! that does not read, fails its checksum or holds other tables is deleted and reported
//! ([`Loaded::Discarded`]), never used.

use std::path::{Path, PathBuf};
use std::time::{Duration, SystemTime};

use super::file::{self, Encoding};
use super::{TableConfig, Tables};
use crate::atmosphere::model::fnv1a;
use crate::atmosphere::Model;
use crate::{Error, Result};

/// The environment variable naming the cache directory.
pub const DIR_VAR: &str = "FIRMAMENT_CACHE_DIR";
/// The environment variable giving the size limit, an integer number of MiB (0: nothing is
/// written).
pub const LIMIT_VAR: &str = "FIRMAMENT_CACHE_LIMIT_MB";
/// The default size limit, MiB: about twenty spectral table sets at the default sizes.
pub const DEFAULT_LIMIT_MB: u64 = 2048;
/// The extension of cached table files.
const EXTENSION: &str = "firmlut";
/// A temporary file older than this is left over from a killed process and removed.
const STALE_TEMPORARY: Duration = Duration::from_secs(3600);

/// FNV-1a of the library sources and data the tables depend on (`build.rs`).
pub const CODE_FINGERPRINT: &str = env!("FIRMAMENT_TABLES_FINGERPRINT");

/// A cache directory and its size limit.
#[derive(Clone, Debug, PartialEq)]
pub struct TableCache {
    /// Where the files are (created on the first write).
    pub dir: PathBuf,
    /// The most bytes its table files may take together after a write.
    pub limit_bytes: u64,
}

/// What [`TableCache::load`] found.
#[derive(Debug)]
pub enum Loaded {
    /// The tables, read from `path`.
    Hit {
        /// The tables.
        tables: Box<Tables>,
        /// Their file.
        path: PathBuf,
    },
    /// No file for these tables.
    Missing {
        /// Where they would be.
        path: PathBuf,
    },
    /// A file that could not be used (truncated, corrupt, other tables): it was deleted.
    Discarded {
        /// The file.
        path: PathBuf,
        /// Why it could not be used.
        reason: String,
    },
}

/// What [`TableCache::store`] did.
#[derive(Debug)]
pub struct Stored {
    /// The file written.
    pub path: PathBuf,
    /// The tables as the file holds them (half floats read back): what a later run reads,
    /// so that a run that computes and one that reads give the same numbers.
    pub tables: Box<Tables>,
    /// The older files removed to keep within the limit.
    pub evicted: Vec<PathBuf>,
}

impl TableCache {
    /// The user's cache: `$FIRMAMENT_CACHE_DIR` if set, else `$XDG_CACHE_HOME/firmament`,
    /// `$HOME/.cache/firmament` or `%LOCALAPPDATA%\firmament\cache`; None when none of these
    /// is set. The limit is `$FIRMAMENT_CACHE_LIMIT_MB` MiB (default [`DEFAULT_LIMIT_MB`]).
    pub fn from_env() -> Result<Option<TableCache>> {
        let var = |name: &str| std::env::var_os(name).filter(|v| !v.is_empty());
        let dir = var(DIR_VAR).map(PathBuf::from).or_else(|| {
            var("XDG_CACHE_HOME")
                .map(|d| PathBuf::from(d).join("firmament"))
                .or_else(|| var("HOME").map(|h| PathBuf::from(h).join(".cache/firmament")))
                .or_else(|| var("LOCALAPPDATA").map(|d| PathBuf::from(d).join("firmament/cache")))
        });
        let limit_mb = match std::env::var(LIMIT_VAR) {
            Err(_) => DEFAULT_LIMIT_MB,
            Ok(v) => v.trim().parse::<u64>().map_err(|_| {
                Error::invalid(
                    LIMIT_VAR,
                    format!("{v:?}"),
                    "an integer number of MiB ≥ 0 (0: write nothing)",
                )
            })?,
        };
        Ok(dir.map(|dir| TableCache {
            dir,
            limit_bytes: limit_mb.saturating_mul(1 << 20),
        }))
    }

    /// The file that holds the tables of `model` computed with `config`.
    pub fn path(&self, model: &Model, config: &TableConfig) -> PathBuf {
        self.dir.join(format!(
            "tables-{:016x}.{EXTENSION}",
            key(file::VERSION, CODE_FINGERPRINT, model, config)
        ))
    }

    /// The cached tables of `model` and `config`, if a whole, matching file holds them; a
    /// file that does not is deleted. A hit marks the file as used (its access time), so
    /// eviction takes the least recently used first.
    pub fn load(&self, model: &Model, config: &TableConfig) -> Loaded {
        let path = self.path(model, config);
        if !path.exists() {
            return Loaded::Missing { path };
        }
        let shown = path.display().to_string();
        let read = file::read(&path).and_then(|t| {
            t.check_matches(model, &shown)?;
            if t.config != *config {
                return Err(Error::TableFile {
                    path: shown.clone(),
                    reason: format!("computed with {:?}, not {config:?}", t.config),
                });
            }
            Ok(t)
        });
        match read {
            Ok(tables) => {
                if let Ok(f) = std::fs::File::open(&path) {
                    let _ = f.set_times(std::fs::FileTimes::new().set_accessed(SystemTime::now()));
                }
                Loaded::Hit {
                    tables: Box::new(tables),
                    path,
                }
            }
            Err(e) => {
                let _ = std::fs::remove_file(&path);
                let reason = match e {
                    Error::TableFile { reason, .. } | Error::File { reason, .. } => reason,
                    other => other.to_string(),
                };
                Loaded::Discarded { path, reason }
            }
        }
    }

    /// Write `tables` (of `model` and `config`) compactly, then evict the least recently
    /// used files beyond the limit. Refused when one file alone exceeds the limit.
    pub fn store(&self, tables: &Tables, model: &Model, config: &TableConfig) -> Result<Stored> {
        let path = self.path(model, config);
        let bytes = file::to_bytes_encoded(tables, Encoding::Half);
        if bytes.len() as u64 > self.limit_bytes {
            return Err(Error::File {
                path: path.display().to_string(),
                reason: format!(
                    "not cached: {} MiB, more than the cache's limit ({LIMIT_VAR} = {} MiB)",
                    bytes.len() >> 20,
                    self.limit_bytes >> 20
                ),
            });
        }
        let back = file::from_bytes(&bytes, &path.display().to_string())?;
        std::fs::create_dir_all(&self.dir).map_err(|e| Error::File {
            path: self.dir.display().to_string(),
            reason: format!("cannot create the cache directory: {e}"),
        })?;
        crate::io::write_atomic(&path, |out| {
            std::io::Write::write_all(out, &bytes).map_err(|e| crate::io::io_error(&path, &e, true))
        })?;
        let evicted = self.evict(&path);
        Ok(Stored {
            path,
            tables: Box::new(back),
            evicted,
        })
    }

    /// Remove the least recently used table files (last access or modification, whichever
    /// is later) until they take at most the limit together, never `keep`; and temporary
    /// files left by killed processes. Returns the files removed.
    pub fn evict(&self, keep: &Path) -> Vec<PathBuf> {
        let Ok(entries) = std::fs::read_dir(&self.dir) else {
            return Vec::new();
        };
        let now = SystemTime::now();
        let mut removed = Vec::new();
        let mut files: Vec<(SystemTime, u64, PathBuf)> = Vec::new();
        for entry in entries.flatten() {
            let path = entry.path();
            let Ok(meta) = entry.metadata() else { continue };
            if !meta.is_file() {
                continue;
            }
            let name = entry.file_name().to_string_lossy().into_owned();
            let modified = meta.modified().unwrap_or(now);
            if name.starts_with('.') && name.contains(&format!(".{EXTENSION}.tmp-")) {
                let age = now.duration_since(modified).unwrap_or_default();
                if age > STALE_TEMPORARY && std::fs::remove_file(&path).is_ok() {
                    removed.push(path);
                }
                continue;
            }
            if path.extension().is_some_and(|e| e == EXTENSION) {
                let used = meta.accessed().map_or(modified, |a| a.max(modified));
                files.push((used, meta.len(), path));
            }
        }
        let mut total: u64 = files.iter().map(|f| f.1).sum();
        files.sort();
        for (_, len, path) in files {
            if total <= self.limit_bytes {
                break;
            }
            if path != keep && std::fs::remove_file(&path).is_ok() {
                total -= len;
                removed.push(path);
            }
        }
        removed
    }
}

/// The key of the tables of `model` computed with `config` by the code `fingerprint`
/// into files of `version`: an FNV-1a hash of all of them.
///
/// `model.hash` covers the atmosphere's parameters (a lifted ground included: it changes
/// them) and the wavelengths; the resolved ground albedo and radii are added because a
/// caller may set them on the model after resolving it (a terrain's albedo).
fn key(version: u32, fingerprint: &str, model: &Model, config: &TableConfig) -> u64 {
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<u64>>();
    let text = format!(
        "v{version}|{fingerprint}|{encoding}|{hash:016x}|{nm:?}|{albedo:?}|{radii:?}|{config}",
        encoding = Encoding::Half.name(),
        hash = model.hash,
        nm = bits(model.wavelengths.nm()),
        albedo = bits(&model.ground_albedo),
        radii = bits(&[model.bottom_radius_m, model.top_radius_m]),
        config = serde_json::to_string(config).expect("the configuration serialises"),
    );
    fnv1a(text.as_bytes())
}

#[cfg(test)]
#[path = "cache_tests.rs"]
mod tests;

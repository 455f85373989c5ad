//! Atomic file writes: a temporary file next to the destination, renamed over it once
//! written and synced, removed on any failure or panic.

use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

use super::{file_error, io_error, parent_dir};
use crate::Result;

/// The temporary file's path: `.<name>.tmp-<pid>` next to `path`.
pub(crate) fn temp_path(path: &Path) -> Result<PathBuf> {
    let name = path
        .file_name()
        .ok_or_else(|| file_error(path, "cannot write: the path does not name a file"))?;
    let mut tmp_name = std::ffi::OsString::from(".");
    tmp_name.push(name);
    tmp_name.push(format!(".tmp-{}", std::process::id()));
    Ok(parent_dir(path).join(tmp_name))
}

/// Removes the temporary file on drop unless disarmed (covers errors and panics).
struct TempGuard {
    path: PathBuf,
    armed: bool,
}

impl Drop for TempGuard {
    fn drop(&mut self) {
        if self.armed {
            let _ = std::fs::remove_file(&self.path);
        }
    }
}

/// Writes `path` through a temporary file: `write` fills it, then it is flushed,
/// synced and renamed over `path`. On any failure the temporary is removed and
/// `path` is left untouched.
pub fn write_atomic<F>(path: &Path, write: F) -> Result<()>
where
    F: FnOnce(&mut BufWriter<File>) -> Result<()>,
{
    let tmp = temp_path(path)?;
    if path.is_dir() {
        return Err(file_error(path, "cannot write: the path is a directory"));
    }
    let file = File::create(&tmp).map_err(|e| io_error(path, &e, true))?;
    let mut guard = TempGuard {
        path: tmp.clone(),
        armed: true,
    };
    let mut writer = BufWriter::new(file);
    write(&mut writer)?;
    let file = writer
        .into_inner()
        .map_err(|e| io_error(path, e.error(), true))?;
    file.sync_all().map_err(|e| io_error(path, &e, true))?;
    drop(file);
    std::fs::rename(&tmp, path).map_err(|e| io_error(path, &e, true))?;
    guard.armed = false;
    Ok(())
}

//! JSON files: pretty JSON and a final newline, written atomically.

use crate::io::error::{IoError, Result};
use serde::Serialize;
use std::io::Write;
use std::path::{Path, PathBuf};

/// Write `value` to `path` as pretty JSON followed by a newline, creating the
/// parent folder. The text goes to `path.tmp` first and is renamed into place,
/// so a reader never sees a half-written file.
pub fn write_pretty<T: Serialize + ?Sized>(path: &Path, value: &T) -> Result<()> {
    let text = serde_json::to_string_pretty(value)
        .map_err(IoError::json("cannot encode as JSON", path))?;
    create_parent(path)?;
    let tmp = tmp_path(path);
    let write = || -> std::io::Result<()> {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(text.as_bytes())?;
        f.write_all(b"\n")?;
        f.sync_all()
    };
    write().map_err(IoError::file("writing", &tmp))?;
    std::fs::rename(&tmp, path).map_err(IoError::file("writing", path))
}

/// Create the folder holding `path` (if it names one).
pub fn create_parent(path: &Path) -> Result<()> {
    match path.parent().filter(|d| !d.as_os_str().is_empty()) {
        Some(dir) => std::fs::create_dir_all(dir).map_err(IoError::file("creating folder", dir)),
        None => Ok(()),
    }
}

/// `path` with ".tmp" appended to its file name.
fn tmp_path(path: &Path) -> PathBuf {
    let mut s = path.as_os_str().to_os_string();
    s.push(".tmp");
    PathBuf::from(s)
}

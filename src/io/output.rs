//! Output files written whole or not at all: [`Output`], the one way every
//! writer of knotrod (recordings, summaries, streams, maps, plots, reports,
//! exports) creates a file.
//!
//! The bytes go to `PATH.tmp` in the same folder, renamed over PATH when
//! committed (an atomic replace: a reader sees the old file or the new one,
//! never half of one). The temporary file is also the lock: it is held with
//! an exclusive `flock` while written, so a second writer of the same path
//! (another process, or this one) is refused at once, naming the path. The
//! lock goes with the process, so a killed run leaves no stale lock, at most
//! a stale `PATH.tmp` that the next writer reuses. A write that fails (a full
//! disk) leaves the file that was there as it was.

use crate::io::error::{IoError, Result};
use std::fs::{File, OpenOptions};
use std::io::{ErrorKind, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

/// A file being written: at `PATH.tmp` until [`Output::commit`] renames it
/// to PATH. Dropped uncommitted, it is removed and PATH is left as it was.
#[derive(Debug)]
pub struct Output {
    path: PathBuf,
    tmp: PathBuf,
    /// The locked temporary file; None once committed.
    file: Option<File>,
    /// The kind of the first write that failed (a full disk is reported as
    /// such whatever layer above saw it).
    failed: Option<ErrorKind>,
}

/// The error of `step` on `path` from the operating system's `e`: a full
/// device (or quota) is [`IoError::NoSpace`].
pub fn file_error(step: &'static str, path: &Path, e: std::io::Error) -> IoError {
    if no_space(e.kind()) {
        IoError::NoSpace { path: path.into() }
    } else {
        IoError::File {
            step,
            path: path.into(),
            source: e,
        }
    }
}

fn no_space(kind: ErrorKind) -> bool {
    matches!(kind, ErrorKind::StorageFull | ErrorKind::QuotaExceeded)
}

/// `path` with ".tmp" appended to its file name.
fn tmp_path(path: &Path) -> PathBuf {
    let mut s = path.as_os_str().to_os_string();
    s.push(".tmp");
    PathBuf::from(s)
}

/// Whether the open `file` is still the one at `path` (another writer may
/// have renamed or removed it between our open and our lock).
#[cfg(unix)]
fn still_at(file: &File, path: &Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    match (file.metadata(), std::fs::metadata(path)) {
        (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
        _ => false,
    }
}

#[cfg(not(unix))]
fn still_at(_: &File, path: &Path) -> bool {
    path.exists()
}

impl Output {
    /// Start writing `path` (its folder created if need be): refused if
    /// `path` is a folder or another writer holds it.
    pub fn create(path: &Path) -> Result<Self> {
        create_parent(path)?;
        if path.is_dir() {
            return Err(IoError::Refused {
                path: path.into(),
                why: "is a folder; name a file".into(),
            });
        }
        let tmp = tmp_path(path);
        // a few rounds at most: each retry follows a writer that just finished
        for _ in 0..100 {
            let file = OpenOptions::new()
                .write(true)
                .create(true)
                .truncate(false)
                .open(&tmp)
                .map_err(|e| file_error("creating", &tmp, e))?;
            match file.try_lock() {
                Ok(()) => {}
                Err(std::fs::TryLockError::WouldBlock) => {
                    return Err(IoError::Refused {
                        path: path.into(),
                        why: format!(
                            "another writer (another knotrod run?) is writing it \
                             (it holds {})",
                            tmp.display()
                        ),
                    });
                }
                Err(std::fs::TryLockError::Error(e)) => {
                    return Err(file_error("locking", &tmp, e));
                }
            }
            if still_at(&file, &tmp) {
                file.set_len(0)
                    .map_err(|e| file_error("creating", &tmp, e))?;
                return Ok(Output {
                    path: path.into(),
                    tmp,
                    file: Some(file),
                    failed: None,
                });
            }
        }
        Err(IoError::Refused {
            path: path.into(),
            why: "other writers keep replacing it".into(),
        })
    }

    /// The file it becomes.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The error of `step` on this output from `e`: a full disk as such
    /// when any write failed for want of space.
    pub fn error(&self, step: &'static str, e: std::io::Error) -> IoError {
        match self.failed {
            Some(k) if no_space(k) => IoError::NoSpace {
                path: self.path.clone(),
            },
            _ => file_error(step, &self.path, e),
        }
    }

    /// Whether a write failed for want of space.
    pub fn out_of_space(&self) -> bool {
        self.failed.is_some_and(no_space)
    }

    fn file(&mut self) -> std::io::Result<&mut File> {
        self.file
            .as_mut()
            .ok_or_else(|| std::io::Error::other("the output was committed already"))
    }

    /// Record the first failure of a write.
    fn note<T>(&mut self, r: std::io::Result<T>) -> std::io::Result<T> {
        if let Err(e) = &r {
            self.failed.get_or_insert(e.kind());
        }
        r
    }

    /// Sync the bytes and rename the file into place. Refused after a failed
    /// write: the file that was there stays.
    pub fn commit(mut self) -> Result<()> {
        if let Some(kind) = self.failed {
            return Err(self.error("writing", std::io::Error::from(kind)));
        }
        let r = self.file().and_then(|f| f.sync_all());
        self.note(r).map_err(|e| self.error("writing", e))?;
        // renamed while still locked: a writer waiting on the old name retries
        std::fs::rename(&self.tmp, &self.path).map_err(|e| file_error("writing", &self.path, e))?;
        self.file = None;
        Ok(())
    }
}

impl Output {
    /// Write `bytes` as the whole file and commit it.
    pub fn put(mut self, bytes: &[u8]) -> Result<()> {
        let r = self.write_all(bytes);
        r.map_err(|e| self.error("writing", e))?;
        self.commit()
    }
}

impl Write for Output {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        let r = self.file().and_then(|f| f.write(buf));
        self.note(r)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        let r = self.file().and_then(|f| f.flush());
        self.note(r)
    }
}

impl Seek for Output {
    fn seek(&mut self, pos: SeekFrom) -> std::io::Result<u64> {
        let r = self.file().and_then(|f| f.seek(pos));
        self.note(r)
    }
}

impl Drop for Output {
    fn drop(&mut self) {
        if self.file.is_some() {
            // removed while still locked (see `create`)
            let _ = std::fs::remove_file(&self.tmp);
        }
    }
}

/// Write `bytes` as the whole of `path`, atomically (see [`Output`]).
pub fn write_file(path: &Path, bytes: &[u8]) -> Result<()> {
    Output::create(path)?.put(bytes)
}

/// Create the folder holding `path` (if it names one).
pub fn create_parent(path: &Path) -> Result<()> {
    match path.parent().filter(|d| !d.as_os_str().is_empty()) {
        Some(dir) => std::fs::create_dir_all(dir).map_err(IoError::file("creating folder", dir)),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("knotrod-output-{name}-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    #[test]
    fn a_second_writer_is_refused_and_the_first_commits() {
        let d = dir("two");
        let path = d.join("a.json");
        std::fs::write(&path, "old").unwrap();
        let mut first = Output::create(&path).unwrap();
        let e = Output::create(&path).unwrap_err().to_string();
        assert!(
            e.contains(&path.display().to_string()) && e.contains("another writer"),
            "{e}"
        );
        first.write_all(b"new").unwrap();
        assert_eq!(
            std::fs::read_to_string(&path).unwrap(),
            "old",
            "replaced before commit"
        );
        first.commit().unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "new");
        assert!(!tmp_path(&path).exists());
        // the lock went with the first writer
        write_file(&path, b"third").unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "third");
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn an_uncommitted_output_leaves_the_old_file() {
        let d = dir("drop");
        let path = d.join("b.txt");
        std::fs::write(&path, "old").unwrap();
        let mut out = Output::create(&path).unwrap();
        out.write_all(b"half").unwrap();
        drop(out);
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "old");
        assert!(!tmp_path(&path).exists());
        // a stale temporary file (a killed run's) is reused, not a lock
        std::fs::write(tmp_path(&path), "stale").unwrap();
        write_file(&path, b"new").unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "new");
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn a_folder_is_refused_by_name() {
        let d = dir("folder");
        let e = write_file(&d, b"x").unwrap_err().to_string();
        assert!(
            e.contains(&d.display().to_string()) && e.contains("folder"),
            "{e}"
        );
        std::fs::remove_dir_all(&d).unwrap();
    }
}

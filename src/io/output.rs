//! Output files written whole or not at all, and streams written through:
//! [`Output`], the one way every writer of knotrod (recordings, summaries,
//! streams, maps, plots, reports, exports) creates a file.
//!
//! A regular file, or a path where nothing is yet, is replaced: the bytes go
//! to `TARGET.tmp` in the target's folder, renamed over TARGET when committed
//! (an atomic replace: a reader sees the old file or the new one, never half
//! of one). TARGET is the path with its symbolic links followed, so a link is
//! kept and its target rewritten, as `cp` and editors do. The temporary file
//! is also the lock: it is held with an exclusive `flock` while written, so a
//! second writer of the same file (another process, or this one) is refused
//! at once, naming the path. The lock goes with the process, so a killed run
//! leaves no stale lock, at most a stale `TARGET.tmp` that the next writer
//! reuses. A write that fails (a full disk) leaves the file that was there as
//! it was.
//!
//! Anything else, a FIFO, a character device or a socket, and `-` (standard
//! output), is written directly as the bytes come, never renamed over: a
//! device node stays a device, a reader of a FIFO gets the whole output.

use crate::io::error::{IoError, Result};
use std::fs::{File, OpenOptions};
use std::io::{ErrorKind, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

/// A file being written: replaced when committed, or a stream written
/// through (see the module's text). Dropped uncommitted, a replaced file is
/// left as it was.
#[derive(Debug)]
pub struct Output {
    /// The path as given (named in messages).
    path: PathBuf,
    sink: Sink,
    /// The kind of the first write that failed (a full disk is reported as
    /// such whatever layer above saw it).
    failed: Option<ErrorKind>,
}

/// Where an output's bytes go.
#[derive(Debug)]
enum Sink {
    /// Written to the locked `tmp` beside `target`, renamed over it when
    /// committed; `file` is None once committed.
    Replace {
        target: PathBuf,
        tmp: PathBuf,
        file: Option<File>,
    },
    /// Written directly; `position` counts the bytes written (the one
    /// question a stream can answer about seeking).
    Stream { to: StreamTo, position: u64 },
}

/// What a stream writes to.
#[derive(Debug)]
enum StreamTo {
    Stdout(std::io::Stdout),
    /// A FIFO, character device or socket, opened for writing.
    Node(File),
}

/// The error of `step` on `path` from the operating system's `e`: a full
/// device (or quota) is [`IoError::NoSpace`].
pub fn file_error(step: &'static str, path: &Path, e: std::io::Error) -> IoError {
    if no_space(e.kind()) {
        IoError::NoSpace {
            path: path.into(),
            streamed: false,
        }
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

/// Symbolic links followed at most this many times (as Linux's ELOOP).
const MAX_LINKS: usize = 40;

/// `path` with its symbolic links followed (a link's relative target read
/// from the link's folder) to what is not a link: a file, a node, a folder
/// or nothing yet.
fn follow_links(path: &Path) -> Result<PathBuf> {
    let mut p = path.to_path_buf();
    for _ in 0..MAX_LINKS {
        match std::fs::symlink_metadata(&p) {
            Ok(m) if m.file_type().is_symlink() => {
                let link =
                    std::fs::read_link(&p).map_err(|e| file_error("following the link", &p, e))?;
                p = match p.parent() {
                    Some(dir) if link.is_relative() => dir.join(link),
                    _ => link,
                };
            }
            _ => return Ok(p),
        }
    }
    Err(IoError::Refused {
        path: path.into(),
        why: format!("its symbolic links loop (or chain more than {MAX_LINKS})"),
    })
}

/// How [`Output::create`] would write `path`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OutputKind {
    /// Replaced whole (a regular file, or nothing yet).
    File,
    /// Written through: `-`, a FIFO, a character device or a socket. Files
    /// named after it (a summary's stream of equilibria, its diagrams) are
    /// not written.
    Stream,
}

/// Whether `path` names standard output (`-`).
pub fn is_standard_output(path: &Path) -> bool {
    path.as_os_str() == "-"
}

/// How `path` would be written (symbolic links followed).
pub fn output_kind(path: &Path) -> OutputKind {
    if is_standard_output(path) {
        return OutputKind::Stream;
    }
    match follow_links(path).map(std::fs::metadata) {
        Ok(Ok(m)) if !m.is_file() && !m.is_dir() => OutputKind::Stream,
        _ => OutputKind::File,
    }
}

impl Output {
    /// Start writing `path` (its folder created if need be): `-` is standard
    /// output; refused if `path` is a folder or another writer holds it.
    pub fn create(path: &Path) -> Result<Self> {
        if is_standard_output(path) {
            return Ok(Self::stream(path, StreamTo::Stdout(std::io::stdout())));
        }
        let target = follow_links(path)?;
        match std::fs::metadata(&target) {
            Ok(m) if m.is_dir() => Err(IoError::Refused {
                path: path.into(),
                why: "is a folder; name a file".into(),
            }),
            Ok(m) if !m.is_file() => {
                // opening a FIFO waits for its reader, as a shell's `>` does
                let node = OpenOptions::new()
                    .write(true)
                    .open(&target)
                    .map_err(|e| file_error("opening", path, e))?;
                Ok(Self::stream(path, StreamTo::Node(node)))
            }
            _ => Self::replace(path, target),
        }
    }

    fn stream(path: &Path, to: StreamTo) -> Self {
        Output {
            path: path.into(),
            sink: Sink::Stream { to, position: 0 },
            failed: None,
        }
    }

    /// A locked temporary file beside `target`, to replace it.
    fn replace(path: &Path, target: PathBuf) -> Result<Self> {
        create_parent(&target)?;
        let tmp = tmp_path(&target);
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
                    sink: Sink::Replace {
                        target,
                        tmp,
                        file: Some(file),
                    },
                    failed: None,
                });
            }
        }
        Err(IoError::Refused {
            path: path.into(),
            why: "other writers keep replacing it".into(),
        })
    }

    /// The file it becomes, as given.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Whether it is written through (see [`OutputKind::Stream`]).
    pub fn is_stream(&self) -> bool {
        matches!(self.sink, Sink::Stream { .. })
    }

    /// The error of `step` on this output from `e`: a full disk as such
    /// when any write failed for want of space.
    pub fn error(&self, step: &'static str, e: std::io::Error) -> IoError {
        match self.failed {
            Some(k) if no_space(k) => IoError::NoSpace {
                path: self.path.clone(),
                streamed: self.is_stream(),
            },
            _ => file_error(step, &self.path, e),
        }
    }

    /// Whether a write failed for want of space.
    pub fn out_of_space(&self) -> bool {
        self.failed.is_some_and(no_space)
    }

    fn writer(&mut self) -> std::io::Result<&mut dyn Write> {
        match &mut self.sink {
            Sink::Replace { file: Some(f), .. } => Ok(f),
            Sink::Replace { file: None, .. } => {
                Err(std::io::Error::other("the output was committed already"))
            }
            Sink::Stream {
                to: StreamTo::Stdout(s),
                ..
            } => Ok(s),
            Sink::Stream {
                to: StreamTo::Node(f),
                ..
            } => Ok(f),
        }
    }

    /// Record the first failure of a write.
    fn note<T>(&mut self, r: std::io::Result<T>) -> std::io::Result<T> {
        if let Err(e) = &r {
            self.failed.get_or_insert(e.kind());
        }
        r
    }

    /// Finish: a replaced file is synced and renamed into place, a stream
    /// flushed. Refused after a failed write: the file that was there stays.
    pub fn commit(mut self) -> Result<()> {
        if let Some(kind) = self.failed {
            return Err(self.error("writing", std::io::Error::from(kind)));
        }
        let r = match &mut self.sink {
            Sink::Replace { file: Some(f), .. } => f.sync_all(),
            Sink::Replace { file: None, .. } => {
                Err(std::io::Error::other("the output was committed already"))
            }
            // a pipe or device cannot be synced: flushed, it has the bytes
            Sink::Stream {
                to: StreamTo::Stdout(s),
                ..
            } => s.flush(),
            Sink::Stream {
                to: StreamTo::Node(f),
                ..
            } => f.flush(),
        };
        self.note(r).map_err(|e| self.error("writing", e))?;
        if let Sink::Replace { target, tmp, file } = &mut self.sink {
            // renamed while still locked: a writer waiting on the old name retries
            std::fs::rename(&*tmp, &*target).map_err(|e| file_error("writing", &self.path, e))?;
            *file = None;
        }
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
        let r = self.writer().and_then(|w| w.write(buf));
        if let (Ok(n), Sink::Stream { position, .. }) = (&r, &mut self.sink) {
            *position += *n as u64;
        }
        self.note(r)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        let r = self.writer().and_then(|w| w.flush());
        self.note(r)
    }
}

impl Seek for Output {
    fn seek(&mut self, pos: SeekFrom) -> std::io::Result<u64> {
        let r = match &mut self.sink {
            Sink::Replace { file: Some(f), .. } => f.seek(pos),
            Sink::Replace { file: None, .. } => {
                Err(std::io::Error::other("the output was committed already"))
            }
            // a stream only says where it is
            Sink::Stream { position, .. } => match pos {
                SeekFrom::Current(0) => Ok(*position),
                _ => Err(std::io::Error::new(
                    ErrorKind::Unsupported,
                    "a stream (FIFO, device or standard output) cannot seek",
                )),
            },
        };
        self.note(r)
    }
}

impl Drop for Output {
    fn drop(&mut self) {
        if let Sink::Replace {
            tmp, file: Some(_), ..
        } = &self.sink
        {
            // removed while still locked (see `create`)
            let _ = std::fs::remove_file(tmp);
        }
    }
}

/// Write `bytes` as the whole of `path` (see [`Output`]).
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

    #[cfg(unix)]
    #[test]
    fn a_symbolic_link_is_followed_and_kept() {
        let d = dir("link");
        let target = d.join("target.json");
        std::fs::write(&target, "old").unwrap();
        // a relative link, read from the link's folder
        let link = d.join("link.json");
        std::os::unix::fs::symlink("target.json", &link).unwrap();
        write_file(&link, b"new").unwrap();
        assert!(
            std::fs::symlink_metadata(&link)
                .unwrap()
                .file_type()
                .is_symlink()
        );
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "new");
        assert!(!tmp_path(&target).exists() && !tmp_path(&link).exists());
        // a link to nothing yet makes its target, a chain is followed
        let chain = d.join("chain.json");
        std::os::unix::fs::symlink(d.join("later.json"), d.join("dangling.json")).unwrap();
        std::os::unix::fs::symlink("dangling.json", &chain).unwrap();
        write_file(&chain, b"made").unwrap();
        assert_eq!(
            std::fs::read_to_string(d.join("later.json")).unwrap(),
            "made"
        );
        // a loop is refused by name
        std::os::unix::fs::symlink("loop_b", d.join("loop_a")).unwrap();
        std::os::unix::fs::symlink("loop_a", d.join("loop_b")).unwrap();
        let e = write_file(&d.join("loop_a"), b"x").unwrap_err().to_string();
        assert!(e.contains("loop_a") && e.contains("loop"), "{e}");
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[cfg(unix)]
    #[test]
    fn a_fifo_gets_the_whole_output_and_stays_a_fifo() {
        use std::io::Read;
        use std::os::unix::fs::FileTypeExt;
        let d = dir("fifo");
        let fifo = d.join("f.json");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status();
        if !made.is_ok_and(|s| s.success()) {
            eprintln!("skipped: mkfifo is not available");
            return;
        }
        assert_eq!(output_kind(&fifo), OutputKind::Stream);
        let reader = {
            let fifo = fifo.clone();
            std::thread::spawn(move || {
                let mut text = String::new();
                File::open(&fifo)
                    .unwrap()
                    .read_to_string(&mut text)
                    .unwrap();
                text
            })
        };
        let bytes = "x".repeat(1 << 20);
        let mut out = Output::create(&fifo).unwrap();
        assert!(out.is_stream());
        out.write_all(bytes.as_bytes()).unwrap();
        assert_eq!(out.stream_position().unwrap(), bytes.len() as u64);
        assert!(out.seek(SeekFrom::Start(0)).is_err());
        drop(out);
        assert_eq!(reader.join().unwrap(), bytes);
        assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo());
        assert!(!tmp_path(&fifo).exists());
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[cfg(unix)]
    #[test]
    fn a_full_device_behind_a_link_says_so_and_stays_a_device() {
        use std::os::unix::fs::FileTypeExt;
        let full = Path::new("/dev/full");
        if !std::fs::metadata(full).is_ok_and(|m| m.file_type().is_char_device()) {
            eprintln!("skipped: no /dev/full");
            return;
        }
        let d = dir("full");
        let link = d.join("out.json");
        std::os::unix::fs::symlink(full, &link).unwrap();
        let e = write_file(&link, &[b'x'; 8192]).unwrap_err();
        assert!(
            matches!(e, IoError::NoSpace { streamed: true, .. }),
            "{e:?}"
        );
        let e = e.to_string();
        assert!(
            e.contains("No space left on device") && e.contains("out.json"),
            "{e}"
        );
        assert!(
            std::fs::metadata(full)
                .unwrap()
                .file_type()
                .is_char_device()
        );
        assert!(
            std::fs::symlink_metadata(&link)
                .unwrap()
                .file_type()
                .is_symlink()
        );
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn a_dash_is_standard_output() {
        assert_eq!(output_kind(Path::new("-")), OutputKind::Stream);
        assert!(Output::create(Path::new("-")).unwrap().is_stream());
        let d = dir("kind");
        assert_eq!(output_kind(&d.join("new.json")), OutputKind::File);
        std::fs::remove_dir_all(&d).unwrap();
    }
}

//! The errors of reading and writing files: each names the file and the step.

use std::path::PathBuf;

/// What went wrong reading or writing a file.
#[derive(Debug, thiserror::Error)]
pub enum IoError {
    /// A file could not be created, read, written, synced or renamed.
    #[error("{step} {}", path.display())]
    File {
        /// The step, e.g. "writing" or "cannot read recording".
        step: &'static str,
        /// The file.
        path: PathBuf,
        /// The operating system's error.
        #[source]
        source: std::io::Error,
    },
    /// A value could not be encoded to, or decoded from, JSON.
    #[error("{}: {step}", path.display())]
    Json {
        /// The step, e.g. "malformed state message".
        step: &'static str,
        /// The file.
        path: PathBuf,
        /// The JSON error.
        #[source]
        source: serde_json::Error,
    },
    /// The MCAP writer failed.
    #[error("{}: {step}", path.display())]
    Mcap {
        /// The step, e.g. "adding a channel".
        step: &'static str,
        /// The recording.
        path: PathBuf,
        /// The MCAP error.
        #[source]
        source: mcap::McapError,
    },
    /// A recording is damaged, lacks what was asked for, or a message could not
    /// be encoded.
    #[error("{}: {reason}", path.display())]
    Recording {
        /// The recording.
        path: PathBuf,
        /// What is wrong.
        reason: String,
    },
    /// The device holding a file is full: a file was not replaced (a
    /// stream, FIFO or device written directly holds what came before).
    #[error(
        "No space left on device: {} {}",
        path.display(),
        if *streamed {
            "was written only in part (written directly: a FIFO, device or standard output)"
        } else {
            "not written (a file already there is left as it was)"
        }
    )]
    NoSpace {
        /// The file being written.
        path: PathBuf,
        /// Whether it was written directly rather than replaced.
        streamed: bool,
    },
    /// A file cannot be written: it is a folder, or another writer holds it.
    #[error("{}: {why}", path.display())]
    Refused {
        /// The file.
        path: PathBuf,
        /// Why.
        why: String,
    },
    /// Drawing a plot failed.
    #[error("plot: {0}")]
    Plot(String),
    /// Writing to the output stream (stdout) failed.
    #[error("writing the output")]
    Output(#[source] std::io::Error),
}

impl IoError {
    /// A file error at `step` on `path`.
    pub fn file(
        step: &'static str,
        path: impl Into<PathBuf>,
    ) -> impl FnOnce(std::io::Error) -> Self {
        let path = path.into();
        move |source| IoError::File { step, path, source }
    }

    /// A JSON error at `step` on `path`.
    pub fn json(
        step: &'static str,
        path: impl Into<PathBuf>,
    ) -> impl FnOnce(serde_json::Error) -> Self {
        let path = path.into();
        move |source| IoError::Json { step, path, source }
    }
}

/// Results of reading and writing files.
pub type Result<T, E = IoError> = std::result::Result<T, E>;

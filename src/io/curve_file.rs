//! Curve files: one point per line (see `geometry::polyline`).

use crate::geometry::polyline::{CurveError, parse_points};
use nalgebra::Vector3;
use std::path::{Path, PathBuf};

/// A curve file that could not be read.
#[derive(Debug, thiserror::Error)]
pub enum CurveFileError {
    /// The file could not be read.
    #[error("cannot read curve {}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// Why.
        #[source]
        source: std::io::Error,
    },
    /// Its text is not a curve.
    #[error("curve {}", path.display())]
    Parse {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        #[source]
        source: CurveError,
    },
}

/// Read a curve file.
pub fn read_points(path: &Path) -> Result<Vec<Vector3<f64>>, CurveFileError> {
    let text = crate::io::read_text(path, crate::io::DATA_FILE_LIMIT).map_err(|source| {
        CurveFileError::Read {
            path: path.into(),
            source,
        }
    })?;
    parse_points(&text).map_err(|source| CurveFileError::Parse {
        path: path.into(),
        source,
    })
}

//! Why a report could not be made: the typed error of the report entry
//! points, with the steps it was in (as a chain of sources).

use crate::analysis::equilibrium::AnalysisError;
use crate::io::map_files::MapFileError;
use crate::linalg::eigen::StabilityError;
use crate::scene::SceneError;
use crate::solve::continuation::ContinuationError;
use crate::solve::outcome::SolveError;
use crate::study::error::StudyError;

/// A report that could not be made.
#[derive(Debug, thiserror::Error)]
pub enum ReportError {
    /// A study behind it failed (the library's own errors arrive as one).
    #[error(transparent)]
    Study(#[from] StudyError),
    /// A map's files could not be used.
    #[error(transparent)]
    MapFile(#[from] MapFileError),
    /// Writing the text failed.
    #[error("writing the report: {0}")]
    Format(#[from] std::fmt::Error),
    /// Writing to the terminal or a file failed.
    #[error("writing the report: {0}")]
    Write(#[from] std::io::Error),
    /// A check that could not be made, saying why.
    #[error("{0}")]
    Failed(String),
    /// What the report was doing when its cause failed.
    #[error("{step}")]
    At {
        /// The step.
        step: String,
        /// What failed there.
        #[source]
        source: Box<ReportError>,
    },
}

// the library's errors below the study come to a report as a study's
macro_rules! through_study {
    ($($error:ty),*) => {$(
        impl From<$error> for ReportError {
            fn from(e: $error) -> Self {
                ReportError::Study(e.into())
            }
        }
    )*};
}
through_study!(
    SceneError,
    SolveError,
    ContinuationError,
    StabilityError,
    AnalysisError
);

/// A report's result.
pub type Result<T, E = ReportError> = std::result::Result<T, E>;

crate::study::error::step_context!(ReportError);

/// Stop a report with a message.
macro_rules! fail {
    ($($t:tt)*) => {
        return Err($crate::report::error::ReportError::Failed(format!($($t)*)))
    };
}
pub(crate) use fail;

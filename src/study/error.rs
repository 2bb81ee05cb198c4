//! Why a study failed: the typed error of every study entry point, with the
//! steps it was in (as a chain of sources).

use crate::analysis::equilibrium::AnalysisError;
use crate::linalg::eigen::StabilityError;
use crate::model::strip_shooting::StripShootingError;
use crate::scene::SceneError;
use crate::solve::continuation::ContinuationError;
use crate::solve::outcome::SolveError;

/// A study that could not go on.
#[derive(Debug, thiserror::Error)]
pub enum StudyError {
    /// The scene cannot be used as asked.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// A minimisation failed.
    #[error(transparent)]
    Solve(#[from] SolveError),
    /// A continuation step failed.
    #[error(transparent)]
    Continuation(#[from] ContinuationError),
    /// A stability analysis failed.
    #[error(transparent)]
    Stability(#[from] StabilityError),
    /// Measuring an equilibrium failed.
    #[error(transparent)]
    Analysis(#[from] AnalysisError),
    /// Strip shooting (a continuum start) did not converge.
    #[error(transparent)]
    StripShooting(#[from] StripShootingError),
    /// The continuum equations could not be integrated (a shooting start).
    #[error(transparent)]
    Integration(#[from] crate::model::ode::IntegrationError),
    /// The continuum check (adaptive shooting) failed.
    #[error(transparent)]
    Continuum(#[from] crate::solve::continuum::ContinuumError),
    /// The study cannot go on, and says why.
    #[error("{0}")]
    Failed(String),
    /// The observer stopped the study (interrupted, or it could not write).
    #[error(transparent)]
    Observer(Box<dyn std::error::Error + Send + Sync>),
    /// What the study was doing when its cause failed.
    #[error("{step}")]
    At {
        /// The step, e.g. "loading leg 0, step 3".
        step: String,
        /// What failed there.
        #[source]
        source: Box<StudyError>,
    },
}

/// A study's result.
pub type Result<T, E = StudyError> = std::result::Result<T, E>;

/// Give an error enum with `At { step, source }` and `Failed(String)`
/// variants its `Context` trait (as anyhow's `context`): study and report
/// errors name the steps they happened in the same way.
macro_rules! step_context {
    ($error:ident) => {
        /// Name the step an error happened in (as anyhow's `context`).
        pub trait Context<T> {
            /// The error, said to have happened in `step`.
            fn context(self, step: impl Into<String>) -> Result<T, $error>;
            /// As [`Context::context`], the step made only on failure.
            fn with_context<S: Into<String>>(self, step: impl FnOnce() -> S) -> Result<T, $error>;
        }

        impl<T, E: Into<$error>> Context<T> for std::result::Result<T, E> {
            fn context(self, step: impl Into<String>) -> Result<T, $error> {
                self.map_err(|e| $error::At {
                    step: step.into(),
                    source: Box::new(e.into()),
                })
            }
            fn with_context<S: Into<String>>(self, step: impl FnOnce() -> S) -> Result<T, $error> {
                self.map_err(|e| $error::At {
                    step: step().into(),
                    source: Box::new(e.into()),
                })
            }
        }

        impl<T> Context<T> for Option<T> {
            fn context(self, step: impl Into<String>) -> Result<T, $error> {
                self.ok_or_else(|| $error::Failed(step.into()))
            }
            fn with_context<S: Into<String>>(self, step: impl FnOnce() -> S) -> Result<T, $error> {
                self.ok_or_else(|| $error::Failed(step().into()))
            }
        }
    };
}
pub(crate) use step_context;

step_context!(StudyError);

/// An error and its causes, "step: cause: cause" (as anyhow's `{:#}`).
pub fn describe(e: &(dyn std::error::Error + 'static)) -> String {
    let mut text = e.to_string();
    let mut cause = e.source();
    while let Some(c) = cause {
        text += ": ";
        text += &c.to_string();
        cause = c.source();
    }
    text
}

/// Stop a study with a message (as anyhow's `bail!`).
macro_rules! fail {
    ($($t:tt)*) => {
        return Err($crate::study::error::StudyError::Failed(format!($($t)*)))
    };
}
pub(crate) use fail;

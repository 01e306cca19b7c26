//! The error of the library's pipelines ([`super`]): each stage's error
//! kept as it is, so that the command line and Python tell input, bound
//! and identification failures apart.

pub use crate::bound::BoundError;
pub use crate::how_many::HowManyError;
pub use crate::identify::IdentifyError;
pub use crate::lsq::LsqError;
use thiserror::Error;

/// What can stop a pipeline: bad input, or an error of a stage.
#[derive(Debug, Error)]
pub enum ExperimentError {
    /// Bad input (settings, pool).
    #[error(transparent)]
    Input(#[from] crate::Error),
    /// The relaxation bound.
    #[error(transparent)]
    Bound(#[from] BoundError),
    /// Identification or Monte-Carlo.
    #[error(transparent)]
    Identify(#[from] IdentifyError),
    /// The calibrated frames of a fit.
    #[error(transparent)]
    Frames(#[from] crate::frames::FramesError),
    /// Identification from a data file that the file's data make fail.
    #[error("{path}: {error}")]
    InFile {
        /// The data file.
        path: String,
        /// What is wrong.
        error: IdentifyError,
    },
}

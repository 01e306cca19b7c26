//! Least squares that know no robot (argmin's `solver/` beside its
//! `core/problem.rs`): a [`Residuals`] is anything with a residual vector
//! and its Jacobian at θ; Levenberg–Marquardt ([`levmar`]) minimises
//! `½‖r(θ)‖²` for any of them, a robust loss ([`loss`]) wraps one without
//! touching the solver, and data snooping ([`outliers`]) tests each block
//! of residuals for a gross error. Identification (`crate::identify`)
//! builds the calibration problem on top.

pub mod levmar;
pub mod loss;
pub mod outliers;

use faer::Mat;
use thiserror::Error;

/// A setting out of its range, or a problem these solvers cannot take.
#[derive(Debug, Error)]
pub enum LsqError {
    /// A setting out of its range.
    #[error("invalid setting {name} = {value}: {reason}")]
    Setting {
        /// The setting's name.
        name: &'static str,
        /// Its value, printed.
        value: String,
        /// The allowed range.
        reason: &'static str,
    },
    /// A problem the solver cannot take (its shape, its blocks).
    #[error("{0}")]
    Invalid(String),
}

/// Result with an [`LsqError`].
pub type Result<T> = std::result::Result<T, LsqError>;

/// A least-squares problem: `m` residuals of `n` parameters.
pub trait Residuals {
    /// Number of residuals `m`.
    fn n_residuals(&self) -> usize;

    /// Number of parameters `n`.
    fn n_params(&self) -> usize;

    /// Residuals come in consecutive blocks of this many rows that a robust
    /// loss treats as one (the rows of one measured pose). Default 1.
    fn block_rows(&self) -> usize {
        1
    }

    /// Writes `r(θ)` into `r` (`m` entries) and, if `jac` is given, the
    /// Jacobian `∂r/∂θ` into it (`m × n`). Returns whether every value
    /// written is finite.
    fn eval(&mut self, theta: &[f64], r: &mut [f64], jac: Option<&mut Mat<f64>>) -> bool;
}

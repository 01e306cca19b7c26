//! Identification: estimate the unknown parameters from points (or full
//! poses) measured at known joint angles, by Levenberg–Marquardt from the
//! nominal parameters, with the estimate's covariance `σ̂² (XᵀX)⁻¹`;
//! simulation of measurements; Monte-Carlo comparison of designs; the paper's
//! Tables III and IV.
//!
//! The point model is `y_i = p(θ, q_i) + ε_i`, `ε_i ~ N(0, σ² I₃)`, and the
//! estimate minimises `Σ ‖y_i − p(θ, q_i)‖²` over the unknowns θ (Sun &
//! Hollerbach §V-E). A full-pose robot also measures the end frame's
//! orientation, `R_i = exp([η_i]×) R(θ, q_i)`, `η_i ~ N(0, (σ/w)² I₃)` with
//! `w` = [`Robot::orientation_scale`], and the estimate minimises
//! `Σ ‖y_i − p(θ, q_i)‖² + w² ‖log(R(θ, q_i) R_iᵀ)‖²`: every weighted row
//! carries noise σ, and the weighted `XᵀX` that pose selection maximises is
//! the Fisher information up to `σ²`.
//!
//! * [`residual`]: the problem apart from the solver: the [`Residuals`]
//!   trait and the calibration problem ([`Calibration`]: robot, sensor,
//!   measurements).
//! * [`lm`]: the solver, generic over [`Residuals`] ([`levenberg_marquardt`]),
//!   and [`identify`] with its settings, statuses and covariance.
//! * [`loss`]: robust losses (Huber, Cauchy) wrapping any [`Residuals`],
//!   solved by IRLS ([`identify_robust`]).
//! * [`simulate`](mod@simulate): noisy measurements of the real robot, seeded.
//! * [`evaluation`]: a model's errors on data in mm and degrees, no fitting.
//! * [`fit`](mod@fit): one call from data to a fit with a run-time loss,
//!   parameter significance, fixed/freed unknowns and held-out splits.
//! * [`start`]: the sensor a measurement set calls for (markers, full
//!   poses) and where identification starts.
//! * [`montecarlo`]: repeated identification over noise realisations, and
//!   held-out validation poses.
//! * [`variance`]: each residual block's σ from its own residuals
//!   (variance components), the weights [`fit_weighted`] iterates.
//! * [`tables`]: estimates and residuals in the paper's table layout.
//! * [`camera`](mod@camera): calibration from a camera's pixels (the robot
//!   and the camera's and target's placements).
//!
//! Failures are kept apart as everywhere in the crate: bad input (missing or
//! NaN measurements, wrong joint counts, invalid settings) is an
//! [`IdentifyError`]; a numerical outcome (no convergence, divergence, a rank
//! deficient design) is the [`Status`] of the result.

pub mod axis_relations;
pub mod camera;
pub mod compliance;
pub mod contact;
pub mod evaluation;
pub mod fit;
pub mod lm;
pub mod montecarlo;
pub mod offsets;
pub mod plausible;
pub mod residual;
pub mod restriction;
pub mod simulate;
pub mod start;

pub mod tables;
pub mod undetermined;
pub mod variance;

#[cfg(test)]
mod robust_tests;

pub use crate::lsq::loss::{Cauchy, Huber, L2, Loss, Robust};
pub use evaluation::{ModelErrors, SampleResidual, residuals};
pub use fit::{
    Fit, HoldoutSettings, LossChoice, LossKind, ParameterTrust, SplitResult, WeightedFit, Weights,
    fit, fit_weighted, holdout, prepare_for_data, trust, with_fixed_and_free,
};
pub use lm::{
    Correlation, Covariance, Identification, LmSettings, Solution, Status, StopReason, identify,
    identify_robust, irls, levenberg_marquardt, predicted_covariance,
};
pub use montecarlo::{
    Comparison, GeneralizedVariance, MonteCarloSettings, MonteCarloSummary, ParameterStats, Spread,
    ValidationSet, compare_designs, monte_carlo,
};
pub use residual::{Calibration, Residuals};
pub use simulate::{simulate, trial_rng};
pub use start::{Start, for_measurements};
pub use tables::{PaperTables, ParamGrid, paper_tables};
pub use undetermined::{Determined, FixedParameter, fix_undetermined};

use crate::error::Error;
use thiserror::Error;

/// Bad input to identification: what was wrong and where.
#[derive(Debug, Error)]
pub enum IdentifyError {
    /// Orientations that are one rotation at every pose while the robot's
    /// own orientation turns over the poses: not a measurement (a tracker
    /// that measures none writes the identity).
    #[error(
        "the orientation is {what} at every one of the {poses} poses while the robot's nominal orientation turns by up to {turn_deg:.1}° over them: orientations that never change while the joints move are not a measurement; remove the orientation columns (phix1, phiy1, phiz1 or qw1, qx1, qy1, qz1) to calibrate from the points"
    )]
    ConstantOrientation {
        /// "the identity" or "one rotation".
        what: &'static str,
        /// Number of poses.
        poses: usize,
        /// The largest angle, degrees, between the nominal model's
        /// orientation at the first pose and at another.
        turn_deg: f64,
    },
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
    /// A design that does not fit its pool or the other designs.
    #[error("design '{name}': {reason}")]
    Design {
        /// The design's name.
        name: String,
        /// What is wrong.
        reason: String,
    },
    /// Bad measured data (counts, non-finite values, poses that do not fit
    /// the robot, orientations that are not rotations).
    #[error(transparent)]
    Data(#[from] crate::data::DataError),
    /// Invalid robot, parameter table or pool.
    #[error(transparent)]
    Model(#[from] Error),
    /// A solver's setting out of range, or a problem it cannot take.
    #[error(transparent)]
    Lsq(#[from] crate::lsq::LsqError),
}

/// Result with an [`IdentifyError`].
pub type Result<T> = std::result::Result<T, IdentifyError>;

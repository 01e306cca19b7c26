//! Identification: estimate the unknown parameters from points measured at
//! known joint angles, by Levenberg–Marquardt from the nominal parameters,
//! with the estimate's covariance `σ̂² (XᵀX)⁻¹`; simulation of measurements;
//! Monte-Carlo comparison of designs; the paper's Tables III and IV.
//!
//! The model is `y_i = p(θ, q_i) + ε_i`, `ε_i ~ N(0, σ² I₃)`, and the estimate
//! minimises `Σ ‖y_i − p(θ, q_i)‖²` over the unknowns θ (Sun & Hollerbach §V-E).
//!
//! * [`lm`]: the solver ([`identify`]), its settings, statuses and covariance.
//! * [`simulate`](mod@simulate): noisy measurements of the real robot, seeded.
//! * [`montecarlo`]: repeated identification over noise realisations, and
//!   held-out validation poses.
//! * [`tables`]: estimates and residuals in the paper's table layout.
//!
//! Failures are kept apart as everywhere in the crate: bad input (missing or
//! NaN measurements, wrong joint counts, invalid settings) is an
//! [`IdentifyError`]; a numerical outcome (no convergence, divergence, a rank
//! deficient design) is the [`Status`] of the result.

mod dense;
pub mod lm;
pub mod montecarlo;
pub mod simulate;
pub mod tables;

pub use lm::{
    Correlation, Covariance, Identification, LmSettings, Status, StopReason, identify,
    predicted_covariance,
};
pub use montecarlo::{
    Comparison, GeneralizedVariance, MonteCarloSettings, MonteCarloSummary, ParameterStats, Spread,
    ValidationSet, compare_designs, monte_carlo,
};
pub use simulate::{simulate, trial_rng};
pub use tables::{PaperTables, ParamGrid, paper_tables};

use crate::error::Error;
use crate::robot::{Measurement, Robot};
use serde::{Deserialize, Serialize};
use thiserror::Error;

/// Bad input to identification: what was wrong and where.
#[derive(Debug, Error)]
pub enum IdentifyError {
    /// No poses at all.
    #[error("no measurements: identification needs at least one measured pose")]
    Empty,
    /// Joint vectors and measured points of different counts.
    #[error(
        "{poses} poses but {measurements} measured points: every pose needs exactly one measurement (missing measurements?)"
    )]
    MeasurementCount {
        /// Number of joint vectors.
        poses: usize,
        /// Number of measured points.
        measurements: usize,
    },
    /// A measured coordinate that is NaN or infinite.
    #[error(
        "measurement {pose}, coordinate {coordinate}: not a finite number ({value}); missing or corrupt"
    )]
    NonFiniteMeasurement {
        /// 0-based pose number.
        pose: usize,
        /// `x`, `y` or `z`.
        coordinate: char,
        /// The value given.
        value: f64,
    },
    /// A joint vector that does not fit the robot.
    #[error("pose {pose}: {source}")]
    Pose {
        /// 0-based pose number.
        pose: usize,
        /// What is wrong with it.
        source: Error,
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
    /// A robot whose measurements are not points (3 rows per pose).
    #[error(
        "robot '{robot}' measures {rows} coordinates per pose; identification handles point measurements (3) only"
    )]
    UnsupportedMeasurement {
        /// The robot's name.
        robot: String,
        /// Rows of its Jacobian per pose.
        rows: usize,
    },
    /// Invalid robot, parameter table or pool.
    #[error(transparent)]
    Model(#[from] Error),
}

/// Result with an [`IdentifyError`].
pub type Result<T> = std::result::Result<T, IdentifyError>;

/// Errors unless the robot measures points (the only kind identified so far).
pub(crate) fn require_points(robot: &Robot) -> Result<()> {
    if robot.measurement != Measurement::Point {
        return Err(IdentifyError::UnsupportedMeasurement {
            robot: robot.name.clone(),
            rows: robot.rows_per_pose(),
        });
    }
    Ok(())
}

/// Points measured at known joint angles, validated against a robot: as many
/// points as joint vectors, every joint vector of the robot's length and
/// finite, every coordinate finite.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Measurements {
    qs: Vec<Vec<f64>>,
    points: Vec<[f64; 3]>,
}

impl Measurements {
    /// Validates and wraps joint vectors and the points measured at them.
    ///
    /// ```
    /// use activecal::identify::Measurements;
    /// use activecal::robot::Robot;
    /// let robot = Robot::puma560();
    /// let bad = Measurements::new(&robot, vec![vec![0.0; 6]], vec![[0.0, f64::NAN, 0.0]]);
    /// assert!(bad.unwrap_err().to_string().contains("coordinate y"));
    /// ```
    pub fn new(robot: &Robot, qs: Vec<Vec<f64>>, points: Vec<[f64; 3]>) -> Result<Self> {
        let m = Self { qs, points };
        m.check(robot)?;
        Ok(m)
    }

    /// Re-checks the measurements against a robot (done by [`identify`]).
    pub fn check(&self, robot: &Robot) -> Result<()> {
        require_points(robot)?;
        if self.qs.len() != self.points.len() {
            return Err(IdentifyError::MeasurementCount {
                poses: self.qs.len(),
                measurements: self.points.len(),
            });
        }
        if self.qs.is_empty() {
            return Err(IdentifyError::Empty);
        }
        for (i, q) in self.qs.iter().enumerate() {
            robot
                .check_q(q)
                .map_err(|source| IdentifyError::Pose { pose: i, source })?;
        }
        for (i, p) in self.points.iter().enumerate() {
            if let Some(c) = (0..3).find(|&c| !p[c].is_finite()) {
                return Err(IdentifyError::NonFiniteMeasurement {
                    pose: i,
                    coordinate: ['x', 'y', 'z'][c],
                    value: p[c],
                });
            }
        }
        Ok(())
    }

    /// Number of measured poses.
    #[must_use]
    pub fn len(&self) -> usize {
        self.qs.len()
    }

    /// Whether there are no poses (never true for a validated value).
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.qs.is_empty()
    }

    /// Joint vectors.
    #[must_use]
    pub fn qs(&self) -> &[Vec<f64>] {
        &self.qs
    }

    /// Measured points, one per joint vector.
    #[must_use]
    pub fn points(&self) -> &[[f64; 3]] {
        &self.points
    }
}

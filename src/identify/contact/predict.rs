//! The true error a contact calibration predicts: what held-out placements
//! cannot see.
//!
//! Held-out contacts judge a model by the spread of its predicted tool
//! points about each socket's mean; an error common to a placement's rows
//! (an offset the free socket points absorb) leaves no trace there. The
//! fit's covariance `σ̂² (XᵀX)⁻¹` of the robot's unknowns and the tool
//! offset, carried to the tool point at random configurations (`J C Jᵀ`,
//! `J` the tool point's Jacobian), predicts the error of the calibrated
//! tool point itself: the RMS over configurations of `√tr(J C Jᵀ)`. It is
//! the error in the fit's own gauge (the unknowns fixed as a rigid motion of
//! the whole setup stay at nominal): compare it with the truth after the
//! best rigid motion between the two models' tool points.

use super::fit::ContactFit;
use crate::blocks::jacobian_of;
use crate::model::MeasurementKind;
use serde::Serialize;

/// Configurations the prediction is taken over.
pub const PREDICTION_CONFIGURATIONS: usize = 1000;

/// The predicted true error of a contact calibration.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PredictedTrueError {
    /// RMS over configurations of the tool point's predicted 3-D error, mm.
    pub rms_mm: f64,
    /// How many random configurations (generic, seeded) it is over.
    pub configurations: usize,
}

/// The tool point's predicted error after `fit` (see the module
/// documentation), at `configurations` generic configurations of `seed`;
/// `None` without a covariance.
#[must_use]
pub fn predicted_true_error(
    fit: &ContactFit,
    configurations: usize,
    seed: u64,
) -> Option<PredictedTrueError> {
    let cov = fit.covariance.as_ref()?;
    let n_kin = fit.robot.n_unknowns();
    let p = n_kin + 3;
    if cov.len() < p || configurations == 0 {
        return None;
    }
    // The tool point as a one-marker sensor at the fitted offset, with the
    // fit's unknowns: columns are the robot's unknowns, then the offset —
    // the first `p` of the fit's.
    let mut tool = fit.robot.clone();
    tool.measurement = MeasurementKind::Markers(1);
    let mut table = fit.table.clone();
    table.markers = vec![fit.tool_offset];
    let qs = crate::observability::generic_configurations(&fit.robot, configurations, seed);
    let x = jacobian_of(&tool, &table, qs.len(), |k, q| q.copy_from_slice(&qs[k]));
    let mut sum = 0.0;
    for i in 0..x.n_poses() {
        let b = x.block(i);
        for r in 0..b.nrows() {
            for a in 0..p {
                for c in 0..p {
                    sum += b[(r, a)] * cov[a][c] * b[(r, c)];
                }
            }
        }
    }
    Some(PredictedTrueError {
        rms_mm: (sum.max(0.0) / qs.len() as f64).sqrt() * 1e3,
        configurations: qs.len(),
    })
}

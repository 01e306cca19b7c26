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
use super::select::SocketPool;
use crate::blocks::jacobian_of;
use crate::model::{MeasurementKind, ParamTable, Robot};
use nalgebra::DMatrix;
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
    let p = fit.robot.n_unknowns() + 3;
    if cov.len() < p || configurations == 0 {
        return None;
    }
    let (w, used) = tool_point_moment(
        &fit.robot,
        &fit.table,
        fit.tool_offset,
        configurations,
        seed,
    );
    // tr(C W): the mean over configurations of tr(J C Jᵀ).
    let trace: f64 = (0..p)
        .flat_map(|a| (0..p).map(move |c| (a, c)))
        .map(|(a, c)| cov[a][c] * w[(c, a)])
        .sum();
    Some(PredictedTrueError {
        rms_mm: trace.max(0.0).sqrt() * 1e3,
        configurations: used,
    })
}

/// The tool point's second moment `W = Σ_q J_qᵀ J_q / N` over `configurations`
/// generic configurations of `seed` (`J_q` the 3 rows of the tool point at
/// `tool_offset` in the end frame, columns `robot`'s unknowns then the
/// offset): `tr(C W)` is the mean squared true error of the tool point for a
/// covariance `C` of those unknowns. Returns `W` and `N`.
#[must_use]
pub fn tool_point_moment(
    robot: &Robot,
    table: &ParamTable,
    tool_offset: [f64; 3],
    configurations: usize,
    seed: u64,
) -> (DMatrix<f64>, usize) {
    // The tool point as a one-marker sensor at the offset: columns are the
    // robot's unknowns, then the offset. (Builds a kind, decides nothing:
    // the contact fit's own sensor is the point with its offset unknown.)
    let mut tool = robot.clone();
    tool.measurement = MeasurementKind::Markers(1);
    let mut table = table.clone();
    table.markers = vec![tool_offset];
    let qs = crate::observability::generic_configurations(robot, configurations, seed);
    let x = jacobian_of(&tool, &table, qs.len(), |k, q| q.copy_from_slice(&qs[k]));
    let p = robot.n_unknowns() + 3;
    let mut w = DMatrix::zeros(p, p);
    for i in 0..x.n_poses() {
        let b = x.block(i);
        let b = DMatrix::from_fn(b.nrows(), p, |r, c| b[(r, c)]);
        w += b.transpose() * b;
    }
    (w / qs.len().max(1) as f64, qs.len())
}

/// The moment of a socket pool's columns whose `tr(M⁻¹ W)` is the tool
/// point's predicted true error (3-D, squared, in units of σ², σ the contact
/// noise per coordinate) at [`PREDICTION_CONFIGURATIONS`] generic
/// configurations: [`tool_point_moment`] of the pool's robot (tool offset
/// 0, the pool's own) in the leading columns, zero on the sockets' points,
/// which no configuration away from the sockets sees.
#[must_use]
pub fn true_error_moment(pool: &SocketPool, table: &ParamTable, seed: u64) -> DMatrix<f64> {
    let (w, _) = tool_point_moment(
        &pool.robot,
        table,
        [0.0; 3],
        PREDICTION_CONFIGURATIONS,
        seed,
    );
    let p = pool.p();
    let mut full = DMatrix::zeros(p, p);
    let k = w.nrows().min(p);
    full.view_mut((0, 0), (k, k))
        .copy_from(&w.view((0, 0), (k, k)));
    full
}

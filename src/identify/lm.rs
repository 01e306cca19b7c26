//! Identification by Levenberg–Marquardt ([`crate::lsq::levmar`]): the
//! calibration problem posed, solved, and its rank and covariance
//! `σ̂² (XᵀX)⁻¹` read off the solution.
//!
//! The loop ([`levenberg_marquardt`]) sees only a [`Residuals`]: no
//! kinematics, no sensor. [`identify`] poses the calibration problem
//! ([`Calibration`]) and reads rank and covariance off the solution;
//! [`identify_robust`] wraps the problem in a robust loss ([`crate::lsq::loss`])
//! and solves it by IRLS ([`irls`]).

use super::residual::{Calibration, Residuals};
use super::{IdentifyError, Result};
use crate::blocks::Blocks;
use crate::data::Measurements;
use crate::linalg::qr::inverse_information;
pub use crate::lsq::levmar::{LmSettings, Solution, StopReason, levenberg_marquardt};
use crate::lsq::loss::{Loss, Robust};
use crate::model::{ParamTable, Robot, Symbol};
use crate::observability::identifiability;
use faer::Mat;
use serde::{Deserialize, Serialize};

/// Outcome of an identification.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Status {
    /// A stopping tolerance was met and the Jacobian at the estimate has full
    /// column rank: the estimate and its covariance are meaningful.
    Converged,
    /// The iteration limit was reached first.
    MaxIterations,
    /// The cost or the Jacobian became non-finite, or no step could reduce the
    /// cost although no tolerance was met.
    Diverged,
    /// The Jacobian at the estimate is rank deficient: some unknowns (see
    /// [`Identification::unidentifiable`]) are not determined by the design,
    /// and there is no covariance.
    RankDeficient,
}

/// Correlation matrix with its row and column labels.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Correlation {
    /// Names of the unknowns (rows and columns).
    pub names: Vec<String>,
    /// `C_ij / √(C_ii C_jj)`, row-major.
    pub matrix: Vec<Vec<f64>>,
}

/// The estimate's covariance `σ̂² (XᵀX)⁻¹`, `X` the Jacobian at the estimate.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Covariance {
    /// The covariance matrix, row-major, unknowns in the robot's order.
    pub matrix: Vec<Vec<f64>>,
    /// Standard deviations `√C_jj`.
    pub std: Vec<f64>,
    /// The labelled correlation matrix.
    pub correlation: Correlation,
}

/// Result of [`identify`]. It serialises as every calibration report prints
/// it (see its `Serialize`): the estimate and standard deviations by
/// unknown's name, not the raw vectors and tables.
#[derive(Clone, Debug)]
pub struct Identification {
    /// Outcome; the estimate is trustworthy only when `Converged`.
    pub status: Status,
    /// Which rule stopped the iteration.
    pub stop: StopReason,
    /// Outer iterations (Jacobian evaluations after the first).
    pub iterations: usize,
    /// Residual evaluations, including rejected and geodesic trial points.
    pub evaluations: usize,
    /// Names of the unknowns.
    pub names: Vec<String>,
    /// Unknowns at the start.
    pub start: Vec<f64>,
    /// Unknowns at the estimate.
    pub estimate: Vec<f64>,
    /// The full parameter table at the estimate.
    pub table: ParamTable,
    /// Sum of squared residuals at the start.
    pub initial_rss: f64,
    /// Sum of squared residuals at the estimate.
    pub rss: f64,
    /// Sum of squared residuals after each accepted step (first entry: start).
    pub rss_history: Vec<f64>,
    /// Final damping `λ` (scaled units).
    pub damping: f64,
    /// Residual degrees of freedom `t n − p` (`t` rows per pose: 3 or 6).
    pub dof: usize,
    /// `σ̂ = √(rss / dof)`, `None` when `dof = 0`.
    pub sigma_hat: Option<f64>,
    /// Numerical rank of the column-scaled Jacobian at the estimate.
    pub rank: usize,
    /// Unknowns in the numerical null space (empty at full rank).
    pub unidentifiable: Vec<String>,
    /// `σ̂² (XᵀX)⁻¹` at the estimate; `None` when rank deficient or `dof = 0`.
    pub covariance: Option<Covariance>,
}

impl Identification {
    /// Whether the status is [`Status::Converged`].
    #[must_use]
    pub fn converged(&self) -> bool {
        self.status == Status::Converged
    }

    /// `{name: value}` of `values` (one per unknown), in name order.
    #[must_use]
    pub fn named(&self, values: &[f64]) -> std::collections::BTreeMap<String, f64> {
        self.names
            .iter()
            .cloned()
            .zip(values.iter().copied())
            .collect()
    }
}

impl Serialize for Identification {
    /// The keys every calibration report prints: `status`, `stop`,
    /// `converged`, `iterations`, `evaluations`, `estimate` and `std` by
    /// unknown (`std` and `correlation` null below full rank), `sigma_hat`,
    /// `rss`, `initial_rss`, `rank`, `unidentifiable`. The start, the table,
    /// the history and the covariance matrix stay out.
    fn serialize<S: serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        use serde::ser::SerializeStruct;
        let cov = self.covariance.as_ref();
        let mut st = s.serialize_struct("Identification", 13)?;
        st.serialize_field("status", &self.status)?;
        st.serialize_field("stop", &self.stop)?;
        st.serialize_field("converged", &self.converged())?;
        st.serialize_field("iterations", &self.iterations)?;
        st.serialize_field("evaluations", &self.evaluations)?;
        st.serialize_field("estimate", &self.named(&self.estimate))?;
        st.serialize_field("std", &cov.map(|c| self.named(&c.std)))?;
        st.serialize_field("correlation", &cov.map(|c| &c.correlation))?;
        st.serialize_field("sigma_hat", &self.sigma_hat)?;
        st.serialize_field("rss", &self.rss)?;
        st.serialize_field("initial_rss", &self.initial_rss)?;
        st.serialize_field("rank", &self.rank)?;
        st.serialize_field("unidentifiable", &self.unidentifiable)?;
        st.end()
    }
}

/// `x` shifted by a multiple of 2π into (−π, π].
fn wrap_angle(x: f64) -> f64 {
    use std::f64::consts::{PI, TAU};
    let w = x - TAU * (x / TAU).round();
    if w <= -PI { w + TAU } else { w }
}

/// Identifies the robot's unknowns from `meas` by Levenberg–Marquardt from
/// the unknowns' values in `start` (normally `robot.nominal`); the parameters
/// that are not unknown keep their values in `start`.
///
/// Bad input (measurements that do not fit the robot, a non-finite start,
/// invalid settings) is an `Err`; everything else is a [`Status`].
///
/// ```
/// use activecal::identify::{identify, simulate, trial_rng, LmSettings};
/// use activecal::pool::Pool;
/// use activecal::model::Robot;
/// let robot = Robot::puma560();
/// let pool = Pool::full(&robot, 5).unwrap();
/// let qs: Vec<Vec<f64>> = (0..40).map(|k| pool.q(k * 389)).collect();
/// let meas = simulate(&robot, &robot.real, &qs, 0.0, &mut trial_rng(1, 0)).unwrap();
/// let id = identify(&robot, &robot.nominal, &meas, &LmSettings::default()).unwrap();
/// assert!(id.converged());
/// let truth = robot.unknown_values(&robot.real);
/// assert!(id.estimate.iter().zip(&truth).all(|(e, t)| (e - t).abs() < 1e-9));
/// ```
pub fn identify(
    robot: &Robot,
    start: &ParamTable,
    meas: &Measurements,
    settings: &LmSettings,
) -> Result<Identification> {
    let (names, theta0) = check_inputs(robot, start, meas, settings)?;
    let mut prob = Calibration::new(robot, start, meas)?;
    let out = levenberg_marquardt(&mut prob, &theta0, settings);
    Ok(finish(robot, start, names, theta0, out))
}

/// As [`identify`], minimising `½ Σ_i ρ(‖r_i‖²)` over the poses `i` for a
/// robust `loss` ([`crate::lsq::loss`]) by iteratively reweighted least squares
/// ([`irls`]). Rank and covariance are those of the weighted problem at the
/// estimate (down-weighted poses count less); the residual sums
/// (`rss`, `sigma_hat`) are weighted too. With [`crate::lsq::loss::L2`] the
/// result equals [`identify`]'s.
pub fn identify_robust<L: Loss>(
    robot: &Robot,
    start: &ParamTable,
    meas: &Measurements,
    settings: &LmSettings,
    loss: L,
) -> Result<Identification> {
    let (names, theta0) = check_inputs(robot, start, meas, settings)?;
    let mut prob = Robust::new(Calibration::new(robot, start, meas)?, loss);
    let out = irls(
        &mut prob,
        &theta0,
        settings,
        IRLS_ITERATIONS,
        IRLS_TOLERANCE,
    );
    Ok(finish(robot, start, names, theta0, out))
}

/// Most IRLS rounds of [`identify_robust`].
pub const IRLS_ITERATIONS: usize = 50;
/// [`identify_robust`] stops when no `√w` of a pose changes by more than
/// this between rounds.
pub const IRLS_TOLERANCE: f64 = 1e-9;

/// Iteratively reweighted least squares: Levenberg–Marquardt on `prob` with
/// its weights frozen, then [`Robust::reweight`] at the estimate, until no
/// `√w_b` changes by more than `tol` or `rounds` rounds are done. Returns
/// the last round's solution, which minimises the least squares weighted by
/// the weights it was solved with (its `evaluations` and `iterations` summed
/// over rounds, `initial_rss` that of the first round).
pub fn irls<R: Residuals, L: Loss>(
    prob: &mut Robust<R, L>,
    theta0: &[f64],
    settings: &LmSettings,
    rounds: usize,
    tol: f64,
) -> Solution {
    let mut theta = theta0.to_vec();
    let (mut evaluations, mut iterations) = (0, 0);
    let mut initial_rss = None;
    let mut round = 0;
    loop {
        let mut sol = levenberg_marquardt(prob, &theta, settings);
        round += 1;
        evaluations += sol.evaluations;
        iterations += sol.iterations;
        let initial = *initial_rss.get_or_insert(sol.initial_rss);
        let change = if sol.finite {
            prob.reweight(&sol.theta)
        } else {
            None
        };
        if change.is_none_or(|c| c <= tol) || round >= rounds {
            sol.evaluations = evaluations;
            sol.iterations = iterations;
            sol.initial_rss = initial;
            return sol;
        }
        theta.clone_from(&sol.theta);
    }
}

/// Validates the inputs of [`identify`]; returns the unknowns' names and
/// start values.
fn check_inputs(
    robot: &Robot,
    start: &ParamTable,
    meas: &Measurements,
    settings: &LmSettings,
) -> Result<(Vec<String>, Vec<f64>)> {
    settings.validate()?;
    robot.validate()?;
    meas.check(robot)?;
    if start.rows.len() != robot.frames.len() {
        return Err(IdentifyError::Model(crate::Error::Invalid(format!(
            "the start table has {} rows for {} frames",
            start.rows.len(),
            robot.frames.len()
        ))));
    }
    let names = robot.parameter_names();
    let theta0 = robot.unknown_values(start);
    if let Some((k, &v)) = theta0.iter().enumerate().find(|(_, v)| !v.is_finite()) {
        return Err(crate::Error::NonFiniteParameter {
            name: names[k].clone(),
            value: v,
        }
        .into());
    }
    Ok((names, theta0))
}

/// The identification report of a solution: angles wrapped near the start,
/// rank, status and covariance at the estimate.
fn finish(
    robot: &Robot,
    start: &ParamTable,
    names: Vec<String>,
    theta0: Vec<f64>,
    mut out: Solution,
) -> Identification {
    let p = theta0.len();
    let m = out.jac.nrows();
    // Angles live on the circle: report the representative nearest the start
    // (the kinematics depend on them through sin and cos only, so the
    // residual and the Jacobian are unchanged).
    for ((t, t0), u) in out.theta.iter_mut().zip(&theta0).zip(&robot.unknowns) {
        if matches!(u.symbol, Symbol::Gamma | Symbol::Alpha | Symbol::Beta) && t.is_finite() {
            *t = t0 + wrap_angle(*t - t0);
        }
    }

    // ---- rank and covariance at the estimate -------------------------------
    let table = robot.with_unknowns(start, &out.theta);
    let dof = m.saturating_sub(p);
    let sigma_hat = (dof > 0 && out.rss.is_finite()).then(|| (out.rss / dof as f64).sqrt());
    let (rank, unidentifiable, inv) = if out.finite {
        // Moved, not copied: the Jacobian is the largest thing held.
        let x = Blocks::new(
            std::mem::replace(&mut out.jac, Mat::new()),
            robot.rows_per_pose(),
        );
        let idf = identifiability(robot, &x);
        let inv = (idf.rank == p)
            .then(|| inverse_information(x.mat()))
            .flatten();
        (idf.rank, idf.unidentifiable, inv)
    } else {
        (0, Vec::new(), None)
    };
    let status = match out.stop {
        StopReason::NonFinite | StopReason::DampingLimit => Status::Diverged,
        _ if rank < p => Status::RankDeficient,
        StopReason::MaxIterations => Status::MaxIterations,
        _ => Status::Converged,
    };
    let covariance = match (inv, sigma_hat) {
        (Some(inv), Some(s)) => Some(covariance_from(&inv, s * s, &names)),
        _ => None,
    };
    Identification {
        status,
        stop: out.stop,
        iterations: out.iterations,
        evaluations: out.evaluations,
        names,
        start: theta0,
        estimate: out.theta,
        table,
        initial_rss: out.initial_rss,
        rss: out.rss,
        rss_history: out.history,
        damping: out.lambda,
        dof,
        sigma_hat,
        rank,
        unidentifiable,
        covariance,
    }
}

/// `σ² (XᵀX)⁻¹` with `X` the identification Jacobian of `table` at `qs`: the
/// covariance the linearised model predicts for the estimate with noise σ.
/// `None` when `X` is rank deficient.
pub fn predicted_covariance(
    robot: &Robot,
    table: &ParamTable,
    qs: &[Vec<f64>],
    sigma: f64,
) -> Result<Option<Mat<f64>>> {
    for (i, q) in qs.iter().enumerate() {
        robot
            .check_q(q)
            .map_err(|source| crate::data::DataError::Pose { pose: i, source })?;
    }
    let x = crate::blocks::jacobian_of(robot, table, qs.len(), |k, q| q.copy_from_slice(&qs[k]));
    if identifiability(robot, &x).rank < robot.n_params() {
        return Ok(None);
    }
    Ok(inverse_information(x.mat()).map(|inv| {
        let s2 = sigma * sigma;
        Mat::from_fn(inv.nrows(), inv.ncols(), |i, j| s2 * inv[(i, j)])
    }))
}

fn covariance_from(inv: &Mat<f64>, s2: f64, names: &[String]) -> Covariance {
    let p = inv.nrows();
    let matrix: Vec<Vec<f64>> = (0..p)
        .map(|i| (0..p).map(|j| s2 * inv[(i, j)]).collect())
        .collect();
    let std: Vec<f64> = (0..p).map(|i| matrix[i][i].max(0.0).sqrt()).collect();
    // Correlations from (XᵀX)⁻¹ directly: defined even when σ̂ = 0.
    let corr = (0..p)
        .map(|i| {
            (0..p)
                .map(|j| inv[(i, j)] / (inv[(i, i)] * inv[(j, j)]).sqrt())
                .collect()
        })
        .collect();
    Covariance {
        matrix,
        std,
        correlation: Correlation {
            names: names.to_vec(),
            matrix: corr,
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::identify::{simulate, trial_rng};

    /// The residual's Jacobian (with `J_l⁻¹(φ)` on the orientation rows)
    /// against central differences of the residual, far from the solution:
    /// orientation noise of 0.3 rad makes `J_l⁻¹` differ from I by ~0.15, so
    /// dropping it fails by orders of magnitude more than the tolerance.
    #[test]
    fn pose_residual_jacobian_matches_central_differences() {
        let mut robot = Robot::builtin("stanford:pose").unwrap();
        robot.orientation_scale = 0.5;
        let qs: Vec<Vec<f64>> = (0..8)
            .map(|k| {
                robot
                    .limits
                    .iter()
                    .enumerate()
                    .map(|(j, &[lo, hi])| lo + (hi - lo) * (((k * 7 + j * 3) % 11) as f64 / 10.0))
                    .collect()
            })
            .collect();
        // σ = 0.15 m → orientation noise 0.3 rad per axis.
        let meas = simulate(&robot, &robot.real, &qs, 0.15, &mut trial_rng(2, 0)).unwrap();
        let mut prob = Calibration::new(&robot, &robot.nominal, &meas).unwrap();
        let theta = robot.unknown_values(&robot.nominal);
        let (m, p) = (prob.n_residuals(), theta.len());
        let mut r = vec![0.0; m];
        let mut jac = Mat::<f64>::zeros(m, p);
        assert!(prob.eval(&theta, &mut r, Some(&mut jac)));
        let (mut rp, mut rm) = (vec![0.0; m], vec![0.0; m]);
        let h = 1e-6;
        let mut worst: f64 = 0.0;
        for k in 0..p {
            let mut tp = theta.clone();
            tp[k] += h;
            let mut tm = theta.clone();
            tm[k] -= h;
            prob.eval(&tp, &mut rp, None);
            prob.eval(&tm, &mut rm, None);
            for i in 0..m {
                worst = worst.max(((rp[i] - rm[i]) / (2.0 * h) - jac[(i, k)]).abs());
            }
        }
        // Truncation h²|r'''| ≈ 1e-12 and rounding ε|r|/h ≈ 1e-9 at |r| ≤ 5 m.
        assert!(worst < 1e-7, "max |fd − J| = {worst:e}");
    }
}

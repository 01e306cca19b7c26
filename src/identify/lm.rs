//! Levenberg–Marquardt identification with column scaling, Nielsen damping
//! updates and optional geodesic acceleration; covariance `σ̂² (XᵀX)⁻¹`.
//!
//! Each step minimises the damped, scaled linear model
//! `‖J δ + r‖² + λ ‖D δ‖²` by solving the augmented least-squares system
//! `[J D⁻¹; √λ I] u = [−r; 0]`, `δ = D⁻¹ u`, with faer's Householder QR.
//!
//! Why not a crate: `levenberg-marquardt` (the MINPACK port) is written
//! against its own nalgebra version and would put a second nalgebra in the
//! build; our Jacobians live in faer matrices anyway. Why the augmented
//! system and not the normal equations `(JᵀJ + λD²) δ = −Jᵀr`: forming `JᵀJ`
//! squares the condition number, and a 20 m lever arm (frame `a`) beside
//! millimetre offsets makes that matter for the 1e-9 recovery we require.
//!
//! `D` is MINPACK's scaling, `d_j = max over iterations of ‖J_{:,j}‖`, so the
//! damping is invariant to the units of the unknowns (radians vs. metres).
//!
//! The loop ([`levenberg_marquardt`]) sees only a [`Residuals`]: no
//! kinematics, no sensor. [`identify`] poses the calibration problem
//! ([`Calibration`]) and reads rank and covariance off the solution;
//! [`identify_robust`] wraps the problem in a robust loss ([`super::loss`])
//! and solves it by IRLS ([`irls`]).

use super::loss::{Loss, Robust};
use super::residual::{Calibration, Residuals};
use super::{IdentifyError, Measurements, Result};
use crate::blocks::Blocks;
use crate::linalg::qr::{SeqQr, inverse_information};
use crate::model::{ParamTable, Robot, Symbol};
use crate::observability::identifiability;
use faer::Mat;
use serde::{Deserialize, Serialize};

/// Settings of the solver, with documented defaults; [`LmSettings::validate`]
/// is called by [`identify`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct LmSettings {
    /// Most outer iterations (Jacobian evaluations after the first). Default 200.
    pub max_iterations: usize,
    /// Step tolerance: stop when `‖D δ‖ ≤ xtol (‖D θ‖ + xtol)`. Default 1e-10.
    pub xtol: f64,
    /// Cost tolerance: stop when the actual and the predicted relative
    /// reductions of the cost are both at most `ftol`. Default 1e-12.
    pub ftol: f64,
    /// Gradient tolerance: stop when every column of `J` is within `gtol` of
    /// orthogonal to the residual (cosine). Default 1e-10.
    pub gtol: f64,
    /// Initial damping `λ₀` relative to the largest diagonal entry of the
    /// scaled `JᵀJ`. Default 1e-3.
    pub initial_damping: f64,
    /// Add Transtrum's geodesic acceleration (one extra residual evaluation
    /// per trial step) to follow curved valleys from a far start. Default true.
    pub geodesic: bool,
}

impl Default for LmSettings {
    fn default() -> Self {
        Self {
            max_iterations: 200,
            xtol: 1e-10,
            ftol: 1e-12,
            gtol: 1e-10,
            initial_damping: 1e-3,
            geodesic: true,
        }
    }
}

impl LmSettings {
    /// Sets [`LmSettings::max_iterations`].
    #[must_use]
    pub fn with_max_iterations(mut self, n: usize) -> Self {
        self.max_iterations = n;
        self
    }

    /// Sets [`LmSettings::xtol`], [`LmSettings::ftol`] and [`LmSettings::gtol`].
    #[must_use]
    pub fn with_tolerances(mut self, xtol: f64, ftol: f64, gtol: f64) -> Self {
        self.xtol = xtol;
        self.ftol = ftol;
        self.gtol = gtol;
        self
    }

    /// Sets [`LmSettings::geodesic`].
    #[must_use]
    pub fn with_geodesic(mut self, on: bool) -> Self {
        self.geodesic = on;
        self
    }

    /// Checks every setting is in range.
    pub fn validate(&self) -> Result<()> {
        let bad = |name, value: f64, reason| IdentifyError::Setting {
            name,
            value: value.to_string(),
            reason,
        };
        if self.max_iterations == 0 {
            return Err(IdentifyError::Setting {
                name: "max_iterations",
                value: "0".into(),
                reason: "at least one iteration is needed (0 would report the start as the estimate)",
            });
        }
        for (name, v) in [
            ("xtol", self.xtol),
            ("ftol", self.ftol),
            ("gtol", self.gtol),
        ] {
            if !(v.is_finite() && (0.0..1.0).contains(&v)) {
                return Err(bad(name, v, "a tolerance must be in [0, 1)"));
            }
        }
        if !(self.initial_damping.is_finite() && self.initial_damping > 0.0) {
            return Err(bad(
                "initial_damping",
                self.initial_damping,
                "must be finite and > 0",
            ));
        }
        Ok(())
    }
}

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

/// Why the iteration stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StopReason {
    /// The residual is exactly zero.
    ZeroResidual,
    /// The step tolerance `xtol` was met.
    StepTolerance,
    /// The cost tolerance `ftol` was met.
    CostTolerance,
    /// The gradient tolerance `gtol` was met.
    GradientTolerance,
    /// `max_iterations` outer iterations were done.
    MaxIterations,
    /// The cost or the Jacobian was not finite at an accepted point.
    NonFinite,
    /// The damping reached its ceiling (1e32) without an acceptable step.
    DampingLimit,
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

/// Result of [`identify`].
#[derive(Clone, Debug, Serialize)]
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
}

/// `x` shifted by a multiple of 2π into (−π, π].
fn wrap_angle(x: f64) -> f64 {
    use std::f64::consts::{PI, TAU};
    let w = x - TAU * (x / TAU).round();
    if w <= -PI { w + TAU } else { w }
}

fn sumsq(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum()
}

fn norm(v: &[f64]) -> f64 {
    sumsq(v).sqrt()
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
/// robust `loss` ([`super::loss`]) by iteratively reweighted least squares
/// ([`irls`]). Rank and covariance are those of the weighted problem at the
/// estimate (down-weighted poses count less); the residual sums
/// (`rss`, `sigma_hat`) are weighted too. With [`super::loss::L2`] the
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
            .map_err(|source| IdentifyError::Pose { pose: i, source })?;
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

/// What [`levenberg_marquardt`] returns: the solver's state at the end.
#[derive(Clone, Debug)]
pub struct Solution {
    /// Parameters at the end.
    pub theta: Vec<f64>,
    /// Jacobian at `theta` (`m × n`).
    pub jac: Mat<f64>,
    /// Whether the residual and the Jacobian at `theta` are finite.
    pub finite: bool,
    /// Which rule stopped the iteration.
    pub stop: StopReason,
    /// Outer iterations (Jacobian evaluations after the first).
    pub iterations: usize,
    /// Residual evaluations, including rejected and geodesic trial points.
    pub evaluations: usize,
    /// `‖r‖²` at the start.
    pub initial_rss: f64,
    /// `‖r‖²` at `theta`.
    pub rss: f64,
    /// `‖r‖²` after each accepted step (first entry: start).
    pub history: Vec<f64>,
    /// Final damping `λ` (scaled units).
    pub lambda: f64,
}

/// Ceiling on the scaled damping: past it a step is ~1e-32 of a gradient step.
const MAX_DAMPING: f64 = 1e32;
/// Smallest gain ratio for accepting a step.
const ACCEPT: f64 = 1e-4;
/// Geodesic acceleration: finite-difference step along the velocity, and the
/// largest allowed ratio `2‖a‖/‖v‖` (Transtrum & Sethna 2012).
const GEO_H: f64 = 0.1;
const GEO_ALPHA: f64 = 0.75;

/// Levenberg–Marquardt on any [`Residuals`] from `theta0`: one outer
/// iteration per Jacobian, inner trials raising the damping until a step is
/// accepted or a tolerance is met (settings are not validated here; see
/// [`LmSettings::validate`]).
pub fn levenberg_marquardt<R: Residuals + ?Sized>(
    prob: &mut R,
    theta0: &[f64],
    s: &LmSettings,
) -> Solution {
    let p = theta0.len();
    debug_assert_eq!(p, prob.n_params());
    let m = prob.n_residuals();
    let mut theta = theta0.to_vec();
    let mut r = vec![0.0; m];
    let mut jac = Mat::<f64>::zeros(m, p);
    let mut evaluations = 1;
    let finite = prob.eval(&theta, &mut r, Some(&mut jac));
    let rss0 = sumsq(&r);
    // The Jacobian is held once (3n × p for n measured points): `out.jac`
    // gets it at the end, and each trial builds only the augmented system.
    let mut out = Solution {
        theta: theta.clone(),
        jac: Mat::new(),
        finite: finite && rss0.is_finite(),
        stop: StopReason::NonFinite,
        iterations: 0,
        evaluations,
        initial_rss: rss0,
        rss: rss0,
        history: vec![rss0],
        lambda: 0.0,
    };
    if !out.finite {
        out.jac = jac;
        return out;
    }
    let mut cost = 0.5 * rss0;
    let mut d = vec![0.0f64; p];
    let mut lambda = f64::NAN;
    let mut nu = 2.0;
    let mut r_try = vec![0.0; m];
    let mut r_geo = vec![0.0; m];
    let mut theta_try = vec![0.0; p];
    let mut iterations = 0;
    let stop = 'outer: loop {
        // ---- scaling, gradient test -----------------------------------------
        let col_norms: Vec<f64> = (0..p).map(|c| jac.col(c).norm_l2()).collect();
        for (dj, &cn) in d.iter_mut().zip(&col_norms) {
            *dj = (*dj).max(cn);
            if *dj == 0.0 {
                *dj = 1.0;
            }
        }
        if cost == 0.0 {
            break StopReason::ZeroResidual;
        }
        let rnorm = norm(&r);
        let g: Vec<f64> = (0..p)
            .map(|c| (0..m).map(|i| jac[(i, c)] * r[i]).sum::<f64>())
            .collect();
        let gcos = (0..p)
            .filter(|&c| col_norms[c] > 0.0)
            .map(|c| g[c].abs() / (col_norms[c] * rnorm))
            .fold(0.0, f64::max);
        if gcos <= s.gtol {
            break StopReason::GradientTolerance;
        }
        if iterations >= s.max_iterations {
            break StopReason::MaxIterations;
        }
        if lambda.is_nan() {
            // The largest diagonal entry of the scaled JᵀJ, ‖J_{:,j}/d_j‖²
            // (one column at a time).
            let max_diag = (0..p)
                .map(|c| faer::Col::from_fn(m, |i| jac[(i, c)] / d[c]).squared_norm_l2())
                .fold(0.0, f64::max);
            lambda = s.initial_damping * max_diag.max(f64::MIN_POSITIVE);
        }
        let dtheta_norm = norm(&theta.iter().zip(&d).map(|(t, d)| t * d).collect::<Vec<_>>());
        iterations += 1;

        // ---- inner loop: damped trial steps ---------------------------------
        loop {
            // [Js; √λ I] u = [−r; 0], Js = J D⁻¹
            let sl = lambda.sqrt();
            let aug = Mat::from_fn(m + p, p, |i, j| {
                if i < m {
                    jac[(i, j)] / d[j]
                } else if i - m == j {
                    sl
                } else {
                    0.0
                }
            });
            let mut qr = SeqQr::new(aug);
            let mut u = Mat::from_fn(m + p, 1, |i, _| if i < m { -r[i] } else { 0.0 });
            qr.solve_lstsq_in_place(u.as_mut());
            let u: Vec<f64> = (0..p).map(|j| u[(j, 0)]).collect();
            let mut step: Vec<f64> = (0..p).map(|j| u[j] / d[j]).collect();
            let mut ok = u.iter().all(|v| v.is_finite());

            // ---- geodesic acceleration: a = −(JᵀJ + λD²)⁻¹ Jᵀ r_vv ----------
            if ok && s.geodesic {
                for j in 0..p {
                    theta_try[j] = theta[j] + GEO_H * step[j];
                }
                evaluations += 1;
                if prob.eval(&theta_try, &mut r_geo, None) {
                    // r_vv ≈ (2/h) [(r(θ + h v) − r(θ))/h − J v]
                    let jv: Vec<f64> = (0..m)
                        .map(|i| (0..p).map(|j| jac[(i, j)] * step[j]).sum::<f64>())
                        .collect();
                    let mut a = Mat::from_fn(m + p, 1, |i, _| {
                        if i < m {
                            -(2.0 / GEO_H) * ((r_geo[i] - r[i]) / GEO_H - jv[i])
                        } else {
                            0.0
                        }
                    });
                    qr.solve_lstsq_in_place(a.as_mut());
                    let a_s: Vec<f64> = (0..p).map(|j| a[(j, 0)]).collect();
                    let un = norm(&u);
                    if a_s.iter().all(|v| v.is_finite()) && 2.0 * norm(&a_s) <= GEO_ALPHA * un {
                        for j in 0..p {
                            step[j] += 0.5 * a_s[j] / d[j];
                        }
                    } else {
                        // Too curved for this damping: reject, damp more.
                        ok = false;
                    }
                } else {
                    ok = false;
                }
            }

            let du: Vec<f64> = step.iter().zip(&d).map(|(x, d)| x * d).collect();
            let du_norm = norm(&du);
            // Predicted reduction of ½‖r‖² by the linear model: −gᵀδ − ½‖Jδ‖².
            let jd: Vec<f64> = (0..m)
                .map(|i| (0..p).map(|j| jac[(i, j)] * step[j]).sum::<f64>())
                .collect();
            let pred = -(0..p).map(|j| g[j] * step[j]).sum::<f64>() - 0.5 * sumsq(&jd);
            let mut actual = f64::NEG_INFINITY;
            let mut new_cost = f64::INFINITY;
            if ok {
                for j in 0..p {
                    theta_try[j] = theta[j] + step[j];
                }
                evaluations += 1;
                if prob.eval(&theta_try, &mut r_try, None) {
                    new_cost = 0.5 * sumsq(&r_try);
                    if new_cost.is_finite() {
                        actual = cost - new_cost;
                    }
                }
            }
            let rho = if pred > 0.0 {
                actual / pred
            } else {
                f64::NEG_INFINITY
            };
            let accepted = rho > ACCEPT;

            // ---- tolerances (MINPACK's tests, on this trial) ----------------
            let ftol_met = ok
                && actual.is_finite()
                && actual.abs() <= s.ftol * cost
                && pred <= s.ftol * cost
                && rho <= 2.0;
            let xtol_met = du_norm <= s.xtol * (dtheta_norm + s.xtol);

            if accepted {
                theta.copy_from_slice(&theta_try);
                cost = new_cost;
                std::mem::swap(&mut r, &mut r_try);
                out.history.push(2.0 * cost);
                lambda *= (1.0 / 3.0f64).max(1.0 - (2.0 * rho - 1.0).powi(3));
                nu = 2.0;
                if !prob.eval(&theta, &mut r, Some(&mut jac)) {
                    break 'outer StopReason::NonFinite;
                }
            } else {
                lambda *= nu;
                nu *= 2.0;
            }
            if ftol_met {
                break 'outer StopReason::CostTolerance;
            }
            if xtol_met {
                break 'outer StopReason::StepTolerance;
            }
            if lambda > MAX_DAMPING {
                break 'outer StopReason::DampingLimit;
            }
            if accepted {
                break;
            }
        }
    };
    out.finite = stop != StopReason::NonFinite;
    out.theta = theta;
    out.jac = jac;
    out.stop = stop;
    out.iterations = iterations;
    out.evaluations = evaluations;
    out.rss = 2.0 * cost;
    out.lambda = lambda;
    out
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

//! Refinement beyond the pool: each pose of a finished design moves
//! continuously in joint space to increase `ln det(M0 + Σ X(q_k)ᵀX(q_k))`.
//!
//! Block-coordinate ascent over the poses: for pose `k`, with the others
//! (and the prior) fixed in `M_rest`, the objective is
//! `f(q) = ln det(M_rest + X(q)ᵀX(q))`, its gradient is taken by central
//! differences of `f` in each joint (one-sided at a limit), and a projected
//! step `q ← clip(q + α∇f)` is accepted only when `f` increases by more than
//! rounding and the new configuration passes every pool filter; `α` starts
//! where the largest joint moves [`RefineSettings::max_move`] and halves on
//! refusal. So the refined `ln det` never falls below the design's, every
//! pose stays inside the joint limits and the filters, and the result is the
//! same whatever the number of threads (the computation is sequential).
//!
//! A refined design is no longer a pool design: the pool's certified bound
//! does not bound it, and it may exceed that bound (which the caller
//! reports).

use crate::criterion::Prior;
use crate::error::{Error, Result};
use crate::linalg::chol::ln_det_spd_equilibrated;
use crate::measure::JacobianEvaluator;
use crate::model::{ParamTable, Robot};
use crate::pool::PoolFilter;
use faer::Mat;
use serde::{Deserialize, Serialize};

/// Settings of [`refine`]: [`RefineSettings::builder`] (validated) or the
/// defaults.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
#[non_exhaustive]
pub struct RefineSettings {
    /// Passes over all poses (default 3); fewer when a pass gains less than
    /// `tol`.
    pub sweeps: usize,
    /// Accepted steps per pose per pass (default 20).
    pub steps: usize,
    /// Largest joint move of a first trial step, radians or metres
    /// (default 0.2).
    pub max_move: f64,
    /// Central-difference step, radians or metres (default 1e-6: the
    /// truncation error `O(h²)` and the rounding `O(ε·|f|/h)` of `f` balance
    /// near it for `|f| ~ 100`).
    pub fd_step: f64,
    /// Smallest gain of `ln det` that counts as an increase (default 1e-9;
    /// the rounding of one `p ≤ 45` Cholesky of an equilibrated matrix is
    /// ~1e-13 relative, so this is ~1,000 times above it for `|f| ≤ 100`).
    pub tol: f64,
}

impl Default for RefineSettings {
    fn default() -> Self {
        Self {
            sweeps: 3,
            steps: 20,
            max_move: 0.2,
            fd_step: 1e-6,
            tol: 1e-9,
        }
    }
}

crate::settings::settings_builder! {
    /// Validated construction of [`RefineSettings`].
    RefineSettingsBuilder for RefineSettings, error Error {
        /// Passes over all poses (default 3).
        sweeps: usize,
        /// Accepted steps per pose per pass (default 20).
        steps: usize,
        /// Largest joint move of a first trial step, `> 0` (default 0.2).
        max_move: f64,
        /// Central-difference step, `> 0` (default 1e-6).
        fd_step: f64,
        /// Smallest gain of ln det that counts, `≥ 0` (default 1e-9).
        tol: f64,
    }
}

impl RefineSettings {
    /// Checks `max_move > 0`, `fd_step > 0` and `tol ≥ 0` (all finite).
    pub fn validate(&self) -> Result<()> {
        let ok = |v: f64, min_ok: bool| v.is_finite() && (v > 0.0 || (min_ok && v == 0.0));
        if !(ok(self.max_move, false) && ok(self.fd_step, false) && ok(self.tol, true)) {
            return Err(Error::Invalid(
                "refinement needs max_move > 0, fd_step > 0 and tol >= 0".into(),
            ));
        }
        Ok(())
    }
}

/// One refined pose.
#[derive(Clone, Debug, Serialize)]
pub struct RefinedPose {
    /// Position in the design.
    pub index: usize,
    /// Joint values before.
    pub q_before: Vec<f64>,
    /// Joint values after.
    pub q: Vec<f64>,
    /// Increase of the design's `ln det` from moving this pose (all
    /// passes).
    pub gain: f64,
    /// Largest joint move, `max_j |q_j − q_before_j|`.
    pub max_move: f64,
}

/// The outcome of [`refine`].
#[derive(Clone, Debug, Serialize)]
pub struct Refinement {
    /// `ln det` of the design before (prior included).
    pub ln_oid_before: f64,
    /// `ln det` after.
    pub ln_oid: f64,
    /// `ln_oid − ln_oid_before ≥ 0`.
    pub gain: f64,
    /// Every pose, in design order.
    pub poses: Vec<RefinedPose>,
    /// Passes run.
    pub sweeps: usize,
    /// Objective evaluations (one Jacobian and one Cholesky each).
    pub evaluations: usize,
}

struct Problem<'a> {
    robot: &'a Robot,
    filter_table: &'a ParamTable,
    filters: &'a [PoolFilter],
    ev: JacobianEvaluator<'a>,
    jac: Vec<f64>,
    t: usize,
    p: usize,
    evaluations: usize,
}

impl Problem<'_> {
    /// `X(q)ᵀX(q)` as a `p × p` matrix.
    fn gram(&mut self, q: &[f64]) -> Mat<f64> {
        self.ev.eval(q, &mut self.jac);
        let (t, p) = (self.t, self.p);
        let x = Mat::from_fn(t, p, |r, c| self.jac[r * p + c]);
        x.transpose() * &x
    }

    /// `f(q) = ln det(M_rest + X(q)ᵀX(q))`, `-∞` when singular.
    fn value(&mut self, rest: &Mat<f64>, q: &[f64]) -> f64 {
        self.evaluations += 1;
        let m = rest + self.gram(q);
        ln_det_spd_equilibrated(m.as_ref()).unwrap_or(f64::NEG_INFINITY)
    }

    fn admissible(&self, q: &[f64]) -> bool {
        self.filters
            .iter()
            .all(|f| f.keeps(self.robot, self.filter_table, q))
    }
}

impl Problem<'_> {
    /// Errors on a pose of the wrong length, outside the limits or a filter.
    fn check_design(&self, qs: &[Vec<f64>]) -> Result<()> {
        let dof = self.robot.dof();
        for (k, q) in qs.iter().enumerate() {
            if q.len() != dof {
                return Err(Error::JointCount {
                    expected: dof,
                    got: q.len(),
                });
            }
            let inside = q
                .iter()
                .zip(&self.robot.limits)
                .all(|(v, [lo, hi])| *lo <= *v && *v <= *hi);
            if !inside || !self.admissible(q) {
                return Err(Error::Invalid(format!(
                    "design pose {} is outside the joint limits or a pool filter",
                    k + 1
                )));
            }
        }
        Ok(())
    }

    /// `∇f(q)` by central differences of step `h`, one-sided at a limit.
    fn gradient(&mut self, rest: &Mat<f64>, q: &[f64], h: f64, grad: &mut [f64]) {
        for (j, gj) in grad.iter_mut().enumerate() {
            let [lo, hi] = self.robot.limits[j];
            let mut a = q.to_vec();
            let mut b = q.to_vec();
            a[j] = (a[j] + h).min(hi);
            b[j] = (b[j] - h).max(lo);
            let width = a[j] - b[j];
            *gj = if width > 0.0 {
                (self.value(rest, &a) - self.value(rest, &b)) / width
            } else {
                0.0
            };
        }
    }

    /// Up to `s.steps` projected gradient steps on pose `q` with the other
    /// poses' information `rest` held, each halved until it gains more than
    /// `s.tol` within the filters; returns the gain in ln det.
    fn ascend_pose(&mut self, rest: &Mat<f64>, q: &mut Vec<f64>, s: &RefineSettings) -> f64 {
        let mut f = self.value(rest, q);
        let mut gain = 0.0;
        let mut grad = vec![0.0; q.len()];
        for _ in 0..s.steps {
            self.gradient(rest, q, s.fd_step, &mut grad);
            let gmax = grad.iter().fold(0.0f64, |m, g| m.max(g.abs()));
            if !(gmax > 0.0 && gmax.is_finite()) {
                break;
            }
            let mut alpha = s.max_move / gmax;
            let mut accepted = false;
            for _ in 0..30 {
                let mut trial: Vec<f64> = q.iter().zip(&grad).map(|(v, g)| v + alpha * g).collect();
                clip(&mut trial, &self.robot.limits);
                let ft = self.value(rest, &trial);
                if ft > f + s.tol && self.admissible(&trial) {
                    gain += ft - f;
                    f = ft;
                    *q = trial;
                    accepted = true;
                    break;
                }
                alpha *= 0.5;
            }
            if !accepted {
                break;
            }
        }
        gain
    }
}

fn clip(q: &mut [f64], limits: &[[f64; 2]]) {
    for (v, &[lo, hi]) in q.iter_mut().zip(limits) {
        *v = v.clamp(lo, hi);
    }
}

/// Refines the design `qs` (joint values of its poses) for `robot`, with
/// the identification Jacobian at `table`, the filters evaluated at
/// `filter_table` (as the pool's were), on top of `prior` if any. Errors on
/// a pose of the wrong length, outside the limits or the filters, or a
/// design that is singular to begin with.
pub fn refine(
    robot: &Robot,
    table: &ParamTable,
    filter_table: &ParamTable,
    filters: &[PoolFilter],
    prior: Option<&Prior>,
    qs: &[Vec<f64>],
    s: &RefineSettings,
) -> Result<Refinement> {
    let (t, p) = (robot.rows_per_pose(), robot.n_unknowns());
    s.validate()?;
    let mut pb = Problem {
        robot,
        filter_table,
        filters,
        ev: JacobianEvaluator::new(robot, table),
        jac: vec![0.0; t * p],
        t,
        p,
        evaluations: 0,
    };
    pb.check_design(qs)?;
    let mut q: Vec<Vec<f64>> = qs.to_vec();
    let mut grams: Vec<Mat<f64>> = q.iter().map(|x| pb.gram(x)).collect();
    let base = || match prior {
        Some(pr) => pr.matrix().to_owned(),
        None => Mat::<f64>::zeros(p, p),
    };
    let total = |grams: &[Mat<f64>]| grams.iter().fold(base(), |acc, g| acc + g);
    let ln_before = ln_det_spd_equilibrated(total(&grams).as_ref())
        .ok_or_else(|| Error::Invalid("the design to refine is singular".into()))?;
    let mut gains = vec![0.0; q.len()];
    let mut sweeps = 0;
    for _ in 0..s.sweeps {
        sweeps += 1;
        let mut sweep_gain = 0.0;
        for k in 0..q.len() {
            let rest = grams
                .iter()
                .enumerate()
                .filter(|&(j, _)| j != k)
                .fold(base(), |acc, (_, g)| acc + g);
            let gain = pb.ascend_pose(&rest, &mut q[k], s);
            gains[k] += gain;
            sweep_gain += gain;
            grams[k] = pb.gram(&q[k]);
        }
        if sweep_gain <= s.tol {
            break;
        }
    }
    // Every accepted step raised f by more than `tol`; the fresh sum
    // differs from the tracked one by rounding only.
    let ln_after = ln_det_spd_equilibrated(total(&grams).as_ref()).unwrap_or(f64::NEG_INFINITY);
    Ok(Refinement {
        ln_oid_before: ln_before,
        ln_oid: ln_after,
        gain: ln_after - ln_before,
        poses: refined_poses(qs, &q, &gains),
        sweeps,
        evaluations: pb.evaluations,
    })
}

/// Each pose before and after, with its gain and its largest joint move.
fn refined_poses(before: &[Vec<f64>], after: &[Vec<f64>], gains: &[f64]) -> Vec<RefinedPose> {
    after
        .iter()
        .zip(before)
        .enumerate()
        .map(|(k, (after, before))| RefinedPose {
            index: k,
            q_before: before.clone(),
            q: after.clone(),
            gain: gains[k],
            max_move: after
                .iter()
                .zip(before)
                .fold(0.0f64, |m, (a, b)| m.max((a - b).abs())),
        })
        .collect()
}

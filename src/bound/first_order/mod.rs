//! A first-order solver for the relaxation: pairwise (vertex-)exchange steps
//! with exact line search on the box-constrained simplex
//! `{0 ≤ w ≤ 1, Σ w = N}`, after a few capped multiplicative steps.
//!
//! Each round recomputes `M(w)`, its Cholesky factor and the variances `d_i`
//! of the whole pool ([`variances_into`]), evaluates the certificate (eq. C),
//! and then works on a candidate set `K` = support ∪ the poses outside the
//! support with the largest `d_i`: it repeatedly moves weight `δ` from the
//! pose `j ∈ K` with the smallest `d_j` among `w_j > 0` to the pose `i ∈ K`
//! with the largest `d_i` among `w_i < 1`, with the step that maximises
//!
//! `φ(δ) = ln det(M + δ(X_iᵀX_i − X_jᵀX_j)) − ln det M = Σ_k ln(1 + δ μ_k)`   (X1)
//!
//! where `μ_k` are the eigenvalues of `D G`, `G = U M⁻¹ Uᵀ` for the stacked
//! blocks `U = [X_i; X_j]` and `D = diag(I_t, −I_t)`. `M⁻¹` and the `d` of the
//! candidates follow each step by the Woodbury identity
//!
//! `(M + Uᵀ δD U)⁻¹ = M⁻¹ − W R Wᵀ,  W = M⁻¹Uᵀ,  R = δ (I + δ D G)⁻¹ D`.   (X2)
//!
//! The optimality conditions are `d_i ≥ c` where `w_i = 1`, `d_i = c` where
//! `0 < w_i < 1` and `d_i ≤ c` where `w_i = 0`; a pairwise step exists exactly
//! while they fail.

use super::BoundError;
pub use super::exchange_step::line_search;
use super::exchange_step::{PairWork, exchange_round};
use super::variance::{
    Scaled, VarianceWork, certificate_with_prior, check_problem, make_feasible, scale_columns,
    top_sum, variances_into,
};
use crate::blocks::Blocks;
use faer::Mat;
use serde::{Deserialize, Serialize};
use std::time::Instant;

/// Settings of the first-order solver: [`ExchangeSettings::builder`]
/// (validated by [`ExchangeSettings::validate`]) or the defaults in
/// [`Default`].
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(default)]
#[non_exhaustive]
pub struct ExchangeSettings {
    /// Stop when the certificate gap (eq. C) in ln det is at most this.
    /// Default 1e-7.
    pub gap_tol: f64,
    /// Maximum rounds (full-pool variance evaluations). Default 2000.
    pub max_rounds: usize,
    /// Wall-clock limit in seconds: a safety net, not a stopping rule.
    /// Default one day, so that the rounds and step limits decide and the
    /// result never depends on the machine's speed or load (a 60 s default
    /// stopped the 10⁶-pose PUMA screening half-way on a loaded machine and
    /// left the bound uncertified).
    pub time_limit: f64,
    /// Capped multiplicative steps `w_i ← min(1, c·w_i d_i)` before the
    /// exchange rounds, when no start is given. Default 30.
    pub warmup_rounds: usize,
    /// After the warm-up, keep at most this many of the largest weights
    /// (at least `N` and `⌈p/t⌉`). Default 1000.
    pub keep: usize,
    /// Poses outside the support added to the candidate set each round, by
    /// largest `d_i`. Default 100.
    pub extra: usize,
    /// Maximum pairwise steps per round. Default 3000.
    pub max_steps: usize,
}

impl Default for ExchangeSettings {
    fn default() -> Self {
        Self {
            gap_tol: 1e-7,
            max_rounds: 2000,
            time_limit: 86_400.0,
            warmup_rounds: 30,
            keep: 1000,
            extra: 100,
            max_steps: 3000,
        }
    }
}

crate::settings::settings_builder! {
    /// Validated construction of [`ExchangeSettings`].
    ExchangeSettingsBuilder for ExchangeSettings, error BoundError {
        /// Certificate gap to stop at (default 1e-7).
        gap_tol: f64,
        /// Most rounds (default 2000).
        max_rounds: usize,
        /// Wall-clock safety net, seconds (default one day).
        time_limit: f64,
        /// Capped multiplicative warm-up steps (default 30).
        warmup_rounds: usize,
        /// Largest weights kept after the warm-up (default 1000).
        keep: usize,
        /// Candidates added per round (default 100).
        extra: usize,
        /// Most pairwise steps per round (default 3000).
        max_steps: usize,
    }
}

impl ExchangeSettings {
    /// Checks every field's range.
    pub fn validate(&self) -> Result<(), BoundError> {
        let bad = |name, value: String, reason| {
            Err(BoundError::InvalidSetting {
                name,
                value,
                reason,
            })
        };
        if !(self.gap_tol > 0.0 && self.gap_tol.is_finite()) {
            return bad(
                "first_order.gap_tol",
                self.gap_tol.to_string(),
                "must be finite and > 0",
            );
        }
        if self.time_limit.is_nan() || self.time_limit <= 0.0 {
            return bad(
                "first_order.time_limit",
                self.time_limit.to_string(),
                "must be > 0",
            );
        }
        if self.max_rounds == 0 {
            return bad("first_order.max_rounds", "0".into(), "must be ≥ 1");
        }
        if self.keep == 0 {
            return bad("first_order.keep", "0".into(), "must be ≥ 1");
        }
        if self.max_steps == 0 {
            return bad("first_order.max_steps", "0".into(), "must be ≥ 1");
        }
        Ok(())
    }
}

/// What the first-order solver found. ln det values are of the unscaled
/// information matrix.
#[derive(Clone, Debug, Serialize)]
pub struct ExchangeOutcome {
    /// Feasible weights, one per pool pose.
    pub weights: Vec<f64>,
    /// `ln det M(w)` at `weights`: a lower bound on the relaxation optimum.
    pub ln_det: f64,
    /// The smallest certificate (eq. C) seen: an upper bound on it.
    pub ln_bound: f64,
    /// `ln_bound − ln_det`.
    pub gap: f64,
    /// Rounds run.
    pub rounds: usize,
    /// Pairwise steps taken.
    pub steps: usize,
    /// Whether `gap ≤ gap_tol`.
    pub converged: bool,
    /// Wall-clock seconds.
    pub seconds: f64,
}

/// Runs the first-order solver on a pool Jacobian for designs of `n` poses,
/// from `start` (any nonnegative weights; made feasible) or from the uniform
/// design.
///
/// Errors on bad input (see [`BoundError`]); a solver that stops before
/// `gap_tol` reports `converged = false` with a valid bound.
pub fn solve(
    x: &Blocks,
    n: usize,
    start: Option<&[f64]>,
    settings: &ExchangeSettings,
) -> Result<ExchangeOutcome, BoundError> {
    settings.validate()?;
    check_problem(x, n)?;
    if let Some(w) = start {
        check_start(w, x.n_poses())?;
    }
    let sc = scale_columns(x, n)?;
    let mut out = solve_scaled(&sc, n, start.map(<[f64]>::to_vec), settings);
    unscale(&mut out, &sc);
    Ok(out)
}

pub(crate) fn check_start(w: &[f64], pool: usize) -> Result<(), BoundError> {
    if w.len() != pool {
        return Err(BoundError::InvalidWeights(format!(
            "{} weights for a pool of {pool} poses",
            w.len()
        )));
    }
    if let Some(i) = w.iter().position(|v| !v.is_finite() || *v < 0.0) {
        return Err(BoundError::InvalidWeights(format!(
            "weight {i} is {} (need a finite w ≥ 0)",
            w[i]
        )));
    }
    Ok(())
}

pub(crate) fn unscale(out: &mut ExchangeOutcome, sc: &Scaled) {
    out.ln_det += sc.ln_scale;
    out.ln_bound += sc.ln_scale;
}

/// The state of one round: full-pool variances at the current weights.
pub(crate) struct Evaluation {
    pub ln_det: f64,
    pub bound: f64,
    pub d: Vec<f64>,
    pub minv: Mat<f64>,
}

/// Evaluates `M(w)` (prior included), its variances and the certificate
/// (eq. C0) on the whole pool, or `None` if `M(w)` is not positive definite.
pub(crate) fn evaluate(
    sc: &Scaled,
    n: usize,
    w: &[f64],
    work: &mut VarianceWork,
    scratch: &mut Vec<f64>,
) -> Option<Evaluation> {
    let x = &sc.x;
    let m = sc.information(w);
    let mut d = vec![0.0; x.n_poses()];
    let (ln_det, minv) = variances_into(x, m.as_ref(), work, &mut d)?;
    let s_n = top_sum(&d, n, scratch);
    let c0 = sc.prior_trace(minv.as_ref());
    Some(Evaluation {
        ln_det,
        bound: certificate_with_prior(ln_det, c0, s_n, x.p()),
        d,
        minv,
    })
}

/// The solver on already scaled blocks (ln det values in scaled units).
/// Input must have passed [`check_problem`] and [`scale_columns`].
pub(crate) fn solve_scaled(
    sc: &Scaled,
    n: usize,
    start: Option<Vec<f64>>,
    s: &ExchangeSettings,
) -> ExchangeOutcome {
    let clock = Instant::now();
    let pool = sc.x.n_poses();
    let (t, p) = (sc.x.t(), sc.x.p());
    let mut ev = Evaluator {
        sc,
        n,
        work: VarianceWork::default(),
        scratch: Vec::new(),
    };
    if n == pool {
        let w = vec![1.0; pool];
        let e = ev.eval(&w).expect("full-rank pool");
        return ExchangeOutcome {
            weights: w,
            ln_det: e.ln_det,
            ln_bound: e.ln_det,
            gap: 0.0,
            rounds: 1,
            steps: 0,
            converged: true,
            seconds: clock.elapsed().as_secs_f64(),
        };
    }
    // --- start: given weights, or uniform + capped multiplicative steps + pruning
    let started = start.is_some();
    let mut it = start_point(&mut ev, start);
    // Without a start the weights are uniform, all positive: `v > 0.0` as
    // `>=` is equivalent (issue #30's sample).
    let support = it.w.iter().filter(|&&v| v > 0.0).count();
    let keep = s.keep.max(n).max(p.div_ceil(t));
    if !started && support > keep {
        warm_up_and_prune(&mut ev, &mut it, s.warmup_rounds, keep);
    }
    exchange_rounds(&mut ev, it, s, clock)
}

/// Evaluations at one problem, with their reusable workspace.
struct Evaluator<'a> {
    sc: &'a Scaled,
    n: usize,
    work: VarianceWork,
    scratch: Vec<f64>,
}

impl Evaluator<'_> {
    /// [`evaluate`] at `w`.
    fn eval(&mut self, w: &[f64]) -> Option<Evaluation> {
        evaluate(self.sc, self.n, w, &mut self.work, &mut self.scratch)
    }
}

/// The solver's point between phases, its evaluation, the smallest
/// certificate seen and the rounds (evaluations) so far.
struct Iterate {
    w: Vec<f64>,
    eval: Evaluation,
    best_bound: f64,
    rounds: usize,
}

/// The start: the given weights made feasible, or uniform; uniform too when
/// the given weights' `M` is singular.
fn start_point(ev: &mut Evaluator<'_>, start: Option<Vec<f64>>) -> Iterate {
    let (n, pool) = (ev.n, ev.sc.x.n_poses());
    let mut w = match start {
        Some(mut w) => {
            make_feasible(&mut w, n);
            w
        }
        None => vec![n as f64 / pool as f64; pool],
    };
    let eval = match ev.eval(&w) {
        Some(e) => e,
        None => {
            // A start with a singular M: fall back to the uniform design.
            w = vec![n as f64 / pool as f64; pool];
            ev.eval(&w).expect("full-rank pool")
        }
    };
    Iterate {
        w,
        best_bound: eval.bound,
        eval,
        rounds: 1,
    }
}

/// From a uniform start: capped multiplicative steps (at most `rounds`),
/// then the weights pruned to the `keep` largest (widened while `M` is
/// singular).
fn warm_up_and_prune(ev: &mut Evaluator<'_>, it: &mut Iterate, rounds: usize, keep: usize) {
    let (n, pool) = (ev.n, ev.sc.x.n_poses());
    for _ in 0..rounds {
        crate::progress::checkpoint();
        if !multiplicative_step(&mut it.w, &it.eval.d, n) {
            break;
        }
        match ev.eval(&it.w) {
            Some(e) => it.eval = e,
            None => break,
        }
        it.rounds += 1;
        it.best_bound = it.best_bound.min(it.eval.bound);
    }
    // Prune to the `keep` largest weights; widen if M becomes singular.
    let mut k = keep;
    loop {
        let mut pruned = prune(&it.w, k);
        make_feasible(&mut pruned, n);
        if let Some(e) = ev.eval(&pruned) {
            it.w = pruned;
            it.eval = e;
            it.rounds += 1;
            it.best_bound = it.best_bound.min(it.eval.bound);
            break;
        }
        if k >= pool {
            break;
        }
        // Any growth to the pool ends at a regular prune or the whole pool:
        // `2 * k` as `2 + k` changes only how many evaluations it takes
        // (equivalent in value, issue #30's sample).
        k = (2 * k).min(pool);
    }
}

/// Exchange rounds on the candidates ([`candidates`], [`exchange_round`])
/// until the certified gap of the best point is at most `s.gap_tol`, or a
/// round or time limit.
fn exchange_rounds(
    ev: &mut Evaluator<'_>,
    mut it: Iterate,
    s: &ExchangeSettings,
    clock: Instant,
) -> ExchangeOutcome {
    let (x, n) = (&ev.sc.x, ev.n);
    let mut steps = 0;
    let task = crate::progress::Task::start("bound: first-order rounds", None);
    let mut best_w = it.w.clone();
    let mut best_ln_det = it.eval.ln_det;
    // The smallest gain a pairwise step is taken for; the rounds stop on the
    // certified gap whatever it is, so `4.0 * n` as `4.0 + n` changes only
    // the number of steps and rounds (equivalent in value, issue #30's
    // sample).
    let step_tol = s.gap_tol / (4.0 * n as f64);
    let mut pair = PairWork::new(x.t(), x.p());
    loop {
        // `>` as `>=` keeps the later of two points of equal ln det:
        // equivalent in value (issue #30's sample).
        if it.eval.ln_det > best_ln_det {
            best_ln_det = it.eval.ln_det;
            best_w.clone_from(&it.w);
        }
        it.best_bound = it.best_bound.min(it.eval.bound);
        task.inc(1);
        task.note(|| {
            format!(
                "gap {:.2e} -> {:.0e}, {steps} steps",
                it.best_bound - best_ln_det,
                s.gap_tol
            )
        });
        if it.best_bound - best_ln_det <= s.gap_tol
            || it.rounds >= s.max_rounds
            || clock.elapsed().as_secs_f64() > s.time_limit
        {
            break;
        }
        let cand = candidates(&it.w, &it.eval.d, s.extra);
        let minv = std::mem::replace(&mut it.eval.minv, Mat::new());
        steps += exchange_round(
            x,
            &cand,
            &mut it.w,
            minv,
            &it.eval.d,
            step_tol,
            s.max_steps,
            &mut pair,
        );
        // Rounding in the Woodbury updates can leave tiny negative weights.
        make_feasible(&mut it.w, n);
        it.rounds += 1;
        match ev.eval(&it.w) {
            Some(e) => it.eval = e,
            // Should not happen (the line search keeps M positive definite);
            // stop with the best point.
            None => break,
        }
    }
    ExchangeOutcome {
        gap: it.best_bound - best_ln_det,
        converged: it.best_bound - best_ln_det <= s.gap_tol,
        weights: best_w,
        ln_det: best_ln_det,
        ln_bound: it.best_bound,
        rounds: it.rounds,
        steps,
        seconds: clock.elapsed().as_secs_f64(),
    }
}

/// One capped multiplicative step `w_i ← min(1, c·w_i d_i)` with `c` chosen
/// so that `Σ w = N` (water-filling over the sorted `w_i d_i`). Returns
/// `false` (and leaves `w`) when fewer than `N` poses carry weight.
fn multiplicative_step(w: &mut [f64], d: &[f64], n: usize) -> bool {
    let mut v: Vec<(f64, usize)> = w
        .iter()
        .zip(d)
        .enumerate()
        .filter(|(_, (wi, di))| **wi > 0.0 && **di > 0.0)
        .map(|(i, (wi, di))| (wi * di, i))
        .collect();
    if v.len() < n {
        return false;
    }
    v.sort_unstable_by(|a, b| b.0.total_cmp(&a.0));
    let mut rest: f64 = v.iter().map(|e| e.0).sum();
    let mut capped = 0;
    let mut c = (n as f64) / rest;
    // `> 1.0` as `>= 1.0` is equivalent in value (issue #30's sample): an
    // entry with `c·v = 1` is 1 capped or not, and capping it leaves `c` as
    // it is (`(n − k − 1)/(rest − v) = (n − k)/rest` when `v = rest/(n − k)`).
    while capped < n && c * v[capped].0 > 1.0 {
        rest -= v[capped].0;
        capped += 1;
        c = (n - capped) as f64 / rest;
    }
    w.iter_mut().for_each(|x| *x = 0.0);
    for (k, &(vi, i)) in v.iter().enumerate() {
        w[i] = if k < capped { 1.0 } else { (c * vi).min(1.0) };
    }
    true
}

/// The `k` largest weights of `w` (others set to 0).
fn prune(w: &[f64], k: usize) -> Vec<f64> {
    if k >= w.len() {
        return w.to_vec();
    }
    let mut idx: Vec<usize> = (0..w.len()).collect();
    idx.select_nth_unstable_by(k - 1, |&a, &b| w[b].total_cmp(&w[a]));
    let mut out = vec![0.0; w.len()];
    for &i in &idx[..k] {
        out[i] = w[i];
    }
    out
}

/// Candidate set: the support plus the `extra` poses outside it with the
/// largest variances, ascending.
pub(crate) fn candidates(w: &[f64], d: &[f64], extra: usize) -> Vec<usize> {
    let mut cand: Vec<usize> = (0..w.len()).filter(|&i| w[i] > 0.0).collect();
    let mut out: Vec<usize> = (0..w.len()).filter(|&i| w[i] <= 0.0).collect();
    let k = extra.min(out.len());
    if k > 0 {
        out.select_nth_unstable_by(k - 1, |&a, &b| d[b].total_cmp(&d[a]));
        cand.extend_from_slice(&out[..k]);
    }
    cand.sort_unstable();
    cand
}

#[cfg(test)]
mod tests;

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

/// Settings of the first-order solver. Defaults in [`Default`]; check with
/// [`ExchangeSettings::validate`].
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(default)]
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
mod tests {
    use super::*;

    use crate::bound::newton::{NewtonSettings, solve_scaled as newton_solve};
    use crate::bound::variance::certificate;
    use crate::linalg::test_rng::lcg;

    /// A pool of `n` random 2 × 3 poses (O(1) entries).
    fn pool(n: usize, seed: u64) -> Blocks {
        let mut s = seed;
        Blocks::new(Mat::from_fn(2 * n, 3, |_, _| lcg(&mut s)), 2)
    }

    /// `ln det M(w)` of `M(w) = Σ w_i X_iᵀX_i` and the variances
    /// `d_i = tr(X_i M⁻¹ X_iᵀ)`, formed here with nalgebra's Cholesky (no
    /// column scaling, no shared code with the solver).
    fn direct(x: &Blocks, w: &[f64]) -> (f64, Vec<f64>) {
        let (t, p) = (x.t(), x.p());
        let mut m = nalgebra::DMatrix::<f64>::zeros(p, p);
        for (i, &wi) in w.iter().enumerate() {
            let b = x.block(i);
            for a in 0..p {
                for c in 0..p {
                    m[(a, c)] += wi * (0..t).map(|r| b[(r, a)] * b[(r, c)]).sum::<f64>();
                }
            }
        }
        let chol = m.cholesky().expect("positive definite");
        let ld = 2.0 * chol.l().diagonal().iter().map(|v| v.ln()).sum::<f64>();
        let inv = chol.inverse();
        let d = (0..x.n_poses())
            .map(|i| {
                let b = x.block(i);
                let mut s = 0.0;
                for r in 0..t {
                    for a in 0..p {
                        for c in 0..p {
                            s += b[(r, a)] * inv[(a, c)] * b[(r, c)];
                        }
                    }
                }
                s
            })
            .collect();
        (ld, d)
    }

    /// The sum of the `n` largest entries.
    fn top(d: &[f64], n: usize) -> f64 {
        let mut v = d.to_vec();
        v.sort_by(|a, b| b.total_cmp(a));
        v[..n].iter().sum()
    }

    #[test]
    fn settings_out_of_range_are_refused() {
        assert!(ExchangeSettings::default().validate().is_ok());
        let with = |f: fn(&mut ExchangeSettings)| {
            let mut s = ExchangeSettings::default();
            f(&mut s);
            s.validate()
        };
        assert!(with(|s| s.gap_tol = 0.0).is_err());
        assert!(with(|s| s.gap_tol = f64::NAN).is_err());
        assert!(with(|s| s.gap_tol = f64::INFINITY).is_err());
        assert!(with(|s| s.gap_tol = 1e-3).is_ok());
        assert!(with(|s| s.time_limit = 0.0).is_err());
        assert!(with(|s| s.time_limit = f64::NAN).is_err());
        assert!(with(|s| s.time_limit = 1e-3).is_ok());
        assert!(with(|s| s.max_rounds = 0).is_err());
        assert!(with(|s| s.keep = 0).is_err());
        assert!(with(|s| s.max_steps = 0).is_err());
        assert!(with(|s| s.max_rounds = 1).is_ok());
        assert!(with(|s| s.keep = 1).is_ok());
        assert!(with(|s| s.max_steps = 1).is_ok());
    }

    /// The solve is certified and right: `gap = ln_bound − ln_det ≤
    /// gap_tol`; `ln_det` is `ln det M(w)` of the returned weights (formed
    /// here unscaled: 1e-9 relative, rounding of sums of a few dozen O(1)
    /// products); `ln_bound` is at most the certificate (eq. C) at those
    /// weights (the smallest seen, these included); and the Newton barrier
    /// solve (accurate to 1e-10) finds an optimum between the two (1e-8 of
    /// slack for both solvers' rounding).
    #[test]
    fn the_solve_is_certified_and_brackets_the_optimum() {
        for (n_pool, n, seed) in [(12, 3, 1), (30, 5, 2), (9, 6, 3)] {
            let x = pool(n_pool, seed);
            let s = ExchangeSettings::default();
            let out = solve(&x, n, None, &s).unwrap();
            assert!(out.converged, "pool {n_pool}");
            assert!((0.0..=s.gap_tol).contains(&out.gap), "gap {}", out.gap);
            // The gap is taken in scaled units, before `ln_scale` is added
            // to both values (O(10)): 1e-12 of rounding.
            assert!((out.gap - (out.ln_bound - out.ln_det)).abs() < 1e-12);
            let w = &out.weights;
            assert!(w.iter().all(|&v| (0.0..=1.0).contains(&v)));
            assert!((w.iter().sum::<f64>() - n as f64).abs() < 1e-9);
            let (ld, d) = direct(&x, w);
            assert!(
                (ld - out.ln_det).abs() < 1e-9 * (1.0 + ld.abs()),
                "{ld} vs {}",
                out.ln_det
            );
            let cert = certificate(ld, top(&d, n), x.p());
            assert!(out.ln_bound <= cert + 1e-9, "{} > {cert}", out.ln_bound);
            let sc = scale_columns(&x, n).unwrap();
            let nt = newton_solve(&sc, n, None, &NewtonSettings::default(), 1.0);
            assert!(
                out.ln_det - 1e-8 <= nt.ln_det_primal && nt.ln_det_primal <= out.ln_bound + 1e-8,
                "pool {n_pool}: {} not in [{}, {}]",
                nt.ln_det_primal,
                out.ln_det,
                out.ln_bound
            );
            assert!(out.rounds >= 1 && out.rounds <= s.max_rounds);
        }
    }

    /// `N` equal to the pool: every weight 1, no step, no gap, one
    /// evaluation (`ln det` of the whole pool, to 1e-9 relative).
    #[test]
    fn a_design_of_the_whole_pool_is_its_own_optimum() {
        let x = pool(5, 4);
        let out = solve(&x, 5, None, &ExchangeSettings::default()).unwrap();
        assert!(out.weights.iter().all(|&v| v == 1.0));
        assert_eq!((out.gap, out.rounds, out.steps), (0.0, 1, 0));
        assert!(out.converged);
        assert_eq!(out.ln_bound, out.ln_det);
        let (ld, _) = direct(&x, &[1.0; 5]);
        assert!((ld - out.ln_det).abs() < 1e-9 * (1.0 + ld.abs()));
    }

    /// Started at its own optimum, the solve stays there (both results
    /// within `gap_tol` of the optimum: 2·1e-7) in no more rounds; one
    /// round allowed is a round limit: the uniform start, no step, its gap
    /// above `gap_tol` (uniform is not optimal on a random pool) and not
    /// converged.
    #[test]
    fn warm_starts_and_round_limits() {
        let x = pool(30, 5);
        let s = ExchangeSettings::default();
        let cold = solve(&x, 5, None, &s).unwrap();
        let warm = solve(&x, 5, Some(&cold.weights), &s).unwrap();
        assert!(warm.converged);
        assert!(cold.steps > 0, "uniform is not optimal: steps were taken");
        // Each round of steps is counted: the start's evaluation and at
        // least one more.
        assert!(cold.rounds >= 2, "{} rounds", cold.rounds);
        assert!((warm.ln_det - cold.ln_det).abs() <= 2.0 * s.gap_tol);
        assert!(
            warm.rounds <= cold.rounds,
            "{} > {}",
            warm.rounds,
            cold.rounds
        );
        let one = ExchangeSettings {
            max_rounds: 1,
            ..ExchangeSettings::default()
        };
        let out = solve(&x, 5, None, &one).unwrap();
        assert_eq!((out.rounds, out.steps, out.converged), (1, 0, false));
        assert!(out.gap > one.gap_tol);
        assert!(out.weights.iter().all(|&v| v == 5.0 / 30.0));
    }

    /// From a uniform start on a pool larger than `keep`, the capped
    /// multiplicative warm-up and the pruning to the `keep` largest weights
    /// (`keep` raised to `N`) still lead to the optimum: the same `ln det`
    /// as without pruning, within both gaps (2·1e-7); with no warm-up
    /// rounds too.
    #[test]
    fn pruning_after_the_warm_up_keeps_the_optimum() {
        let x = pool(40, 6);
        let s = ExchangeSettings::default();
        let reference = solve(&x, 4, None, &s).unwrap();
        for warmup_rounds in [30, 0] {
            let pruned = ExchangeSettings {
                keep: 1,
                warmup_rounds,
                ..ExchangeSettings::default()
            };
            let out = solve(&x, 4, None, &pruned).unwrap();
            assert!(out.converged, "warm-up {warmup_rounds}");
            assert!(
                (out.ln_det - reference.ln_det).abs() <= 2.0 * s.gap_tol,
                "warm-up {warmup_rounds}: {} vs {}",
                out.ln_det,
                reference.ln_det
            );
        }
    }

    /// A start of the wrong length, or with a negative or non-finite
    /// weight, is refused naming the figure.
    #[test]
    fn bad_starts_are_refused() {
        let x = pool(6, 7);
        let s = ExchangeSettings::default();
        for (w, says) in [
            (vec![0.5; 5], "5 weights for a pool of 6"),
            (vec![0.5, 0.5, -0.1, 0.5, 0.5, 0.5], "weight 2 is -0.1"),
            (vec![0.5, f64::NAN, 0.5, 0.5, 0.5, 0.5], "weight 1 is NaN"),
            (
                vec![0.5, 0.5, 0.5, f64::INFINITY, 0.5, 0.5],
                "weight 3 is inf",
            ),
        ] {
            match solve(&x, 3, Some(&w), &s) {
                Err(BoundError::InvalidWeights(m)) => assert!(m.contains(says), "{m}"),
                other => panic!("{w:?}: {other:?}"),
            }
        }
        assert!(check_start(&[0.0, 1.0, 2.0], 3).is_ok());
    }

    /// `prune` keeps the `k` largest weights and zeroes the rest (all of
    /// them for `k` at least the length); `candidates` is the support plus
    /// the `extra` poses outside it with the largest variances, ascending.
    #[test]
    fn pruning_and_candidates_pick_the_largest() {
        let w = [0.1, 0.5, 0.3, 0.9, 0.2];
        assert_eq!(prune(&w, 2), vec![0.0, 0.5, 0.0, 0.9, 0.0]);
        assert_eq!(prune(&w, 1), vec![0.0, 0.0, 0.0, 0.9, 0.0]);
        assert_eq!(prune(&w, 5), w.to_vec());
        assert_eq!(prune(&w, 7), w.to_vec());
        let w = [0.5, 0.0, 0.0, 1.0, 0.0, 0.0];
        let d = [1.0, 5.0, 2.0, 3.0, 4.0, 0.5];
        assert_eq!(candidates(&w, &d, 2), vec![0, 1, 3, 4]);
        assert_eq!(candidates(&w, &d, 1), vec![0, 1, 3]);
        assert_eq!(candidates(&w, &d, 0), vec![0, 3]);
        assert_eq!(candidates(&w, &d, 10), vec![0, 1, 2, 3, 4, 5]);
    }

    /// The multiplicative step caps the largest `w_i d_i` at 1 and shares
    /// the rest of `N` in proportion to `w_i d_i` (here `w_0 d_0 = 5`
    /// capped, the five others `0.5` each sharing 2: 0.4 each, to
    /// rounding); with fewer than `N` poses carrying weight it refuses and
    /// leaves `w`.
    #[test]
    fn the_multiplicative_step_shares_n_in_proportion() {
        let mut w = vec![0.5; 6];
        let d = [10.0, 1.0, 1.0, 1.0, 1.0, 1.0];
        assert!(multiplicative_step(&mut w, &d, 3));
        assert_eq!(w[0], 1.0);
        assert!(w[1..].iter().all(|&v| (v - 0.4).abs() < 1e-15), "{w:?}");
        let mut w = vec![0.5, 0.5, 0.0, 0.0];
        assert!(!multiplicative_step(&mut w, &[1.0; 4], 3));
        assert_eq!(w, vec![0.5, 0.5, 0.0, 0.0]);
        // A zero variance carries no weight either.
        let mut w = vec![0.5; 4];
        assert!(!multiplicative_step(&mut w, &[1.0, 1.0, 0.0, 0.0], 3));
    }

    /// The warm-up runs only from the uniform start on a pool larger than
    /// `keep` (raised to `N` and `⌈p/t⌉`), one evaluation per
    /// multiplicative step and one for the pruned weights: with the rounds
    /// stopped at their first check (`max_rounds = 1`) the solve reports
    /// `1 + warmup_rounds + 1` evaluations (no step fails from the uniform
    /// start: every weight stays positive) and the `N` poses kept; a pool
    /// of exactly `keep` poses gets neither (one evaluation, uniform).
    #[test]
    fn the_warm_up_runs_only_above_keep() {
        let x = pool(40, 8);
        for warmup_rounds in [0, 1, 3] {
            let s = ExchangeSettings {
                keep: 1,
                warmup_rounds,
                max_rounds: 1,
                ..ExchangeSettings::default()
            };
            let out = solve(&x, 4, None, &s).unwrap();
            assert_eq!(out.rounds, warmup_rounds + 2, "warm-up {warmup_rounds}");
            // `make_feasible` may spread a rounding-size rest of `N` over
            // the pruned poses: 1e-9 tells them apart.
            let kept = out.weights.iter().filter(|&&v| v > 1e-9).count();
            assert_eq!(kept, 4, "warm-up {warmup_rounds}");
        }
        let s = ExchangeSettings {
            keep: 40,
            max_rounds: 1,
            ..ExchangeSettings::default()
        };
        let out = solve(&x, 4, None, &s).unwrap();
        assert_eq!(out.rounds, 1);
        assert!(out.weights.iter().all(|&v| v == 4.0 / 40.0));
    }

    /// Pruned weights whose `M` is singular are widened (`k` doubled, up to
    /// the whole pool) until `M` is regular: only the last of 10 poses
    /// informs the third parameter and, with no warm-up, the uniform
    /// weights tie and the prune keeps the first `k` poses, so the prunes
    /// to 2, 4 and 8 poses are singular and the whole pool is kept: one
    /// evaluation for the start and one for the regular prune (the
    /// singular ones are not counted), the weights uniform (`make_feasible`
    /// rescales their sum: 1e-15).
    #[test]
    fn a_singular_prune_is_widened_to_a_regular_one() {
        let mut m = pool(10, 9).mat().to_owned();
        for r in 0..18 {
            m[(r, 2)] = 0.0;
        }
        let x = Blocks::new(m, 2);
        let s = ExchangeSettings {
            keep: 1,
            warmup_rounds: 0,
            max_rounds: 1,
            ..ExchangeSettings::default()
        };
        let out = solve(&x, 2, None, &s).unwrap();
        assert_eq!(out.rounds, 2);
        assert!(
            out.weights.iter().all(|&v| (v - 0.2).abs() < 1e-15),
            "{:?}",
            out.weights
        );
    }

    #[test]
    fn line_search_finds_stationary_point() {
        // φ'(δ) = 1/(1+δ) − 1/(1−δ)·0.5 ... root where the derivative vanishes.
        let mu = [1.0, -0.5];
        let d = line_search(&mu, 1.0);
        let f: f64 = mu.iter().map(|m| m / (1.0 + d * m)).sum();
        assert!(f.abs() < 1e-12, "{d} {f}");
        assert_eq!(line_search(&[1.0, 0.5], 0.3), 0.3);
        assert_eq!(line_search(&[-1.0], 0.3), 0.0);
    }

    #[test]
    fn multiplicative_step_respects_caps() {
        let mut w = vec![0.5; 6];
        let d = vec![10.0, 1.0, 1.0, 1.0, 1.0, 1.0];
        assert!(multiplicative_step(&mut w, &d, 3));
        assert_eq!(w[0], 1.0);
        assert!((w.iter().sum::<f64>() - 3.0).abs() < 1e-12);
        assert!(w.iter().all(|&v| (0.0..=1.0).contains(&v)));
    }
}

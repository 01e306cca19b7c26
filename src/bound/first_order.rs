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
use super::pair::PairFactors;
use super::variance::{
    Scaled, VarianceWork, certificate_with_prior, check_problem, make_feasible, scale_columns,
    top_sum, variances_into,
};
use crate::blocks::Blocks;
use crate::linalg::simd::clear_upper_simd_state;
use faer::linalg::matmul::matmul;
use faer::{Accum, Mat, Par};
use nalgebra::{DMatrix, SymmetricEigen};
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
    let x = &sc.x;
    let clock = Instant::now();
    let pool = x.n_poses();
    let (t, p) = (x.t(), x.p());
    let mut work = VarianceWork::default();
    let mut scratch = Vec::new();
    if n == pool {
        let w = vec![1.0; pool];
        let e = evaluate(sc, n, &w, &mut work, &mut scratch).expect("full-rank pool");
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
    let mut w = match start {
        Some(mut w) => {
            make_feasible(&mut w, n);
            w
        }
        None => vec![n as f64 / pool as f64; pool],
    };
    let mut eval = match evaluate(sc, n, &w, &mut work, &mut scratch) {
        Some(e) => e,
        None => {
            // A start with a singular M: fall back to the uniform design.
            w = vec![n as f64 / pool as f64; pool];
            evaluate(sc, n, &w, &mut work, &mut scratch).expect("full-rank pool")
        }
    };
    let mut best_bound = eval.bound;
    let mut rounds = 1;
    let support = w.iter().filter(|&&v| v > 0.0).count();
    let keep = s.keep.max(n).max(p.div_ceil(t));
    if !started && support > keep {
        for _ in 0..s.warmup_rounds {
            if !multiplicative_step(&mut w, &eval.d, n) {
                break;
            }
            match evaluate(sc, n, &w, &mut work, &mut scratch) {
                Some(e) => eval = e,
                None => break,
            }
            rounds += 1;
            best_bound = best_bound.min(eval.bound);
        }
        // Prune to the `keep` largest weights; widen if M becomes singular.
        let mut k = keep;
        loop {
            let mut pruned = prune(&w, k);
            make_feasible(&mut pruned, n);
            if let Some(e) = evaluate(sc, n, &pruned, &mut work, &mut scratch) {
                w = pruned;
                eval = e;
                rounds += 1;
                best_bound = best_bound.min(eval.bound);
                break;
            }
            if k >= pool {
                break;
            }
            k = (2 * k).min(pool);
        }
    }

    // --- exchange rounds
    let mut steps = 0;
    let task = crate::progress::Task::start("bound: first-order rounds", None);
    let mut best_w = w.clone();
    let mut best_ln_det = eval.ln_det;
    let step_tol = s.gap_tol / (4.0 * n as f64);
    let mut pair = PairWork::new(t, p);
    loop {
        if eval.ln_det > best_ln_det {
            best_ln_det = eval.ln_det;
            best_w.clone_from(&w);
        }
        best_bound = best_bound.min(eval.bound);
        task.inc(1);
        task.note(|| {
            format!(
                "gap {:.2e} -> {:.0e}, {steps} steps",
                best_bound - best_ln_det,
                s.gap_tol
            )
        });
        if best_bound - best_ln_det <= s.gap_tol
            || rounds >= s.max_rounds
            || clock.elapsed().as_secs_f64() > s.time_limit
        {
            break;
        }
        let cand = candidates(&w, &eval.d, s.extra);
        steps += exchange_round(
            x,
            &cand,
            &mut w,
            eval.minv,
            &eval.d,
            step_tol,
            s.max_steps,
            &mut pair,
        );
        // Rounding in the Woodbury updates can leave tiny negative weights.
        make_feasible(&mut w, n);
        match evaluate(sc, n, &w, &mut work, &mut scratch) {
            Some(e) => eval = e,
            None => {
                // Should not happen (the line search keeps M positive
                // definite); stop with the best point.
                rounds += 1;
                break;
            }
        }
        rounds += 1;
    }
    ExchangeOutcome {
        gap: best_bound - best_ln_det,
        converged: best_bound - best_ln_det <= s.gap_tol,
        weights: best_w,
        ln_det: best_ln_det,
        ln_bound: best_bound,
        rounds,
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

/// Reused memory of the pairwise steps.
struct PairWork {
    ut: Mat<f64>,
    wm: Mat<f64>,
    g: Mat<f64>,
    wr: Mat<f64>,
    v: Mat<f64>,
    wv: Mat<f64>,
    sq: Vec<f64>,
    mu: Vec<f64>,
    s: Vec<f64>,
    gs: Vec<f64>,
    pf: PairFactors,
}

impl PairWork {
    fn new(t: usize, p: usize) -> Self {
        Self {
            ut: Mat::zeros(p, 2 * t),
            wm: Mat::zeros(p, 2 * t),
            g: Mat::zeros(2 * t, 2 * t),
            wr: Mat::zeros(p, 2 * t),
            v: Mat::zeros(2 * t, 2 * t),
            wv: Mat::zeros(p, 2 * t),
            sq: Vec::new(),
            mu: Vec::with_capacity(2 * t),
            s: Vec::with_capacity(2 * t),
            gs: vec![0.0; 4 * t * t],
            pf: PairFactors::new(t),
        }
    }
}

/// Pairwise steps on the candidate set `cand`, starting from `M⁻¹ = minv`
/// and the full-pool variances `d`. Returns the number of steps taken.
#[allow(clippy::too_many_arguments)]
fn exchange_round(
    x: &Blocks,
    cand: &[usize],
    w: &mut [f64],
    mut minv: Mat<f64>,
    d: &[f64],
    step_tol: f64,
    max_steps: usize,
    pw: &mut PairWork,
) -> usize {
    let (t, p) = (x.t(), x.p());
    let xm = x.mat();
    let kn = cand.len();
    // Candidate blocks, contiguous.
    let xk = Mat::from_fn(kn * t, p, |r, c| xm[(cand[r / t] * t + r % t, c)]);
    let mut dk: Vec<f64> = cand.iter().map(|&i| d[i]).collect();
    let mut pk = Mat::<f64>::zeros(kn * t, 2 * t);
    const FULL: f64 = 1.0 - 1e-12;
    let mut steps = 0;
    while steps < max_steps {
        // i: largest d among w < 1; j: smallest d among w > 0.
        let mut bi = usize::MAX;
        let mut bj = usize::MAX;
        for k in 0..kn {
            let wk = w[cand[k]];
            if wk < FULL && (bi == usize::MAX || dk[k] > dk[bi]) {
                bi = k;
            }
            if wk > 0.0 && (bj == usize::MAX || dk[k] < dk[bj]) {
                bj = k;
            }
        }
        if bi == usize::MAX || bj == usize::MAX || bi == bj || dk[bi] - dk[bj] <= step_tol {
            break;
        }
        let (i, j) = (cand[bi], cand[bj]);
        // Uᵀ = [X_iᵀ X_jᵀ] (p × 2t), W = M⁻¹Uᵀ, G = U W.
        for r in 0..t {
            for c in 0..p {
                pw.ut[(c, r)] = xk[(bi * t + r, c)];
                pw.ut[(c, t + r)] = xk[(bj * t + r, c)];
            }
        }
        matmul(
            pw.wm.as_mut(),
            Accum::Replace,
            minv.as_ref(),
            pw.ut.as_ref(),
            1.0,
            Par::Seq,
        );
        matmul(
            pw.g.as_mut(),
            Accum::Replace,
            pw.ut.transpose(),
            pw.wm.as_ref(),
            1.0,
            Par::Seq,
        );
        let m2 = 2 * t;
        for a in 0..m2 {
            for b in 0..m2 {
                pw.gs[a * m2 + b] = 0.5 * (pw.g[(a, b)] + pw.g[(b, a)]);
            }
        }
        let Some(delta) = pair_step(pw, t, (1.0 - w[i]).min(w[j])) else {
            break;
        };
        // Weights; exact bounds when a pose fills up or empties.
        if delta >= 1.0 - w[i] {
            w[i] = 1.0;
        } else {
            w[i] += delta;
        }
        if delta >= w[j] {
            w[j] = 0.0;
        } else {
            w[j] -= delta;
        }
        // d_k −= tr(P_k R P_kᵀ), P = X_K W;  M⁻¹ −= W R Wᵀ   (X2)
        // With R = E diag(s) Eᵀ: tr(P_k R P_kᵀ) = Σ_l s_l ‖X_k (W E)_l‖², one
        // product X_K (W E) instead of two.
        matmul(
            pw.wv.as_mut(),
            Accum::Replace,
            pw.wm.as_ref(),
            pw.v.as_ref(),
            1.0,
            Par::Seq,
        );
        matmul(
            pk.as_mut(),
            Accum::Replace,
            xk.as_ref(),
            pw.wv.as_ref(),
            1.0,
            Par::Seq,
        );
        // gemm's AVX-512 kernels can leave dirty upper registers, which
        // slow every SSE instruction after them (see `clear_upper_simd_state`).
        clear_upper_simd_state();
        // Row sums Σ_l s_l (X_K W E)²_rl, vectorised along the rows, then
        // per pose.
        pw.sq.clear();
        pw.sq.resize(kn * t, 0.0);
        for (l, &lam) in pw.s.iter().enumerate() {
            let col = pk
                .col(l)
                .try_as_col_major()
                .expect("a column of an owned matrix is contiguous")
                .as_slice();
            for (s, &v) in pw.sq.iter_mut().zip(col) {
                *s += lam * v * v;
            }
        }
        for (dkv, rows) in dk.iter_mut().zip(pw.sq.chunks_exact(t)) {
            *dkv -= rows.iter().sum::<f64>();
        }
        // M⁻¹ −= (W E) diag(s) (W E)ᵀ.
        for l in 0..m2 {
            for c in 0..p {
                pw.wr[(c, l)] = pw.wv[(c, l)] * pw.s[l];
            }
        }
        matmul(
            minv.as_mut(),
            Accum::Add,
            pw.wr.as_ref(),
            pw.wv.transpose(),
            -1.0,
            Par::Seq,
        );
        clear_upper_simd_state();
        steps += 1;
    }
    steps
}

/// The step of the pair whose symmetric matrix `G` is in `pw.gs`: the exact
/// line search (eq. X1) over `[0, hi]`, then `R = E diag(s) Eᵀ` (eq. X2) with
/// `E` in `pw.v` and `s` in `pw.s`. `None` when no step improves.
fn pair_step(pw: &mut PairWork, t: usize, hi: f64) -> Option<f64> {
    let m2 = 2 * t;
    let fast = pw.pf.factor(&pw.gs);
    pw.mu.clear();
    if fast {
        pw.mu.extend_from_slice(pw.pf.mu());
    } else {
        pw.mu.extend(general_mu(&pw.gs, t).iter());
    }
    let delta = line_search(&pw.mu, hi);
    if delta <= 0.0 {
        return None;
    }
    pw.s.clear();
    if fast {
        let (e, sv) = pw.pf.update(delta);
        for a in 0..m2 {
            for c in 0..m2 {
                pw.v[(a, c)] = e[a * m2 + c];
            }
        }
        pw.s.extend_from_slice(sv);
    } else {
        let (e, sv) = general_r(&pw.gs, t, delta)?;
        for a in 0..m2 {
            for c in 0..m2 {
                pw.v[(a, c)] = e[(a, c)];
            }
        }
        pw.s.extend(sv.iter());
    }
    Some(delta)
}

/// `D = diag(I_t, −I_t)`.
fn sign_matrix(t: usize) -> DMatrix<f64> {
    DMatrix::from_fn(2 * t, 2 * t, |a, b| match (a == b, a < t) {
        (false, _) => 0.0,
        (true, true) => 1.0,
        (true, false) => -1.0,
    })
}

/// The eigenvalues `μ` of `D G` for a pair matrix `G` (row-major, `2t × 2t`)
/// that is only positive semidefinite: those of `G^{1/2} D G^{1/2}`. The
/// general path of [`PairFactors`].
fn general_mu(g: &[f64], t: usize) -> Vec<f64> {
    let m = 2 * t;
    let g = DMatrix::from_row_slice(m, m, &g[..m * m]);
    let eg = SymmetricEigen::new(g);
    let sq = DMatrix::from_diagonal(&eg.eigenvalues.map(|l| l.max(0.0).sqrt()));
    let half = &eg.eigenvectors * sq * eg.eigenvectors.transpose();
    let b = &half * sign_matrix(t) * &half;
    let b = (&b + b.transpose()) * 0.5;
    SymmetricEigen::new(b).eigenvalues.iter().copied().collect()
}

/// `R = δ (I + δ D G)⁻¹ D` (eq. X2) as `V diag(λ) Vᵀ` for a positive
/// semidefinite `G`: the general path of [`PairFactors::update`]. `None`
/// if `I + δ D G` is singular.
fn general_r(g: &[f64], t: usize, delta: f64) -> Option<(DMatrix<f64>, Vec<f64>)> {
    let m = 2 * t;
    let g = DMatrix::from_row_slice(m, m, &g[..m * m]);
    let dm = sign_matrix(t);
    let bmat = DMatrix::<f64>::identity(m, m) + &dm * &g * delta;
    let r = bmat.try_inverse()? * &dm * delta;
    let r = (&r + r.transpose()) * 0.5;
    let er = SymmetricEigen::new(r);
    Some((er.eigenvectors, er.eigenvalues.iter().copied().collect()))
}

/// The step `δ ∈ [0, hi]` maximising `φ(δ) = Σ_k ln(1 + δ μ_k)` (eq. X1):
/// `hi` if `φ'(hi) ≥ 0`, else the root of the decreasing `φ'` by safeguarded
/// Newton. `φ'(0) = Σ μ_k = d_i − d_j > 0` for an improving pair.
#[must_use]
pub fn line_search(mu: &[f64], hi: f64) -> f64 {
    let dphi = |x: f64| -> f64 {
        let mut s = 0.0;
        for &m in mu {
            let den = 1.0 + x * m;
            if den <= 0.0 {
                return f64::NEG_INFINITY;
            }
            s += m / den;
        }
        s
    };
    let d2phi = |x: f64| -> f64 { -mu.iter().map(|&m| (m / (1.0 + x * m)).powi(2)).sum::<f64>() };
    if hi <= 0.0 || dphi(0.0) <= 0.0 {
        return 0.0;
    }
    let fhi = dphi(hi);
    if fhi >= 0.0 {
        return hi;
    }
    let (mut lo, mut up) = (0.0, hi);
    let mut x = 0.0;
    for _ in 0..100 {
        let f = dphi(x);
        if f > 0.0 {
            lo = x;
        } else {
            up = x;
        }
        let mut nx = x - f / d2phi(x);
        if !(nx > lo && nx < up && f.is_finite()) {
            nx = 0.5 * (lo + up);
        }
        if (nx - x).abs() <= 1e-15 * up.max(1e-300) || up - lo <= 1e-15 * up {
            x = nx;
            break;
        }
        x = nx;
    }
    // Stay on the side where φ' ≥ 0 is not required; any point of [0, hi]
    // with 1 + δμ > 0 is feasible and improves on δ = 0 by concavity.
    x.clamp(0.0, hi)
}

#[cfg(test)]
mod tests {
    use super::*;

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

//! The relaxation (R) on a candidate set by a primal log-barrier Newton
//! method: an alternative to Clarabel for the candidate subproblems that
//! exploits the structure of `ln det M(w)` instead of lifting it into a
//! `2p × 2p` PSD cone.
//!
//! For barrier weight μ the method maximises
//!
//! `F_μ(w) = ln det M(w) + μ Σ_i [ln w_i + ln(1 − w_i)]  s.t.  Σ w = N`
//!
//! by Newton steps that keep `Σ w = N`. With `M = L Lᵀ` and `Y = X L⁻ᵀ`
//! (blocks `Y_i`, `A_i = Y_iᵀY_i`), the gradient of `ln det M(w)` is the
//! variance `d_i = tr A_i` and its Hessian is `−Q`, `Q_ij = tr(A_i A_j) =
//! ‖Y_i Y_jᵀ‖²_F`. The step solves `K Δ = g − ν 1`, `1ᵀΔ = 0` with `K = Q +
//! μ Diag(1/w² + 1/(1−w)²)` positive definite (one Cholesky, two solves), and
//! a backtracking line search keeps `w` strictly inside `(0, 1)`. μ falls
//! by `mu_factor` (default 100) once the Newton decrement is small, until the barrier's
//! suboptimality bound `2nμ` is below the target.
//!
//! Cost per step: the `n × p(p+1)/2 × n` product for Q and an `n × n`
//! Cholesky — about 0.2 GFlop for the PUMA's ~700 candidates, against Clarabel's
//! factorisation of a KKT system with a dense `p(2p+1)/2` PSD block. The
//! result is not trusted: [`super::relaxation_bound`] certifies it with
//! eq. (C) on the whole pool, as it does Clarabel's.
//!
//! The kernels called here with a `Par` argument run sequentially
//! (`Par::Seq`), and the binary sets faer's global parallelism (used by its
//! Cholesky of `K`) to sequential, so that the weights never depend on the
//! number of threads.

use super::conic::{ConicOutcome, ConicStatus};
use super::variance::Scaled;
use crate::linalg::chol::ln_det_spd;
use faer::linalg::triangular_solve::solve_lower_triangular_in_place;
use faer::{Mat, Par, Side};
use serde::{Deserialize, Serialize};
use std::time::Instant;

/// Settings of the Newton barrier solve: [`NewtonSettings::builder`]
/// (validated) or the defaults in [`Default`].
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(default)]
#[non_exhaustive]
pub struct NewtonSettings {
    /// Target of the barrier's suboptimality bound `2nμ` (ln det units).
    /// Default 1e-10.
    pub tol: f64,
    /// Newton steps over all barrier weights. Default 300.
    pub max_steps: usize,
    /// Barrier weight reduction per stage. Default 100: on the PUMA and
    /// `ur5:pose` lattices it takes 30 % fewer Newton steps than 10 to the
    /// same certified gap (`bound` prints them).
    pub mu_factor: f64,
}

impl Default for NewtonSettings {
    fn default() -> Self {
        Self {
            tol: 1e-10,
            max_steps: 300,
            mu_factor: 100.0,
        }
    }
}

crate::settings::settings_builder! {
    /// Validated construction of [`NewtonSettings`].
    NewtonSettingsBuilder for NewtonSettings, error super::BoundError {
        /// Target of the suboptimality bound `2nμ` (default 1e-10).
        tol: f64,
        /// Most Newton steps (default 300).
        max_steps: usize,
        /// Barrier weight reduction per stage, `> 1` (default 100).
        mu_factor: f64,
    }
}

impl NewtonSettings {
    /// Checks every field's range.
    pub fn validate(&self) -> Result<(), super::BoundError> {
        super::error::positive("newton.tol", self.tol)?;
        if self.mu_factor.is_nan() || self.mu_factor <= 1.0 {
            return Err(super::BoundError::InvalidSetting {
                name: "newton.mu_factor",
                value: self.mu_factor.to_string(),
                reason: "must be > 1",
            });
        }
        if self.max_steps == 0 {
            return Err(super::BoundError::InvalidSetting {
                name: "newton.max_steps",
                value: "0".into(),
                reason: "must be ≥ 1",
            });
        }
        Ok(())
    }
}

/// `ln det M(w)`, the variances `d` and the lower triangle of the matrix
/// `Q` at `w` (the upper one is not written), or `None` if
/// `M(w)` is not numerically positive definite.
///
/// `Q_ij = ‖Y_i Y_jᵀ‖²_F = tr(A_i A_j)` with `A_i = Y_iᵀY_i`, formed as `Z
/// Zᵀ` where the row `z_i` packs the upper triangle of `A_i` with its
/// off-diagonal entries times √2, so that `z_i·z_j = tr(A_i A_j)`:
/// `n²·p(p+1)/4` flops in one matrix product, where the blocks of the
/// `t·n × t·n` Gram matrix `Y Yᵀ` cost `(t·n)²·p/2` plus a strided sum.
/// Measured (`bound`, Newton seconds): `ur5:pose` (`t = 6`, `p = 30`) 2.07 →
/// 0.63 s; the PUMA (`t = 3`, where the Gram form has fewer flops) 0.59 →
/// 0.52 s.
fn derivatives(sc: &Scaled, w: &[f64], q: &mut Mat<f64>, d: &mut [f64]) -> Option<f64> {
    let x = &sc.x;
    let t = x.t();
    let m = sc.information(w);
    let llt = m.llt(Side::Lower).ok()?;
    let l = llt.L();
    let ld = crate::linalg::chol::ln_det_of_factor(l)?;
    let mut y = x.mat().to_owned();
    solve_lower_triangular_in_place(l, y.as_mut().transpose_mut(), Par::Seq);
    crate::linalg::simd::clear_upper_simd_state();
    q_packed(y.as_ref(), t, q, d);
    Some(ld)
}

/// `Q = Z Zᵀ` (lower triangle) and `d_i = tr A_i` from the packed rows
/// `z_i` of `A_i = Y_iᵀY_i` (see [`derivatives`]).
fn q_packed(y: faer::MatRef<'_, f64>, t: usize, q: &mut Mat<f64>, d: &mut [f64]) {
    let p = y.ncols();
    let n = y.nrows() / t;
    let m = p * (p + 1) / 2;
    // Zᵀ, so that each pose's packed row is a contiguous column.
    let mut zt = Mat::<f64>::zeros(m, n);
    for i in 0..n {
        let yi = y.subrows(i * t, t);
        let mut k = 0;
        let mut tr = 0.0;
        for a in 0..p {
            for b in a..p {
                let mut s = 0.0;
                for r in 0..t {
                    s += yi[(r, a)] * yi[(r, b)];
                }
                zt[(k, i)] = if a == b {
                    tr += s;
                    s
                } else {
                    std::f64::consts::SQRT_2 * s
                };
                k += 1;
            }
        }
        d[i] = tr;
    }
    faer::linalg::matmul::triangular::matmul(
        q.as_mut(),
        faer::linalg::matmul::triangular::BlockStructure::TriangularLower,
        faer::Accum::Replace,
        zt.as_ref().transpose(),
        faer::linalg::matmul::triangular::BlockStructure::Rectangular,
        zt.as_ref(),
        faer::linalg::matmul::triangular::BlockStructure::Rectangular,
        1.0,
        Par::Seq,
    );
}

/// Centring of the barrier stages before the last: a stage ends when the
/// Newton decrement `λ² ≤ CENTERING·μ`. Measured (`bound`, idle machine):
/// against `λ² ≤ 1e-12` in every stage, 3 takes 28 % fewer Newton steps on
/// the PUMA lattice (113 → 81) and 27 % fewer on `ur5:pose` (160 → 117), to
/// the same certified bound; 10 saves a few more but leaves stages less
/// centred than the standard `λ²/μ ≲ 1` region.
const CENTERING: f64 = 3.0;

/// `F_μ` at `w` (`None` outside the domain).
fn barrier_value(sc: &Scaled, w: &[f64], mu: f64) -> Option<f64> {
    if w.iter().any(|&v| !(v > 0.0 && v < 1.0)) {
        return None;
    }
    let ld = ln_det_spd(sc.information(w).as_ref())?;
    Some(ld + mu * w.iter().map(|&v| v.ln() + (1.0 - v).ln()).sum::<f64>())
}

/// A strictly interior start: the warm point (candidate weights, feasible
/// or not) clamped to `[0, 1]` and scaled to `Σ w = N` under the caps
/// ([`capped_to_sum`]), then blended 9:1 with uniform `N/n` (which keeps
/// `Σ w = N` and every weight inside `(0, 1)` when `N < n`); uniform when
/// there is no warm point, its support is too small to carry `N`, or the
/// blend is not interior.
fn interior_start(warm: Option<&[f64]>, n: usize, nf: f64) -> Vec<f64> {
    let uniform = nf / n as f64;
    let blend = match warm {
        Some(v) if v.len() == n => {
            let clamped: Vec<f64> = v.iter().map(|x| x.clamp(0.0, 1.0)).collect();
            capped_to_sum(&clamped, nf)
        }
        _ => None,
    }
    .map(|p| -> Vec<f64> { p.iter().map(|&x| 0.9 * x + 0.1 * uniform).collect() });
    match blend {
        Some(mut w) => {
            // Σ w is N to rounding; make it N to the last bits the Newton
            // steps keep (`1ᵀΔ = 0`). `nf / s` is 1 to rounding, so `*=`
            // as `/=` is equivalent in value (issue #30's sample).
            let s: f64 = w.iter().sum();
            w.iter_mut().for_each(|v| *v *= nf / s);
            // A guard for a rounding-degenerate blend: with `N < n` (the
            // caller's case) every blended weight lies in
            // `[0.1·N/n, 0.9 + 0.1·N/n]`, inside `(0, 1)`, so `>` as `>=`,
            // `<` as `<=` and `&&` as `||` here are equivalent on every
            // input the tests reach (issue #30's sample).
            if w.iter().all(|&v| v > 0.0 && v < 1.0) {
                w
            } else {
                vec![uniform; n]
            }
        }
        None => vec![uniform; n],
    }
}

/// `min(c·p_i, 1)` with the `c ≥ 0` that makes the entries sum to `N`
/// (water-filling: the largest entries are capped at 1 in turn and the rest
/// scaled to what is left, so the uncapped entries keep their ratios), or
/// `None` when the positive entries cannot sum to `N` under the caps.
/// Each cap raises `c` (the capped entry had `c·p_i > 1`), so the entries
/// capped earlier stay capped.
fn capped_to_sum(p: &[f64], nf: f64) -> Option<Vec<f64>> {
    let mut order: Vec<usize> = (0..p.len()).collect();
    order.sort_unstable_by(|&a, &b| p[b].total_cmp(&p[a]));
    let mut rest: f64 = p.iter().sum();
    for (capped, &i) in order.iter().enumerate() {
        let c = (nf - capped as f64) / rest;
        if !(rest > 0.0 && c >= 0.0) {
            return None;
        }
        if c * p[i] <= 1.0 {
            return Some(p.iter().map(|&x| (c * x).min(1.0)).collect());
        }
        rest -= p[i];
    }
    None
}

/// The Newton direction of `F_μ` on `Σ w = N`: `K = Q + μ D`,
/// `g = d + μ (1/w − 1/(1 − w))`, `Δ = K⁻¹g − ν K⁻¹1` with `ν` making
/// `1ᵀΔ = 0`, and the decrement `λ² = gᵀΔ` (`= ΔᵀKΔ`); `None` when `K` is
/// not positive definite or `λ²` is not finite.
fn newton_direction(
    q: &Mat<f64>,
    d: &[f64],
    w: &[f64],
    mu: f64,
    ones: &Mat<f64>,
) -> Option<(Vec<f64>, f64)> {
    use faer::linalg::solvers::Solve;
    let n = w.len();
    let mut k = q.clone();
    let mut g = Mat::<f64>::zeros(n, 1);
    for i in 0..n {
        let (a, b) = (w[i], 1.0 - w[i]);
        k[(i, i)] += mu * (1.0 / (a * a) + 1.0 / (b * b));
        g[(i, 0)] = d[i] + mu * (1.0 / a - 1.0 / b);
    }
    let kc = k.llt(Side::Lower).ok()?;
    let u = kc.solve(&g);
    let v = kc.solve(ones);
    let nu = u.col(0).sum() / v.col(0).sum();
    let delta: Vec<f64> = (0..n).map(|i| u[(i, 0)] - nu * v[(i, 0)]).collect();
    let lambda2: f64 = (0..n).map(|i| g[(i, 0)] * delta[i]).sum();
    lambda2.is_finite().then_some((delta, lambda2))
}

/// The largest step along `delta` inside `(0, 1)` (at 0.99 of the way to
/// the boundary), then backtracking (halving, at most 60 times) until
/// `F_μ` rises by a quarter of the decrement's prediction (Armijo); the
/// accepted point, or `None` when no step ascends (rounding).
fn line_search(
    sc: &Scaled,
    w: &[f64],
    delta: &[f64],
    lambda2: f64,
    mu: f64,
    ld: f64,
) -> Option<Vec<f64>> {
    let n = w.len();
    let mut s_max = 1.0f64;
    for i in 0..n {
        if delta[i] < 0.0 {
            s_max = s_max.min(0.99 * w[i] / -delta[i]);
        // `delta[i] >= 0.0` is equivalent on every direction without a
        // component of exactly −0.0 (a zero component's room is then +∞,
        // which leaves `s_max` as it is).
        } else if delta[i] > 0.0 {
            s_max = s_max.min(0.99 * (1.0 - w[i]) / delta[i]);
        }
    }
    let f0 = ld + mu * w.iter().map(|&v| v.ln() + (1.0 - v).ln()).sum::<f64>();
    let mut s = s_max;
    let mut trial = vec![0.0; n];
    for _ in 0..60 {
        for i in 0..n {
            trial[i] = w[i] + s * delta[i];
        }
        if barrier_value(sc, &trial, mu).is_some_and(|f1| f1 >= f0 + 0.25 * s * lambda2) {
            return Some(trial);
        }
        s *= 0.5;
    }
    None
}

/// Solves (R) on the scaled candidate blocks `sc.x` from `warm` (candidate
/// weights, feasible or not; `None` for uniform), returning the result in
/// Clarabel's outcome type: weights, status (`Solved` when the barrier
/// bound met `tol`, `MaxIterations` otherwise, `NumericalError` when no
/// positive definite start exists), Newton steps as iterations, and
/// `ln det M(w)` unscaled as the primal value (the dual value is that plus
/// the barrier bound `2nμ`, an estimate, not a certificate).
pub(crate) fn solve_scaled(
    sc: &Scaled,
    n_design: usize,
    warm: Option<&[f64]>,
    settings: &NewtonSettings,
    gap_hint: f64,
) -> ConicOutcome {
    let clock = Instant::now();
    let x = &sc.x;
    let n = x.n_poses();
    let nf = n_design as f64;
    let fail = |weights: Vec<f64>, status: ConicStatus, it: u32| ConicOutcome {
        weights,
        status,
        iterations: it,
        retried: false,
        ln_det_primal: f64::NAN,
        ln_det_dual: f64::NAN,
        seconds: clock.elapsed().as_secs_f64(),
    };
    if n_design >= n {
        let w = vec![1.0; n];
        return match ln_det_spd(sc.information(&w).as_ref()) {
            Some(ld) => ConicOutcome {
                ln_det_primal: ld + sc.ln_scale,
                ln_det_dual: ld + sc.ln_scale,
                ..fail(w, ConicStatus::Solved, 0)
            },
            None => fail(w, ConicStatus::NumericalError, 0),
        };
    }
    let mut w = interior_start(warm, n, nf);

    let mut q = Mat::<f64>::zeros(n, n);
    let mut d = vec![0.0; n];
    // Start μ where the barrier's bound 2nμ matches the gap known so far.
    let mut mu = (gap_hint.max(settings.tol) / (2.0 * n as f64)).max(1e-300);
    let mut steps = 0u32;
    let mut status = ConicStatus::MaxIterations;
    let mut ld = f64::NAN;
    let ones = Mat::<f64>::from_fn(n, 1, |_, _| 1.0);
    let task = crate::progress::Task::start("newton steps", None);
    while (steps as usize) < settings.max_steps {
        task.inc(1);
        task.note(|| format!("{n} weights, barrier bound {:.1e}", 2.0 * n as f64 * mu));
        let Some(l) = derivatives(sc, &w, &mut q, &mut d) else {
            return fail(w, ConicStatus::NumericalError, steps);
        };
        ld = l;
        steps += 1;
        let Some((delta, lambda2)) = newton_direction(&q, &d, &w, mu, &ones) else {
            return fail(w, ConicStatus::NumericalError, steps);
        };
        // Centred enough: at the last barrier weight, λ² ≤ tol (the
        // distance to the central point, about λ²/2 in F_μ, is then below
        // the barrier's own bound 2nμ ≤ tol); before it, λ² ≤ CENTERING·μ
        // (the decrement of F_μ/μ below CENTERING), which the next, smaller
        // μ corrects anyway. An absolute 1e-12 stalled on a 4,096-pose PUMA
        // lattice: rounding held λ² at 1.2e-12 for 270 steps.
        // Equivalent in value, time only: `<=` as `>` here (the last stage
        // centred to CENTERING·μ ≈ 1.5e-10/n, the others to tol) and
        // `CENTERING * mu` as `+` below (every stage but the last ends
        // after one step): the last stage still ends at λ² of order tol,
        // the weights and ln det agree within the tests' 1e-7. So is
        // `CENTERING * mu` as `/` (every stage but the last ends after one
        // step, as with `+`). And `2.0 * n as f64 * mu` as `… + mu` (the
        // test then never holds) is equivalent in value: at the last stage
        // `CENTERING·μ ≤ 3·tol/(2n) < tol` (`n ≥ 2` here, as `N < n`), so
        // the other branch's `(CENTERING * mu).max(tol)` is `tol` too.
        let centred = if 2.0 * n as f64 * mu <= settings.tol {
            settings.tol
        } else {
            (CENTERING * mu).max(settings.tol)
        };
        // Centred, or no ascent left at this μ (rounding): the next μ, or
        // done at the last.
        let next_mu = lambda2 <= centred
            || match line_search(sc, &w, &delta, lambda2, mu, ld) {
                Some(t) => {
                    w = t;
                    false
                }
                None => true,
            };
        if next_mu {
            if 2.0 * n as f64 * mu <= settings.tol {
                status = ConicStatus::Solved;
                break;
            }
            mu /= settings.mu_factor;
        }
    }
    let ld = ln_det_spd(sc.information(&w).as_ref()).unwrap_or(ld);
    ConicOutcome {
        ln_det_primal: ld + sc.ln_scale,
        ln_det_dual: ld + 2.0 * n as f64 * mu + sc.ln_scale,
        weights: w,
        status,
        iterations: steps,
        retried: false,
        seconds: clock.elapsed().as_secs_f64(),
    }
}

#[cfg(test)]
mod tests;

//! The variance function d_i(w) = tr(X_i M(w)⁻¹ X_iᵀ) of a whole pool from one
//! Cholesky factorisation and one triangular solve, the column scaling, and
//! the solver-free certificate.
//!
//! With M = L Lᵀ and Y = X L⁻ᵀ, d_i is the squared Frobenius norm of the `t`
//! rows of Y that belong to pose i. The certificate (eq. C below) turns any
//! positive definite M(w) into an upper bound on the relaxation's optimum.

use super::BoundError;
use crate::blocks::Blocks;
use crate::linalg::chol::ln_det_of_factor;
use crate::linalg::rank;
use crate::linalg::simd::clear_upper_simd_state;
use faer::linalg::triangular_solve::solve_lower_triangular_in_place;
use faer::reborrow::{Reborrow, ReborrowMut};
use faer::{Mat, MatRef, Par, Side};

/// A column-scaled copy of a pool Jacobian, `X̃ = X·S⁻¹`, and of a prior
/// `M̃0 = S⁻¹ M0 S⁻¹` when there is one.
///
/// `ln det M(w) = ln det M̃(w) + ln_scale` with `ln_scale = 2·Σ_j ln s_j`;
/// the variances d_i are invariant under the scaling.
#[derive(Clone, Debug)]
pub struct Scaled {
    /// The scaled blocks.
    pub x: Blocks,
    /// Column scale factors `s_j > 0`.
    pub s: Vec<f64>,
    /// `2·Σ_j ln s_j`, added to a scaled ln det to unscale it.
    pub ln_scale: f64,
    /// The scaled prior information `M̃0`, if any.
    pub m0: Option<Mat<f64>>,
}

impl Scaled {
    /// `M̃(w) = M̃0 + Σ_i w_i X̃_iᵀX̃_i` ([`information`] plus the prior).
    #[must_use]
    pub fn information(&self, w: &[f64]) -> Mat<f64> {
        let m = information(&self.x, w);
        match &self.m0 {
            Some(m0) => m + m0,
            None => m,
        }
    }

    /// `tr(M⁻¹ M̃0)`, the prior's share of `tr(M⁻¹ M̃(w*))` in the
    /// certificate (0 without a prior).
    #[must_use]
    pub fn prior_trace(&self, m_inv: MatRef<'_, f64>) -> f64 {
        let Some(m0) = &self.m0 else { return 0.0 };
        let p = m0.nrows();
        let mut s = 0.0;
        for c in 0..p {
            for r in 0..p {
                s += m_inv[(r, c)] * m0[(c, r)];
            }
        }
        s
    }
}

/// Checks the shape and entries of a relaxation problem: `1 ≤ N ≤ pool size`,
/// `N·t ≥ p`, and every Jacobian entry finite.
pub fn check_problem(x: &Blocks, n: usize) -> Result<(), BoundError> {
    check_problem_with_prior(x, n, false)
}

/// [`check_problem`]; with a prior (`with_prior`), `N·t < p` is allowed (the
/// prior may supply the missing rank; [`scale_columns_with_prior`] checks
/// that it does).
pub fn check_problem_with_prior(x: &Blocks, n: usize, with_prior: bool) -> Result<(), BoundError> {
    let (pool, t, p) = (x.n_poses(), x.t(), x.p());
    if n > pool {
        return Err(BoundError::TooManyPoses { n, pool });
    }
    if (n * t < p && !with_prior) || n == 0 {
        return Err(BoundError::TooFewRows {
            n,
            t,
            rows: n * t,
            p,
            need: p.div_ceil(t).max(1),
        });
    }
    let m = x.mat();
    for c in 0..m.ncols() {
        for r in 0..m.nrows() {
            let v = m[(r, c)];
            if !v.is_finite() {
                return Err(BoundError::NonFinite {
                    row: r,
                    col: c,
                    value: v,
                });
            }
        }
    }
    Ok(())
}

/// Scales every column so that the uniform design `w_i = N / pool` has an
/// information matrix with unit diagonal: `s_j = ‖X_{:,j}‖·√(N / pool)`.
///
/// Errors with [`BoundError::RankDeficient`] on a zero column or when the
/// scaled Gram matrix has `λ_min/λ_max ≤ 1/``linalg::rank::MAX_CONDITION`
/// (the rank rule every command shares; a singular-value ratio of `3.2e-7`).
pub fn scale_columns(x: &Blocks, n: usize) -> Result<Scaled, BoundError> {
    scale_columns_with_prior(x, None, n)
}

/// [`scale_columns`] with a prior `M0`: `s_j = √(‖X_{:,j}‖²·N/pool +
/// M0_jj)`, so that `M0` plus the uniform design has unit diagonal; the
/// rank test is on that matrix (a direction the pool cannot see is fine
/// when the prior sees it).
pub fn scale_columns_with_prior(
    x: &Blocks,
    m0: Option<MatRef<'_, f64>>,
    n: usize,
) -> Result<Scaled, BoundError> {
    let m = x.mat();
    let (rows, p) = (m.nrows(), m.ncols());
    let f = (n as f64 / x.n_poses() as f64).sqrt();
    let norms: Vec<f64> = (0..p).map(|c| m.col(c).norm_l2()).collect();
    let s: Vec<f64> = match m0 {
        None => norms.iter().map(|v| v * f).collect(),
        Some(m0) => norms
            .iter()
            .enumerate()
            .map(|(j, v)| ((v * f).powi(2) + m0[(j, j)].max(0.0)).sqrt())
            .collect(),
    };
    // `v.is_nan()` too: a NaN scale is no scale.
    let zero = s.iter().filter(|&&v| v <= 0.0 || v.is_nan()).count();
    if zero > 0 {
        return Err(BoundError::RankDeficient {
            rank: p - zero,
            p,
            ratio: 0.0,
        });
    }
    let scaled = Mat::from_fn(rows, p, |r, c| m[(r, c)] / s[c]);
    let m0s = m0.map(|m0| Mat::from_fn(p, p, |r, c| m0[(r, c)] / (s[r] * s[c])));
    let gram = match &m0s {
        None => scaled.transpose() * &scaled,
        Some(m0s) => scaled.transpose() * &scaled * f * f + m0s,
    };
    let eig =
        gram.self_adjoint_eigenvalues(Side::Lower)
            .map_err(|_| BoundError::RankDeficient {
                rank: 0,
                p,
                ratio: 0.0,
            })?;
    let max = eig.iter().cloned().fold(0.0, f64::max);
    let min = eig.iter().cloned().fold(f64::INFINITY, f64::min);
    let ratio = if max > 0.0 { min / max } else { 0.0 };
    if !rank::eigenvalues_regular(&eig, rank::MAX_CONDITION) {
        let rank = rank::rank_of_eigenvalues(&eig, rank::MAX_CONDITION);
        return Err(BoundError::RankDeficient { rank, p, ratio });
    }
    Ok(Scaled {
        x: Blocks::new(scaled, x.t()),
        ln_scale: 2.0 * s.iter().map(|v| v.ln()).sum::<f64>(),
        s,
        m0: m0s,
    })
}

/// The weighted information matrix `M(w) = Σ_i w_i X_iᵀ X_i` (poses with
/// `w_i = 0` skipped), as one product of the weighted support rows.
#[must_use]
pub fn information(x: &Blocks, w: &[f64]) -> Mat<f64> {
    assert_eq!(w.len(), x.n_poses(), "one weight per pose");
    let t = x.t();
    let support: Vec<usize> = (0..w.len()).filter(|&i| w[i] > 0.0).collect();
    let m = x.mat();
    let sw: Vec<f64> = support.iter().map(|&i| w[i].sqrt()).collect();
    let mut xs = Mat::<f64>::zeros(support.len() * t, x.p());
    // Column by column over contiguous slices (the blocks are column-major).
    for c in 0..x.p() {
        let src = m
            .col(c)
            .try_as_col_major()
            .expect("Blocks are column-major")
            .as_slice();
        let dst = xs
            .col_mut(c)
            .try_as_col_major_mut()
            .expect("owned")
            .as_slice_mut();
        for (k, (&i, &s)) in support.iter().zip(&sw).enumerate() {
            for a in 0..t {
                dst[k * t + a] = s * src[i * t + a];
            }
        }
    }
    crate::linalg::gram::gram_of(xs.as_ref())
}

/// Reusable memory for [`variances_into`]: one chunk of the matrix Y
/// (`VARIANCE_CHUNK` poses' rows × p), never the whole pool's: at 10⁶ PUMA
/// poses that would be a second copy of the 648 MB Jacobian.
#[derive(Debug)]
pub struct VarianceWork {
    y: Mat<f64>,
}

impl Default for VarianceWork {
    fn default() -> Self {
        Self {
            y: Mat::zeros(0, 0),
        }
    }
}

/// Variances of every pose under `M`: writes `d_i = tr(X_i M⁻¹ X_iᵀ)` into
/// `d` and returns `ln det M` with `M⁻¹`, or `None` if `M` is not
/// numerically positive definite.
///
/// One Cholesky `M = L Lᵀ`, then the triangular solve `Y = X L⁻ᵀ` and the
/// row norms of Y, chunk by chunk of `VARIANCE_CHUNK` poses.
pub fn variances_into(
    x: &Blocks,
    m: MatRef<'_, f64>,
    work: &mut VarianceWork,
    d: &mut [f64],
) -> Option<(f64, Mat<f64>)> {
    use faer::linalg::solvers::DenseSolveCore;
    assert_eq!(d.len(), x.n_poses(), "one variance per pose");
    let llt = m.llt(Side::Lower).ok()?;
    let l = llt.L();
    let ln_det = ln_det_of_factor(l)?;
    let xm = x.mat();
    let t = x.t();
    let p = xm.ncols();
    let chunk_rows = VARIANCE_CHUNK * t;
    let rows = chunk_rows.min(xm.nrows());
    if work.y.nrows() != rows || work.y.ncols() != p {
        work.y = Mat::zeros(rows, p);
    }
    for (k, dc) in d.chunks_mut(VARIANCE_CHUNK).enumerate() {
        let r0 = k * chunk_rows;
        let nr = dc.len() * t;
        let mut y = work.y.as_mut().subrows_mut(0, nr);
        y.copy_from(xm.subrows(r0, nr));
        // L Yᵀ = Xᵀ, i.e. Y = X L⁻ᵀ.
        solve_lower_triangular_in_place(l, y.rb_mut().transpose_mut(), Par::Seq);
        clear_upper_simd_state();
        dc.iter_mut().for_each(|v| *v = 0.0);
        for c in 0..p {
            let col = y.rb().col(c);
            for (i, di) in dc.iter_mut().enumerate() {
                let mut s = 0.0;
                for r in i * t..i * t + t {
                    s += col[r] * col[r];
                }
                *di += s;
            }
        }
    }
    if d.iter().any(|v| !v.is_finite()) {
        return None;
    }
    Some((ln_det, llt.inverse()))
}

/// Poses per chunk of [`variances_into`]: 4,096 (a 2.6 MB chunk of Y for
/// the PUMA), large enough that the triangular solve runs at GEMM speed.
const VARIANCE_CHUNK: usize = 4096;

/// `S_N`: the sum of the `n` largest entries of `d`. `scratch` is reused.
#[must_use]
pub fn top_sum(d: &[f64], n: usize, scratch: &mut Vec<f64>) -> f64 {
    assert!(n >= 1 && n <= d.len());
    scratch.clear();
    scratch.extend_from_slice(d);
    let k = n - 1;
    scratch.select_nth_unstable_by(k, |a, b| b.total_cmp(a));
    scratch[..n].iter().sum()
}

/// The `n`-th largest entry of `d` (the threshold `c` of the optimality
/// conditions when the top `n` poses carry the weight).
#[must_use]
pub fn nth_largest(d: &[f64], n: usize, scratch: &mut Vec<f64>) -> f64 {
    scratch.clear();
    scratch.extend_from_slice(d);
    let (_, v, _) = scratch.select_nth_unstable_by(n - 1, |a, b| b.total_cmp(a));
    *v
}

/// The certificate (eq. C): for any positive definite `M` with variances
/// `d_i`, and every feasible `w*` (`0 ≤ w* ≤ 1`, `Σ w* = N`),
///
/// `ln det M(w*) ≤ ln det M + p·ln(S_N / p)`,   (C)
///
/// where `S_N` is the sum of the `N` largest `d_i`.
///
/// Proof: with λ_k the eigenvalues of `M⁻¹ M(w*)`, the AM–GM inequality gives
/// `ln det M(w*) − ln det M = Σ ln λ_k ≤ p·ln(Σ λ_k / p)`, and
/// `Σ λ_k = tr(M⁻¹ M(w*)) = Σ_i w*_i d_i ≤ S_N`. `M` need not be feasible
/// nor optimal; the bound is tight (`S_N = p`) exactly at the optimum.
///
/// **With a prior** (`M(w) = M0 + Σ w_i X_iᵀX_i`, eq. C0) the same steps
/// give `Σ λ_k = tr(M⁻¹M0) + Σ_i w*_i d_i ≤ c0 + S_N`, so
///
/// `ln det M(w*) ≤ ln det M + p·ln((c0 + S_N) / p)`,  `c0 = tr(M⁻¹M0)`,   (C0)
///
/// and `s_n` below is `c0 + S_N` ([`certificate_with_prior`]). It is tight at
/// the optimum too: there `w*` maximises the linearisation `Σ w_i d_i` over
/// the feasible set (the KKT conditions), so `S_N = Σ w*_i d_i = p − c0`.
/// Since `p·ln(x/p) ≤ x − p`, (C0) is never weaker than the Lagrangian
/// (linearisation) bound `ln det M + c0 + S_N − p`, which is the dual
/// function `ln det M + Σ_i (d_i − λ)₊ + Nλ − Σ_i w_i d_i` at its best `λ`
/// (the `N`-th largest `d_i`) for a feasible `M = M(w)`.
#[must_use]
pub fn certificate(ln_det: f64, s_n: f64, p: usize) -> f64 {
    ln_det + p as f64 * (s_n / p as f64).ln()
}

/// Eq. (C0): the certificate with a prior, from `ln det M`, `c0 =
/// tr(M⁻¹M0)` and `S_N`; equals [`certificate`] when `c0 = 0`.
#[must_use]
pub fn certificate_with_prior(ln_det: f64, c0: f64, s_n: f64, p: usize) -> f64 {
    certificate(ln_det, c0 + s_n, p)
}

/// Moves `w` onto the feasible set `{0 ≤ w ≤ 1, Σ w = N}` keeping its support
/// where possible: entries are clamped to `[0, 1]` (NaN to 0), an excess is
/// removed by scaling down, a deficit is spread over the room `1 − w_i` of
/// the support first, and of the other poses only if the support is full.
pub fn make_feasible(w: &mut [f64], n: usize) {
    assert!(n <= w.len());
    for v in w.iter_mut() {
        *v = if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) };
    }
    let nf = n as f64;
    for _ in 0..3 {
        let s: f64 = w.iter().sum();
        if s > nf {
            let f = nf / s;
            w.iter_mut().for_each(|v| *v = (*v * f).min(1.0));
        } else if s < nf {
            let deficit = nf - s;
            let room: f64 = w.iter().filter(|&&v| v > 0.0).map(|v| 1.0 - v).sum();
            if room >= deficit {
                let f = deficit / room;
                w.iter_mut()
                    .filter(|v| **v > 0.0)
                    .for_each(|v| *v = (*v + f * (1.0 - *v)).min(1.0));
            } else {
                let rest = deficit - room;
                w.iter_mut().filter(|v| **v > 0.0).for_each(|v| *v = 1.0);
                let zeros = w.iter().filter(|&&v| v == 0.0).count();
                let f = rest / zeros as f64;
                w.iter_mut()
                    .filter(|v| **v == 0.0)
                    .for_each(|v| *v = f.min(1.0));
            }
        } else {
            break;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn random_blocks(n: usize, t: usize, p: usize, seed: u64) -> Blocks {
        use rand::{RngExt, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let rows: Vec<f64> = (0..n * t * p).map(|_| rng.random::<f64>() - 0.5).collect();
        Blocks::from_row_major(&rows, t, p)
    }

    /// Against `tr(X_i M⁻¹ X_iᵀ)` computed directly, on a pool within one
    /// chunk and on one of three chunks (the last one partial), with the
    /// workspace reused from the first call.
    #[test]
    fn variances_match_direct_formula() {
        let mut work = VarianceWork::default();
        for n in [40, 2 * VARIANCE_CHUNK + 41] {
            let x = random_blocks(n, 3, 7, 1);
            let w: Vec<f64> = (0..n).map(|i| 0.1 + 0.02 * (i % 40) as f64).collect();
            let m = information(&x, &w);
            let mut d = vec![0.0; n];
            let (ld, minv) =
                variances_into(&x, m.as_ref(), &mut work, &mut d).expect("positive definite");
            let last = VARIANCE_CHUNK - 1;
            for i in [0, 17, 39, last, last + 1, 2 * last + 2, n - 1] {
                if i >= n {
                    continue;
                }
                let b = x.block(i);
                let direct = (b * &minv * b.transpose()).diagonal().column_vector().sum();
                assert!(
                    (direct - d[i]).abs() < 1e-10 * direct.abs().max(1.0),
                    "pose {i} of {n}"
                );
            }
            // Σ w_i d_i = tr(M⁻¹ M) = p, over every pose of every chunk.
            let s: f64 = w.iter().zip(&d).map(|(a, b)| a * b).sum();
            assert!(
                (s - 7.0).abs() < 1e-10 * (n as f64 / 40.0),
                "Σ w d = {s} on {n} poses"
            );
            assert!(
                (ld - crate::linalg::chol::ln_det_spd(m.as_ref()).unwrap()).abs()
                    < 1e-12 * ld.abs().max(1.0)
            );
        }
    }

    #[test]
    fn make_feasible_keeps_support() {
        let mut w = vec![0.5, 0.0, 0.9, 1.2, -0.1, 0.3];
        make_feasible(&mut w, 3);
        assert!((w.iter().sum::<f64>() - 3.0).abs() < 1e-12);
        assert!(w.iter().all(|&v| (0.0..=1.0).contains(&v)));
        assert_eq!(w[1], 0.0);
        assert_eq!(w[4], 0.0);
        let mut w = vec![0.9, 0.9, 0.0, 0.0];
        make_feasible(&mut w, 3);
        assert!((w.iter().sum::<f64>() - 3.0).abs() < 1e-12);
        assert!(w.iter().all(|&v| (0.0..=1.0).contains(&v)));
    }
}

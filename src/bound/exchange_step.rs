//! One round of pairwise exchange steps on a candidate set (eq. X1, X2):
//! the steepest pair, its `2t × 2t` system, the exact line search, the
//! weights moved, and `M⁻¹` and the candidates' variances downdated by
//! the Woodbury identity.

use super::pair::PairFactors;
use crate::blocks::Blocks;
use crate::linalg::simd::clear_upper_simd_state;
use faer::linalg::matmul::matmul;
use faer::{Accum, Mat, Par};
use nalgebra::{DMatrix, SymmetricEigen};

/// Reused memory of the pairwise steps.
pub(super) struct PairWork {
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
    pub(super) fn new(t: usize, p: usize) -> Self {
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
pub(super) fn exchange_round(
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
    let mut steps = 0;
    while steps < max_steps {
        let Some((bi, bj)) = steepest_pair(w, cand, &dk, step_tol) else {
            break;
        };
        let (i, j) = (cand[bi], cand[bj]);
        pair_gram(pw, &xk, &minv, (bi, bj));
        let Some(delta) = pair_step(pw, t, (1.0 - w[i]).min(w[j])) else {
            break;
        };
        move_weight(w, i, j, delta);
        downdate(pw, &xk, &mut pk, &mut dk, &mut minv);
        steps += 1;
    }
    steps
}

/// The candidate positions of the pair to exchange: `i` the largest `d`
/// among `w < 1`, `j` the smallest among `w > 0`; `None` when there is no
/// such pair or their variances differ by at most `step_tol`.
fn steepest_pair(w: &[f64], cand: &[usize], dk: &[f64], step_tol: f64) -> Option<(usize, usize)> {
    const FULL: f64 = 1.0 - 1e-12;
    let mut bi = usize::MAX;
    let mut bj = usize::MAX;
    for k in 0..cand.len() {
        let wk = w[cand[k]];
        if wk < FULL && (bi == usize::MAX || dk[k] > dk[bi]) {
            bi = k;
        }
        if wk > 0.0 && (bj == usize::MAX || dk[k] < dk[bj]) {
            bj = k;
        }
    }
    if bi == usize::MAX || bj == usize::MAX || bi == bj || dk[bi] - dk[bj] <= step_tol {
        return None;
    }
    Some((bi, bj))
}

/// For candidates `bi`, `bj`: `Uᵀ = [X_iᵀ X_jᵀ]` (`p × 2t`), `W = M⁻¹Uᵀ`,
/// `G = U W`, and `G` symmetrised into `pw.gs`.
fn pair_gram(pw: &mut PairWork, xk: &Mat<f64>, minv: &Mat<f64>, (bi, bj): (usize, usize)) {
    let (t, p) = (pw.ut.ncols() / 2, pw.ut.nrows());
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
}

/// `delta` of weight from pose `j` to pose `i`, with exact bounds when a
/// pose fills up or empties.
fn move_weight(w: &mut [f64], i: usize, j: usize, delta: f64) {
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
}

/// After a step with `R = E diag(s) Eᵀ` (`E` in `pw.v`, `s` in `pw.s`):
/// `d_k −= tr(P_k R P_kᵀ)`, `P = X_K W`, and `M⁻¹ −= W R Wᵀ` (X2). With the
/// eigen-form, `tr(P_k R P_kᵀ) = Σ_l s_l ‖X_k (W E)_l‖²`: one product
/// `X_K (W E)` instead of two.
fn downdate(
    pw: &mut PairWork,
    xk: &Mat<f64>,
    pk: &mut Mat<f64>,
    dk: &mut [f64],
    minv: &mut Mat<f64>,
) {
    let (m2, p) = (pw.ut.ncols(), pw.ut.nrows());
    let t = m2 / 2;
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
    pw.sq.resize(xk.nrows(), 0.0);
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

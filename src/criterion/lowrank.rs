//! Signed low-rank updates of an inverse information matrix: the block form
//! of the paper's eq. (4)–(22), and the row-by-row cascade as a reference.
//!
//! Adding the rows `Z₊` (`a×p`) and removing the rows `Z₋` (`b×p`) turns
//! `M` into `M' = M + Z₊ᵀZ₊ − Z₋ᵀZ₋`. With `S = Z M⁻¹ Zᵀ` for
//! `Z = [Z₊; Z₋]`, the matrix determinant lemma gives
//!
//! `det M' = det M · det [[I + S₊₊, S₊₋], [−S₋₊, I − S₋₋]]`
//!
//! (eq. (5)/(10) for one row, (17)–(22) for a block), and Woodbury gives
//! `M'⁻¹ = M⁻¹ − F₊F₊ᵀ + F₋F₋ᵀ` (the block form of eq. (6)/(11)) with the
//! factors `F₊`, `F₋` computed below.

use faer::linalg::matmul::matmul;
use faer::{Accum, Mat, MatMut, MatRef, Par};

use crate::linalg::simd::clear_upper_simd_state;
use crate::linalg::small::{chol_in_place, chol_pivoted_in_place, min_pivot};

/// A numerically singular change: a pivot of the removal Schur complement
/// was `≤ pivot_floor`. A numerical outcome, not an error.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Singular {
    /// The offending pivot (the first `≤ pivot_floor`; may be negative).
    pub pivot: f64,
    /// The floor it was compared with.
    pub pivot_floor: f64,
}

/// A computed signed low-rank update of `M⁻¹` and `ln det M`:
/// `M'⁻¹ = M⁻¹ − F₊F₊ᵀ + F₋F₋ᵀ`, `ln det M' = ln det M + ln_det_ratio`.
#[derive(Clone, Debug)]
pub struct LowRank {
    ln_det_ratio: f64,
    min_pivot: f64,
    /// `[F₊ F₋]`, `p × k` column-major with stride `p`.
    f: Vec<f64>,
    p: usize,
    n_plus: usize,
}

impl LowRank {
    /// `ln det M' − ln det M`.
    #[must_use]
    pub fn ln_det_ratio(&self) -> f64 {
        self.ln_det_ratio
    }

    /// Smallest pivot of the removal Schur complement `B` (`+∞` when no row is
    /// removed). Lies in `(0, 1]` for a pure removal; it bounds
    /// `λ_min(B)` from above, where `M' ⪰ λ_min(B)·M`.
    #[must_use]
    pub fn min_pivot(&self) -> f64 {
        self.min_pivot
    }

    /// The factors `[F₊ F₋]` (`p × (a+b)`).
    #[must_use]
    pub fn factors(&self) -> MatRef<'_, f64> {
        MatRef::from_column_major_slice(&self.f, self.p, self.rank())
    }

    /// Number of columns of `F₊` (rows added).
    #[must_use]
    pub fn n_plus(&self) -> usize {
        self.n_plus
    }

    /// Rank of the update (`a + b`).
    #[must_use]
    pub fn rank(&self) -> usize {
        self.f.len() / self.p.max(1)
    }

    /// Applies the update to `M⁻¹` in place: `M⁻¹ ← M⁻¹ − F₊F₊ᵀ + F₋F₋ᵀ`,
    /// each entry computed once and written to both triangles (exactly
    /// symmetric).
    pub fn apply_to_inverse(&self, mut m_inv: MatMut<'_, f64>) {
        let p = self.p;
        assert!(m_inv.nrows() == p && m_inv.ncols() == p, "shape mismatch");
        let mut buf = vec![0.0; p * p];
        for j in 0..p {
            for i in 0..p {
                buf[j * p + i] = m_inv[(i, j)];
            }
        }
        self.apply_to_col_major(&mut buf);
        for j in 0..p {
            for i in 0..p {
                m_inv[(i, j)] = buf[j * p + i];
            }
        }
    }

    /// [`apply_to_inverse`](Self::apply_to_inverse) on a column-major `p×p`
    /// slice (stride `p`): the state's fast path.
    pub(crate) fn apply_to_col_major(&self, m_inv: &mut [f64]) {
        let p = self.p;
        assert_eq!(m_inv.len(), p * p, "shape mismatch");
        // Lower triangle, one rank-1 term at a time (contiguous inner loop).
        for (c, fc) in self.f.chunks_exact(p).enumerate() {
            let sign = if c < self.n_plus { -1.0 } else { 1.0 };
            for j in 0..p {
                let s = sign * fc[j];
                let col = &mut m_inv[j * p..(j + 1) * p];
                for i in j..p {
                    col[i] += s * fc[i];
                }
            }
        }
        for j in 0..p {
            for i in j + 1..p {
                m_inv[i * p + j] = m_inv[j * p + i];
            }
        }
    }
}

/// The block update (one step, not add-then-remove): adds the rows `plus`
/// and removes the rows `minus` from the design whose inverse information
/// matrix is `m_inv`.
///
/// Implements the matrix determinant lemma on the `(a+b)×(a+b)` system
/// `[[I + S₊₊, S₊₋], [−S₋₊, I − S₋₋]]` (eq. (17)/(20) for `b = 0`,
/// eq. (21)/(22) for `a = 0`, and the exchange for both) and the Woodbury
/// identity, the block form of eq. (6)/(11).
///
/// Returns [`Singular`] when a pivot of the (diagonally pivoted) Cholesky
/// factor of the removal Schur complement
/// `B = I − S₋₋ + S₋₊(I + S₊₊)⁻¹S₊₋` is `≤ pivot_floor` (`B` is positive
/// definite iff `M'` is, given `M` is). Use a floor `≥ 0`.
pub fn woodbury(
    m_inv: MatRef<'_, f64>,
    plus: MatRef<'_, f64>,
    minus: MatRef<'_, f64>,
    pivot_floor: f64,
) -> Result<LowRank, Singular> {
    let p = m_inv.nrows();
    assert!(m_inv.ncols() == p && plus.ncols() == p && minus.ncols() == p);
    let (a, b) = (plus.nrows(), minus.nrows());
    let (u, s) = products(m_inv, plus, minus);
    let (la, ln_a) = addition_factor(&s, a)?;
    let mut f = vec![0.0; p * (a + b)];
    added_columns(&mut f, &u, &la, a, p);
    if b == 0 {
        return Ok(LowRank {
            ln_det_ratio: ln_a,
            min_pivot: f64::INFINITY,
            f,
            p,
            n_plus: a,
        });
    }
    let (y, mut lb) = removal_schur(&s, &la, a, b);
    let mut perm = vec![0usize; b];
    let ln_b = chol_pivoted_in_place(&mut lb, b, pivot_floor, &mut perm)
        .map_err(|pivot| Singular { pivot, pivot_floor })?;
    removed_columns(&mut f, &u, &y, &lb, &perm, (a, b, p));
    Ok(LowRank {
        ln_det_ratio: ln_a + ln_b,
        min_pivot: min_pivot(&lb, b),
        f,
        p,
        n_plus: a,
    })
}

/// `S = Z M⁻¹ Zᵀ` (`k×k`, column-major, `k = a + b`) read as the symmetric
/// matrix it is in exact arithmetic: only `S[i][j]` with `i ≥ j` is used.
struct Gram {
    s: Vec<f64>,
    k: usize,
}

impl Gram {
    fn sym(&self, i: usize, j: usize) -> f64 {
        // Reading the upper triangle instead (`i < j` here) is equivalent:
        // `S` is formed whole and its triangles differ by rounding only;
        // either, read consistently, is exactly symmetric.
        if i >= j {
            self.s[j * self.k + i]
        } else {
            self.s[i * self.k + j]
        }
    }
}

/// `Z = [Z₊; Z₋]`, `U = M⁻¹ Zᵀ` (`p×k`, column-major) and `S = Z U`.
fn products(
    m_inv: MatRef<'_, f64>,
    plus: MatRef<'_, f64>,
    minus: MatRef<'_, f64>,
) -> (Vec<f64>, Gram) {
    let p = m_inv.nrows();
    let (a, b) = (plus.nrows(), minus.nrows());
    let k = a + b;
    let par = Par::Seq;
    let mut z = Mat::<f64>::zeros(k, p);
    z.as_mut().subrows_mut(0, a).copy_from(plus);
    z.as_mut().subrows_mut(a, b).copy_from(minus);
    let mut u = vec![0.0; p * k];
    matmul(
        MatMut::from_column_major_slice_mut(&mut u, p, k),
        Accum::Replace,
        m_inv,
        z.transpose(),
        1.0,
        par,
    );
    let mut s = vec![0.0; k * k];
    matmul(
        MatMut::from_column_major_slice_mut(&mut s, k, k),
        Accum::Replace,
        z.as_ref(),
        MatRef::from_column_major_slice(&u, p, k),
        1.0,
        par,
    );
    clear_upper_simd_state();
    (u, Gram { s, k })
}

/// `A = I + S₊₊ = L_A L_Aᵀ` (row-major `a×a`) and `ln det A`. `A ⪰ I`, so it
/// cannot fail for a positive definite `M⁻¹`; a failure means `M⁻¹` itself
/// is broken.
fn addition_factor(s: &Gram, a: usize) -> Result<(Vec<f64>, f64), Singular> {
    let mut la = vec![0.0; a * a];
    for r in 0..a {
        for c in 0..=r {
            la[r * a + c] = s.sym(r, c) + if r == c { 1.0 } else { 0.0 };
        }
    }
    let ln_a = chol_in_place(&mut la, a, 0.0).map_err(|pivot| Singular {
        pivot,
        pivot_floor: 0.0,
    })?;
    Ok((la, ln_a))
}

/// `F₊ = U₊ L_A⁻ᵀ` into the first `a` columns of `f` (`p×k` column-major):
/// each row solves `L_A y = u` (forward substitution), column by column
/// over the whole of `F₊`.
fn added_columns(f: &mut [f64], u: &[f64], la: &[f64], a: usize, p: usize) {
    for r in 0..a {
        let (done, rest) = f.split_at_mut(r * p);
        let fr = &mut rest[..p];
        fr.copy_from_slice(&u[r * p..(r + 1) * p]);
        for j in 0..r {
            let l = la[r * a + j];
            for (x, y) in fr.iter_mut().zip(&done[j * p..(j + 1) * p]) {
                *x -= l * y;
            }
        }
        let d = la[r * a + r];
        for x in fr.iter_mut() {
            *x /= d;
        }
    }
}

/// `Y = L_A⁻¹ S₊₋` (`a×b`, row-major) and `B = I − S₋₋ + Yᵀ Y` (full,
/// row-major `b×b`): the Schur complement of the 2-block system. Its LDLᵀ
/// pivots (unpivoted) are the factors `(1 − x_r' M_{·}⁻¹ x_r)` of the
/// cascade (22); the caller factors it with diagonal pivoting,
/// `P B Pᵀ = L_B L_Bᵀ`, so that a singular `B` shows as a last pivot of
/// rounding size (see `chol_pivoted_in_place`).
fn removal_schur(s: &Gram, la: &[f64], a: usize, b: usize) -> (Vec<f64>, Vec<f64>) {
    let mut y = vec![0.0; a * b];
    for c in 0..b {
        for r in 0..a {
            let mut v = s.sym(r, a + c);
            for j in 0..r {
                v -= la[r * a + j] * y[j * b + c];
            }
            y[r * b + c] = v / la[r * a + r];
        }
    }
    let mut lb = vec![0.0; b * b];
    for r in 0..b {
        for c in 0..=r {
            let mut v = if r == c { 1.0 } else { 0.0 } - s.sym(a + r, a + c);
            for j in 0..a {
                v += y[j * b + r] * y[j * b + c];
            }
            lb[r * b + c] = v;
            lb[c * b + r] = v;
        }
    }
    (y, lb)
}

/// `F₋ = (U₋ − F₊ Y) L_B⁻ᵀ` into the last `b` columns of `f`. Derivation:
/// after adding `Z₊` the inverse is `M₁⁻¹ = M⁻¹ − F₊F₊ᵀ`, so
/// `M₁⁻¹Z₋ᵀ = U₋ − F₊ (L_A⁻¹S₊₋) = U₋ − F₊Y` and `Z₋M₁⁻¹Z₋ᵀ = S₋₋ − YᵀY`;
/// removing `Z₋` from `M₁` by eq. (11) in block form adds
/// `(M₁⁻¹Z₋ᵀ) B⁻¹ (M₁⁻¹Z₋ᵀ)ᵀ`. With `P B Pᵀ = L_B L_Bᵀ` (`perm[r]` the
/// original index of position `r`), `B⁻¹ = Pᵀ L_B⁻ᵀ L_B⁻¹ P`, so
/// `F₋ = (U₋ − F₊Y)Pᵀ L_B⁻ᵀ`: permute the columns, then substitute.
fn removed_columns(
    f: &mut [f64],
    u: &[f64],
    y: &[f64],
    lb: &[f64],
    perm: &[usize],
    (a, b, p): (usize, usize, usize),
) {
    for r in 0..b {
        let pr = perm[r];
        let (done, rest) = f.split_at_mut((a + r) * p);
        let fr = &mut rest[..p];
        fr.copy_from_slice(&u[(a + pr) * p..(a + pr + 1) * p]);
        for j in 0..a {
            let yj = y[j * b + pr];
            for (x, w) in fr.iter_mut().zip(&done[j * p..(j + 1) * p]) {
                *x -= yj * w;
            }
        }
        for j in 0..r {
            let l = lb[r * b + j];
            for (x, w) in fr.iter_mut().zip(&done[(a + j) * p..(a + j + 1) * p]) {
                *x -= l * w;
            }
        }
        let d = lb[r * b + r];
        for x in fr.iter_mut() {
            *x /= d;
        }
    }
}

/// Result of the row-by-row cascade.
#[derive(Clone, Debug)]
pub struct Cascade {
    /// `ln det M' − ln det M`.
    pub ln_det_ratio: f64,
    /// `M'⁻¹`.
    pub m_inv: Mat<f64>,
    /// Smallest removal factor `1 − x' M⁻¹ x` met (`+∞` if none).
    pub min_pivot: f64,
}

/// The paper's cascade, a reference implementation of [`woodbury`]: adds the
/// rows of `plus` one at a time, multiplying the determinant by
/// `(1 + x' M⁻¹ x)` (eq. (20)) and updating `M⁻¹` by Sherman–Morrison
/// (eq. (6)), then removes the rows of `minus` one at a time with
/// `(1 − x' M⁻¹ x)` (eq. (22)) and eq. (11). `O(p²)` per row.
///
/// Returns [`Singular`] when a removal factor is `≤ pivot_floor`. Rows are
/// removed in the given order, without pivoting, so a singular removal can
/// show a larger rounding residue here than in [`woodbury`].
pub fn cascade(
    m_inv: MatRef<'_, f64>,
    plus: MatRef<'_, f64>,
    minus: MatRef<'_, f64>,
    pivot_floor: f64,
) -> Result<Cascade, Singular> {
    let p = m_inv.nrows();
    assert!(m_inv.ncols() == p && plus.ncols() == p && minus.ncols() == p);
    let mut inv = m_inv.to_owned();
    let mut ln = 0.0;
    let mut min_piv = f64::INFINITY;
    let mut u = vec![0.0; p];
    let rows = (0..plus.nrows())
        .map(|r| (plus.row(r), 1.0))
        .chain((0..minus.nrows()).map(|r| (minus.row(r), -1.0)));
    for (x, sign) in rows {
        // u = M⁻¹ x, s = x' M⁻¹ x.
        for (i, ui) in u.iter_mut().enumerate() {
            *ui = (0..p).map(|j| inv[(i, j)] * x[j]).sum();
        }
        let s: f64 = (0..p).map(|j| x[j] * u[j]).sum();
        let d = 1.0 + sign * s;
        // `sign <= 0.0` is equivalent: `sign` is ±1, never 0.
        if sign < 0.0 {
            if !(d > pivot_floor) {
                return Err(Singular {
                    pivot: d,
                    pivot_floor,
                });
            }
            min_piv = min_piv.min(d);
        }
        ln += d.ln();
        // eq. (6): M⁻¹ − u uᵀ / (1 + s); eq. (11): M⁻¹ + u uᵀ / (1 − s).
        for j in 0..p {
            for i in j..p {
                let v = inv[(i, j)] - sign * u[i] * u[j] / d;
                inv[(i, j)] = v;
                inv[(j, i)] = v;
            }
        }
    }
    Ok(Cascade {
        ln_det_ratio: ln,
        m_inv: inv,
        min_pivot: min_piv,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::criterion::test_util::lcg;
    use crate::linalg::chol::cholesky_inverse;
    use crate::linalg::gram::view;

    fn random(rows: usize, cols: usize, seed: &mut u64) -> Mat<f64> {
        Mat::from_fn(rows, cols, |_, _| lcg(seed))
    }

    #[test]
    fn block_equals_cascade_and_direct() {
        let mut seed = 7;
        for p in [1, 2, 5, 9, 27] {
            for t in 1..=6 {
                let x0 = random(3 * p + 6, p, &mut seed);
                let m0 = x0.transpose() * &x0;
                let (m0_inv, ld0) = cholesky_inverse(m0.as_ref()).unwrap();
                let m0_inv = view(&m0_inv, p).to_owned();
                let q = random(t, p, &mut seed);
                let r = x0.as_ref().subrows(0, t).to_owned();
                for (plus, minus) in [
                    (q.as_ref(), r.as_ref().subrows(0, 0)),
                    (q.as_ref().subrows(0, 0), r.as_ref()),
                    (q.as_ref(), r.as_ref()),
                ] {
                    let m1 = &m0 + plus.transpose() * plus - minus.transpose() * minus;
                    let (m1_inv, ld1) = cholesky_inverse(m1.as_ref()).unwrap();
                    let m1_inv = view(&m1_inv, p).to_owned();
                    let w = woodbury(m0_inv.as_ref(), plus, minus, 0.0).unwrap();
                    let c = cascade(m0_inv.as_ref(), plus, minus, 0.0).unwrap();
                    let mut inv = m0_inv.clone();
                    w.apply_to_inverse(inv.as_mut());
                    let scale = m1_inv.norm_max();
                    assert!((ld0 + w.ln_det_ratio() - ld1).abs() < 1e-9, "p={p} t={t}");
                    assert!((w.ln_det_ratio() - c.ln_det_ratio).abs() < 1e-10);
                    assert!((&inv - &m1_inv).norm_max() < 1e-8 * scale);
                    assert!((&c.m_inv - &m1_inv).norm_max() < 1e-8 * scale);
                }
            }
        }
    }

    #[test]
    fn removing_an_essential_block_is_singular() {
        // p = 3 and a design of exactly 3 rows: removing any row leaves rank 2.
        let mut seed = 3;
        let x = random(3, 3, &mut seed);
        let m = x.transpose() * &x;
        let (m_inv, _) = cholesky_inverse(m.as_ref()).unwrap();
        let m_inv = view(&m_inv, 3).to_owned();
        let r = woodbury(
            m_inv.as_ref(),
            x.as_ref().subrows(0, 0),
            x.as_ref().subrows(1, 1),
            1e-8,
        );
        assert!(r.is_err());
        let c = cascade(
            m_inv.as_ref(),
            x.as_ref().subrows(0, 0),
            x.as_ref().subrows(1, 1),
            1e-8,
        );
        assert!(c.is_err());
    }
}

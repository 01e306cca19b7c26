//! Cholesky factorizations of `p×p` symmetric positive definite matrices
//! (faer's `llt`, always sequential so results never depend on the thread
//! count): `ln det`, never the raw determinant, and the inverse.

use super::simd::clear_upper_simd_state;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt;
use faer::linalg::solvers::DenseSolveCore;
use faer::{Mat, MatMut, MatRef, Par, Side};

/// `ln det M` of a symmetric positive definite matrix from its Cholesky
/// factor `M = L Lᵀ` (`Σ 2 ln L_jj`), or `None` if `M` is not numerically
/// positive definite (a pivot not positive, or a non-finite result).
#[must_use]
pub fn ln_det_spd(m: MatRef<'_, f64>) -> Option<f64> {
    let llt = m.llt(Side::Lower).ok()?;
    let v = ln_det_of_factor(llt.L());
    clear_upper_simd_state();
    v
}

/// `ln det M` of a symmetric positive definite matrix through its
/// equilibrated (correlation) form, `ln det M = Σ ln M_jj + ln det(D^{-1/2}
/// M D^{-1/2})` with `D = diag(M)`, so that columns of very different
/// scales (the PUMA's 20 m tracker distance beside millimetre offsets) do
/// not decide whether the factorization succeeds. `None` if a diagonal
/// entry is not positive and finite or `M` is not numerically positive
/// definite.
#[must_use]
pub fn ln_det_spd_equilibrated(m: MatRef<'_, f64>) -> Option<f64> {
    // An early out: a diagonal that is not positive and finite also fails
    // the factorization below (a non-positive or NaN pivot, or a non-finite
    // ln det), so weakening this test (`&&` to `||`, a cargo-mutants
    // mutant) changes no result.
    if (0..m.nrows()).any(|j| !(m[(j, j)] > 0.0 && m[(j, j)].is_finite())) {
        return None;
    }
    // The equilibration scales √M_jj (all positive and finite here): the
    // same as `rank::equilibration_scales`, computed here so that this
    // file and `rank.rs` do not import each other.
    let p = m.nrows();
    let s: Vec<f64> = (0..p).map(|j| m[(j, j)].sqrt()).collect();
    let scaled = Mat::from_fn(p, p, |i, j| m[(i, j)] / (s[i] * s[j]));
    Some(ln_det_spd(scaled.as_ref())? + 2.0 * s.iter().map(|v| v.ln()).sum::<f64>())
}

/// `Σ 2 ln L_jj` of a Cholesky factor `L` (`ln det L Lᵀ`), or `None` when it
/// is not finite.
#[must_use]
pub fn ln_det_of_factor(l: MatRef<'_, f64>) -> Option<f64> {
    let v: f64 = (0..l.nrows()).map(|j| 2.0 * l[(j, j)].ln()).sum();
    v.is_finite().then_some(v)
}

/// Cholesky factorization of a symmetric matrix with faer's `llt` kernel
/// (sequential): returns `(M⁻¹, ln det M)`, `M⁻¹` column-major with stride
/// `p` and exactly symmetric, or `Err(())` when a pivot is not positive.
pub(crate) fn cholesky_inverse(m: MatRef<'_, f64>) -> Result<(Vec<f64>, f64), ()> {
    let p = m.nrows();
    let par = Par::Seq;
    let mut l = Mat::<f64>::zeros(p, p);
    l.as_mut().copy_from_triangular_lower(m);
    let req = llt::factor::cholesky_in_place_scratch::<f64>(p, par, Default::default())
        .or(llt::inverse::inverse_scratch::<f64>(p, par));
    let mut mem = MemBuffer::new(req);
    let stack = MemStack::new(&mut mem);
    llt::factor::cholesky_in_place(
        l.as_mut(),
        Default::default(),
        par,
        stack,
        Default::default(),
    )
    .map_err(|_| {
        clear_upper_simd_state();
    })?;
    clear_upper_simd_state();
    let mut ln_det = 0.0;
    for i in 0..p {
        let d = l[(i, i)];
        // faer refuses non-positive pivots, so `>` vs `≥` here is an
        // equivalent mutant; the finiteness test catches an infinite one.
        if !(d > 0.0) || !d.is_finite() {
            return Err(());
        }
        ln_det += 2.0 * d.ln();
    }
    let mut inv = vec![0.0; p * p];
    llt::inverse::inverse(
        MatMut::from_column_major_slice_mut(&mut inv, p, p),
        l.as_ref(),
        par,
        stack,
    );
    clear_upper_simd_state();
    // The kernel writes the lower triangle; mirror it (from `j + 1`: the
    // diagonal copied onto itself, as `j * 1` would, changes nothing).
    for j in 0..p {
        for i in j + 1..p {
            inv[i * p + j] = inv[j * p + i];
        }
    }
    Ok((inv, ln_det))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::gram::view;

    #[test]
    fn cholesky_inverse_reconstructs() {
        for p in 1..12 {
            let m = Mat::from_fn(p, p, |i, j| {
                if i == j {
                    p as f64 + 1.0
                } else {
                    1.0 / (1.0 + (i + j) as f64)
                }
            });
            let (inv, _) = cholesky_inverse(m.as_ref()).unwrap();
            let prod = &m * view(&inv, p);
            for i in 0..p {
                for j in 0..p {
                    let e = if i == j { 1.0 } else { 0.0 };
                    assert!((prod[(i, j)] - e).abs() < 1e-13);
                }
            }
        }
    }
    #[test]
    fn cholesky_inverse_refuses_an_infinite_pivot() {
        let m = Mat::from_fn(2, 2, |i, j| match (i, j) {
            (0, 0) => f64::INFINITY,
            (1, 1) => 1.0,
            _ => 0.0,
        });
        assert!(cholesky_inverse(m.as_ref()).is_err());
    }

    #[test]
    fn ln_det_handles_scales() {
        let a = Mat::from_fn(3, 3, |i, j| {
            let s = [1e-8f64, 1.0, 1e6];
            let base = if i == j { 2.0 } else { 0.5 };
            base * (s[i] * s[j]).sqrt()
        });
        // det = (Π s_i) · det([[2, .5, .5], [.5, 2, .5], [.5, .5, 2]]) = 1e-2 · 6.75
        let want = (1e-2f64 * 6.75).ln();
        assert!((ln_det_spd_equilibrated(a.as_ref()).unwrap() - want).abs() < 1e-12);
        assert!(ln_det_spd_equilibrated(Mat::<f64>::zeros(2, 2).as_ref()).is_none());
        let indefinite = Mat::from_fn(2, 2, |i, j| if i == j { 1.0 } else { 2.0 });
        assert!(ln_det_spd_equilibrated(indefinite.as_ref()).is_none());
    }
}

/// `M⁻¹` of a symmetric positive definite `M`, through the Cholesky factor
/// of its unit-diagonal equilibration; `None` when it is not positive
/// definite. Equilibrated first, so that graded columns (metres against
/// radians, pixels per metre) do not decide it.
pub fn spd_inverse(m: MatRef<'_, f64>) -> Option<Mat<f64>> {
    let p = m.nrows();
    let d: Vec<f64> = (0..p).map(|i| m[(i, i)].max(0.0).sqrt()).collect();
    if d.iter().any(|&v| !(v > 0.0 && v.is_finite())) {
        return None;
    }
    let e = faer::Mat::from_fn(p, p, |i, j| m[(i, j)] / (d[i] * d[j]));
    let inv = e.llt(faer::Side::Lower).ok()?.inverse();
    Some(faer::Mat::from_fn(p, p, |i, j| inv[(i, j)] / (d[i] * d[j])))
}

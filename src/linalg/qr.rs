//! Householder QR for identification, sequential (`Par::Seq`) so that a
//! result never depends on the number of threads: least-squares solves and
//! `(XᵀX)⁻¹` from a column-scaled QR.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::qr::no_pivoting::{factor, solve};
use faer::linalg::triangular_solve::solve_upper_triangular_in_place;
use faer::{Conj, Mat, MatMut, MatRef, Par};

/// Householder QR `A = Q R` of a tall `m × n` matrix (`m ≥ n`).
pub(crate) struct SeqQr {
    /// Householder basis: unit lower trapezoidal `m × n`.
    basis: Mat<f64>,
    /// Block Householder coefficients.
    coeff: Mat<f64>,
    /// `R`, upper triangular `n × n`.
    r: Mat<f64>,
    mem: MemBuffer,
}

impl SeqQr {
    /// Factors `a` (consumed as the work array).
    pub(crate) fn new(mut a: Mat<f64>) -> Self {
        let (m, n) = a.shape();
        assert!(m >= n && n > 0, "SeqQr needs a tall matrix");
        let bs = factor::recommended_block_size::<f64>(m, n);
        let mut coeff = Mat::<f64>::zeros(bs, n);
        let req = factor::qr_in_place_scratch::<f64>(m, n, bs, Par::Seq, Default::default()).or(
            solve::solve_lstsq_in_place_scratch::<f64>(m, n, bs, 2, Par::Seq),
        );
        let mut mem = MemBuffer::new(req);
        factor::qr_in_place(
            a.as_mut(),
            coeff.as_mut(),
            Par::Seq,
            MemStack::new(&mut mem),
            Default::default(),
        );
        let r = Mat::from_fn(n, n, |i, j| if i <= j { a[(i, j)] } else { 0.0 });
        for j in 0..n {
            for i in 0..=j {
                a[(i, j)] = if i == j { 1.0 } else { 0.0 };
            }
        }
        Self {
            basis: a,
            coeff,
            r,
            mem,
        }
    }

    /// The triangular factor `R`.
    pub(crate) fn r(&self) -> MatRef<'_, f64> {
        self.r.as_ref()
    }

    /// Least-squares solve in place: on return the first `n` rows of `rhs`
    /// (`m × k`) hold `argmin ‖A x − b‖`.
    pub(crate) fn solve_lstsq_in_place(&mut self, rhs: MatMut<'_, f64>) {
        solve::solve_lstsq_in_place_with_conj(
            self.basis.as_ref(),
            self.coeff.as_ref(),
            self.r.as_ref(),
            Conj::No,
            rhs,
            Par::Seq,
            MemStack::new(&mut self.mem),
        );
    }
}

/// `(XᵀX)⁻¹` through the QR of the column-scaled `X D⁻¹ = Q R`:
/// `(XᵀX)⁻¹ = D⁻¹ R⁻¹ R⁻ᵀ D⁻¹`, never forming `XᵀX`. `None` if `X` has fewer
/// rows than columns, a zero or non-finite column, or a zero pivot.
pub(crate) fn inverse_information(x: MatRef<'_, f64>) -> Option<Mat<f64>> {
    let p = x.ncols();
    if x.nrows() < p || p == 0 {
        return None;
    }
    let d: Vec<f64> = (0..p).map(|c| x.col(c).norm_l2()).collect();
    if d.iter().any(|&v| !(v > 0.0 && v.is_finite())) {
        return None;
    }
    let qr = SeqQr::new(Mat::from_fn(x.nrows(), p, |i, j| x[(i, j)] / d[j]));
    let r = qr.r();
    if (0..p).any(|i| r[(i, i)] == 0.0 || !r[(i, i)].is_finite()) {
        return None;
    }
    let mut rinv = Mat::<f64>::identity(p, p);
    solve_upper_triangular_in_place(r, rinv.as_mut(), Par::Seq);
    // (R⁻¹ R⁻ᵀ)_ij = Σ_k R⁻¹_ik R⁻¹_jk, R⁻¹ upper triangular: k ≥ max(i, j).
    Some(Mat::from_fn(p, p, |i, j| {
        let s: f64 = (i.max(j)..p).map(|k| rinv[(i, k)] * rinv[(j, k)]).sum();
        s / (d[i] * d[j])
    }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::gram::{gram_of as gram, product};

    fn test_matrix(m: usize, n: usize) -> Mat<f64> {
        // Pseudo-random entries in [−0.5, 0.5), columns scaled 1e-2 … 10.
        Mat::from_fn(m, n, |i, j| {
            let h = (i * 2_654_435_761 + j * 40_503 + i * j * 977) % 1000;
            (h as f64 / 1000.0 - 0.5) * 10f64.powi(j as i32 % 4 - 2)
        })
    }

    #[test]
    fn lstsq_matches_normal_equations() {
        let a = test_matrix(12, 5);
        let b = Mat::from_fn(12, 1, |i, _| (i as f64).cos());
        let mut x = b.clone();
        SeqQr::new(a.clone()).solve_lstsq_in_place(x.as_mut());
        // Optimality: Aᵀ (A x − b) = 0.
        let x5 = Mat::from_fn(5, 1, |i, _| x[(i, 0)]);
        let res = product(a.as_ref(), x5.as_ref()) - &b;
        let g = product(a.transpose(), res.as_ref());
        for j in 0..5 {
            let scale = a.col(j).norm_l2() * b.norm_l2();
            assert!(g[(j, 0)].abs() < 1e-13 * scale, "{j}: {}", g[(j, 0)]);
        }
    }

    #[test]
    fn inverse_information_inverts_the_gram_matrix() {
        let a = test_matrix(20, 6);
        let inv = inverse_information(a.as_ref()).unwrap();
        let prod = product(gram(a.as_ref()).as_ref(), inv.as_ref());
        for i in 0..6 {
            for j in 0..6 {
                let want = if i == j { 1.0 } else { 0.0 };
                assert!(
                    (prod[(i, j)] - want).abs() < 1e-9,
                    "({i},{j}) {}",
                    prod[(i, j)]
                );
            }
        }
        assert!(inverse_information(test_matrix(4, 6).as_ref()).is_none());
        let mut z = a.clone();
        z.col_mut(3).fill(0.0);
        assert!(inverse_information(z.as_ref()).is_none());
    }
}

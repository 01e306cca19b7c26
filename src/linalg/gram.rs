//! Gram-matrix kernels on `p×p` column-major slices: gathering a pose's
//! `t×p` block, `M ± XᵀX` updates that keep `M` exactly symmetric, the
//! induced 1-norm, and faer views of the slices.

use faer::{Mat, MatRef, Par};

/// Copies a `t×p` block (any strides) into `out`, column-major with stride
/// `t` (`out[a·t + r] = X[r, a]`), reusing `out`'s allocation.
pub(crate) fn gather_block(x: MatRef<'_, f64>, out: &mut Vec<f64>) {
    out.clear();
    for a in 0..x.ncols() {
        out.extend(x.col(a).iter().copied());
    }
}

/// `M += sign · XᵀX` for a `t×p` block gathered by [`gather_block`], on a
/// `p×p` column-major `M` (stride `p`). Each entry is computed once and
/// written to both triangles, so `M` stays exactly symmetric.
pub(crate) fn add_gram(m: &mut [f64], p: usize, xb: &[f64], t: usize, sign: f64) {
    debug_assert!(m.len() == p * p && xb.len() == t * p);
    for b in 0..p {
        let cb = &xb[b * t..b * t + t];
        for a in b..p {
            let ca = &xb[a * t..a * t + t];
            let s: f64 = ca.iter().zip(cb).map(|(x, y)| x * y).sum();
            let v = m[b * p + a] + sign * s;
            m[b * p + a] = v;
            m[a * p + b] = v;
        }
    }
}

/// Induced 1-norm (largest absolute column sum) of a `p×p` column-major
/// matrix.
#[cfg(test)]
pub(crate) fn norm1(m: &[f64], p: usize) -> f64 {
    m.chunks(p.max(1))
        .map(|c| c.iter().map(|x| x.abs()).sum::<f64>())
        .fold(0.0, f64::max)
}

/// A `p×p` column-major slice viewed as a faer matrix.
pub(crate) fn view(m: &[f64], p: usize) -> MatRef<'_, f64> {
    MatRef::from_column_major_slice(m, p, p)
}

/// `AᵀA` (sequential).
pub(crate) fn gram_of(a: MatRef<'_, f64>) -> Mat<f64> {
    let mut out = Mat::<f64>::zeros(a.ncols(), a.ncols());
    faer::linalg::matmul::matmul(
        out.as_mut(),
        faer::Accum::Replace,
        a.transpose(),
        a,
        1.0,
        Par::Seq,
    );
    out
}

/// `A B` (sequential).
pub(crate) fn product(a: MatRef<'_, f64>, b: MatRef<'_, f64>) -> Mat<f64> {
    let mut out = Mat::<f64>::zeros(a.nrows(), b.ncols());
    faer::linalg::matmul::matmul(out.as_mut(), faer::Accum::Replace, a, b, 1.0, Par::Seq);
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::Mat;

    #[test]
    fn gram_is_symmetric_and_correct() {
        let x = Mat::from_fn(3, 4, |i, j| (i * 4 + j) as f64 - 5.0);
        let mut xb = Vec::new();
        gather_block(x.as_ref(), &mut xb);
        let mut m = vec![1.0; 16];
        add_gram(&mut m, 4, &xb, 3, 1.0);
        let want = x.transpose() * &x;
        for i in 0..4 {
            for j in 0..4 {
                assert_eq!(m[j * 4 + i], 1.0 + want[(i, j)]);
            }
        }
        assert_eq!(norm1(&[1.0, -2.0, 3.0, 0.5], 2), 3.5);
    }
}

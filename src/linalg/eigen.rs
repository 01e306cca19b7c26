//! Eigenvalues and singular values (faer, sequential).

use super::gram::{add_gram, gather_block, view};
use super::simd::clear_upper_simd_state;
use faer::diag::Diag;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::evd::{self, ComputeEigenvectors};
use faer::linalg::svd::{self, ComputeSvdVectors};
use faer::{MatRef, Par};

/// Reusable scratch for symmetric eigenvalue computations of one size.
pub(crate) struct EigenScratch {
    mem: MemBuffer,
    s: Diag<f64>,
}

impl EigenScratch {
    /// Scratch for `p×p` matrices.
    pub(crate) fn new(p: usize) -> Self {
        let req = evd::self_adjoint_evd_scratch::<f64>(
            p,
            ComputeEigenvectors::No,
            Par::Seq,
            Default::default(),
        );
        Self {
            mem: MemBuffer::new(req),
            s: Diag::zeros(p),
        }
    }

    /// Eigenvalues of the symmetric matrix `m` (lower triangle read), in
    /// nondecreasing order; `None` if the iteration fails.
    pub(crate) fn eigenvalues(&mut self, m: MatRef<'_, f64>) -> Option<&[f64]> {
        let p = m.nrows();
        let stack = MemStack::new(&mut self.mem);
        let r = evd::self_adjoint_evd(
            m,
            self.s.as_mut(),
            None,
            Par::Seq,
            stack,
            Default::default(),
        );
        clear_upper_simd_state();
        r.ok()?;
        let col = self.s.column_vector();
        let slice = col.try_as_col_major()?.as_slice();
        Some(&slice[..p])
    }
}

/// Eigenvalues (nondecreasing) and eigenvectors (the columns of the second
/// matrix) of the symmetric `m` (lower triangle read), sequential; `None` if
/// the iteration fails.
pub(crate) fn symmetric_eigen(m: MatRef<'_, f64>) -> Option<(Vec<f64>, faer::Mat<f64>)> {
    let p = m.nrows();
    let req = evd::self_adjoint_evd_scratch::<f64>(
        p,
        ComputeEigenvectors::Yes,
        Par::Seq,
        Default::default(),
    );
    let mut mem = MemBuffer::new(req);
    let mut s = Diag::<f64>::zeros(p);
    let mut u = faer::Mat::<f64>::zeros(p, p);
    let r = evd::self_adjoint_evd(
        m,
        s.as_mut(),
        Some(u.as_mut()),
        Par::Seq,
        MemStack::new(&mut mem),
        Default::default(),
    );
    clear_upper_simd_state();
    r.ok()?;
    let ev: Vec<f64> = (0..p).map(|i| s[i]).collect();
    Some((ev, u))
}

/// Singular values of `x` (nonincreasing), padded with zeros to `x.ncols()`
/// when `x` has fewer rows than columns.
pub(crate) fn singular_values(x: MatRef<'_, f64>) -> Vec<f64> {
    let (m, n) = x.shape();
    let k = m.min(n);
    let mut out = vec![0.0; n];
    if k == 0 {
        return out;
    }
    let par = Par::Seq;
    let req = svd::svd_scratch::<f64>(
        m,
        n,
        ComputeSvdVectors::No,
        ComputeSvdVectors::No,
        par,
        Default::default(),
    );
    let mut mem = MemBuffer::new(req);
    let mut s = Diag::<f64>::zeros(k);
    let r = svd::svd(
        x,
        s.as_mut(),
        None,
        None,
        par,
        MemStack::new(&mut mem),
        Default::default(),
    );
    clear_upper_simd_state();
    if r.is_err() {
        // The SVD iteration did not converge; fall back to the eigenvalues of
        // XᵀX, which are σ².
        let mut g = vec![0.0; n * n];
        let mut xb = Vec::new();
        gather_block(x, &mut xb);
        add_gram(&mut g, n, &xb, m, 1.0);
        let mut es = EigenScratch::new(n);
        if let Some(ev) = es.eigenvalues(view(&g, n)) {
            let mut sv: Vec<f64> = ev.iter().map(|&l| l.max(0.0).sqrt()).collect();
            sv.sort_by(|a, b| b.total_cmp(a));
            return sv;
        }
        return out;
    }
    let col = s.column_vector();
    let sv = col
        .try_as_col_major()
        .expect("a fresh Diag is contiguous")
        .as_slice();
    for (o, &v) in out.iter_mut().zip(sv) {
        *o = v.max(0.0);
    }
    out.sort_by(|a, b| b.total_cmp(a));
    out
}

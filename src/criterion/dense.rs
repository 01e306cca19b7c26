//! Small dense kernels shared by the update formulas: packed symmetric `t×t`
//! blocks, Cholesky with a pivot floor, Gram-matrix updates, and the faer
//! calls (always sequential, so results never depend on the thread count).

use faer::diag::Diag;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt;
use faer::linalg::evd::{self, ComputeEigenvectors};
use faer::linalg::svd::{self, ComputeSvdVectors};
use faer::{Mat, MatMut, MatRef, Par};

use super::MAX_T;

/// Clears the upper halves of the vector registers (`vzeroupper`) after a
/// faer/gemm kernel. Some of gemm's x86 AVX-512 micro-kernels return with
/// dirty upper register state; until it is cleared every later SSE
/// instruction of this thread pays a transition penalty (measured: the add
/// scan slowed 10×, `ln` 7×). Cheap; a no-op without AVX.
#[inline]
pub(crate) fn clear_upper_simd_state() {
    #[cfg(target_arch = "x86_64")]
    {
        #[target_feature(enable = "avx")]
        fn zeroupper() {
            core::arch::x86_64::_mm256_zeroupper();
        }
        if std::arch::is_x86_feature_detected!("avx") {
            // SAFETY: AVX support was just checked.
            unsafe { zeroupper() }
        }
    }
}

/// Length of the packed lower triangle of a `t×t` symmetric matrix.
#[inline]
pub(crate) const fn packed_len(t: usize) -> usize {
    t * (t + 1) / 2
}

/// Index of entry `(a, b)`, `b ≤ a`, in the packed lower triangle (by rows).
#[inline]
pub(crate) const fn pk(a: usize, b: usize) -> usize {
    a * (a + 1) / 2 + b
}

/// Cholesky `A = L Lᵀ` in place of a row-major `n×n` symmetric matrix
/// (lower triangle read and overwritten by `L`). Returns `ln det A` when every
/// pivot `d_k = L_kk²` exceeds `floor`, else `Err(d_k)` for the first pivot
/// that does not (NaN pivots fail too).
#[inline]
pub(crate) fn chol_in_place(a: &mut [f64], n: usize, floor: f64) -> Result<f64, f64> {
    let mut ln_det = 0.0;
    chol_pivots_in_place(a, n, floor, |d| ln_det += d.ln())?;
    Ok(ln_det)
}

/// The Cholesky factorization of [`chol_in_place`], handing each pivot
/// `d_k = L_kk²` to `pivot` (so a caller can take their product and one `ln`
/// instead of `n` of them); `Err(d_k)` for the first pivot `≤ floor`.
#[inline]
pub(crate) fn chol_pivots_in_place(
    a: &mut [f64],
    n: usize,
    floor: f64,
    mut pivot: impl FnMut(f64),
) -> Result<(), f64> {
    for k in 0..n {
        let mut d = a[k * n + k];
        for j in 0..k {
            d -= a[k * n + j] * a[k * n + j];
        }
        if !(d > floor) {
            return Err(d);
        }
        pivot(d);
        let lkk = d.sqrt();
        a[k * n + k] = lkk;
        for i in k + 1..n {
            let mut s = a[i * n + k];
            for j in 0..k {
                s -= a[i * n + j] * a[k * n + j];
            }
            a[i * n + k] = s / lkk;
        }
    }
    Ok(())
}

/// Cholesky with diagonal (complete symmetric) pivoting, `P A Pᵀ = L Lᵀ`, in
/// place of a row-major `n×n` symmetric matrix whose *both* triangles are
/// set; `L` ends in the lower triangle and `perm[k]` is the original index of
/// position `k`. Returns `ln det A`, or `Err(d)` for the first pivot
/// `d ≤ floor` — after choosing the largest remaining diagonal, so the first
/// failing pivot is the largest remaining one.
///
/// Used for the removal Schur complement `B = I − S`: without pivoting, a
/// small early pivot amplifies the rounding of the later ones (a projection
/// `I − vvᵀ/‖v‖²` can show a zero pivot as `1e-11`); with pivoting the small
/// pivots come last and carry only `≈ n·u·‖B‖` of rounding (Higham,
/// *Accuracy and Stability*, §10.3), so the singularity test is reliable.
#[inline]
pub(crate) fn chol_pivoted_in_place(
    a: &mut [f64],
    n: usize,
    floor: f64,
    perm: &mut [usize],
) -> Result<f64, f64> {
    let mut ln_det = 0.0;
    chol_pivoted_pivots_in_place(a, n, floor, perm, |d| ln_det += d.ln())?;
    Ok(ln_det)
}

/// The pivoted factorization of [`chol_pivoted_in_place`], handing each
/// pivot `d_k` to `pivot` (for one `ln` of their product, as
/// [`chol_pivots_in_place`] does); `Err(d)` for the first pivot `≤ floor`.
#[inline]
pub(crate) fn chol_pivoted_pivots_in_place(
    a: &mut [f64],
    n: usize,
    floor: f64,
    perm: &mut [usize],
    mut pivot: impl FnMut(f64),
) -> Result<(), f64> {
    for (k, pk) in perm.iter_mut().enumerate().take(n) {
        *pk = k;
    }
    for k in 0..n {
        // Largest remaining diagonal entry (first on ties: deterministic).
        let mut j = k;
        for i in k + 1..n {
            if a[i * n + i] > a[j * n + j] {
                j = i;
            }
        }
        if j != k {
            perm.swap(k, j);
            for c in 0..n {
                a.swap(k * n + c, j * n + c);
            }
            for r in k..n {
                a.swap(r * n + k, r * n + j);
            }
        }
        let d = a[k * n + k];
        if !(d > floor) {
            return Err(d);
        }
        pivot(d);
        let l = d.sqrt();
        a[k * n + k] = l;
        for i in k + 1..n {
            a[i * n + k] /= l;
        }
        for i in k + 1..n {
            let lik = a[i * n + k];
            for c in k + 1..n {
                a[i * n + c] -= lik * a[c * n + k];
            }
        }
    }
    Ok(())
}

/// Smallest LDLᵀ pivot of a Cholesky factor produced by [`chol_in_place`]
/// or [`chol_pivoted_in_place`].
#[inline]
pub(crate) fn min_pivot(l: &[f64], n: usize) -> f64 {
    (0..n)
        .map(|k| l[k * n + k] * l[k * n + k])
        .fold(f64::INFINITY, f64::min)
}

/// `ln det(I + V)` for a packed PSD `t×t` block `V`: the add gain of
/// eq. (17)/(20) in block form. `I + V ⪰ I`, so the only failure is non-finite
/// input, reported as `-∞`.
#[inline]
pub(crate) fn ln_det_i_plus(v: &[f64], t: usize) -> f64 {
    let mut a = [0.0f64; MAX_T * MAX_T];
    for r in 0..t {
        for c in 0..=r {
            let x = v[pk(r, c)];
            a[r * t + c] = if r == c { 1.0 + x } else { x };
        }
    }
    chol_in_place(&mut a[..t * t], t, 0.0).unwrap_or(f64::NEG_INFINITY)
}

/// `ln det(I − V)` for a packed `t×t` block: the removal loss of
/// eq. (21)/(22) in block form; `Err(pivot)` when a pivot is `≤ floor`.
#[inline]
pub(crate) fn ln_det_i_minus(v: &[f64], t: usize, floor: f64) -> Result<f64, f64> {
    let mut a = [0.0f64; MAX_T * MAX_T];
    for r in 0..t {
        for c in 0..=r {
            let x = v[pk(r, c)];
            a[r * t + c] = if r == c { 1.0 - x } else { -x };
            a[c * t + r] = a[r * t + c];
        }
    }
    let mut perm = [0usize; MAX_T];
    chol_pivoted_in_place(&mut a[..t * t], t, floor, &mut perm[..t])
}

/// First factor of the exchange determinant: the Cholesky factor of
/// `I + V_in` (row-major lower triangle in `la`) and `ln det(I + V_in)`.
pub(crate) fn exchange_in_factor(
    t: usize,
    v_in: &[f64],
    la: &mut [f64; MAX_T * MAX_T],
) -> Result<f64, f64> {
    for r in 0..t {
        for c in 0..=r {
            let x = v_in[pk(r, c)];
            la[r * t + c] = if r == c { 1.0 + x } else { x };
        }
    }
    chol_in_place(&mut la[..t * t], t, 0.0)
}

/// Size below which an unpivoted pivot of the exchange's Schur complement
/// `B` is re-examined with pivoting ([`exchange_out_ln_det`]). `B` is
/// dimensionless, `0 ⪯ B ⪯ I + YᵀY`, with pivots of order 0.01–1 away from
/// singularity.
pub(crate) const SUSPECT_PIVOT: f64 = 1e-6;

/// Second factor of the exchange determinant: `ln det(I − V_out + YᵀY)`
/// with `Y = L_A⁻¹ W` (`la` from [`exchange_in_factor`], `w(a, b)` the cross
/// block `X_in M⁻¹ X_outᵀ`), with one `ln` of the product of its pivots.
/// `Err(pivot)` for a pivot `≤ floor`.
///
/// `B` is the removal Schur complement, singular exactly when the exchange
/// loses rank, and the singularity test needs pivoting (see
/// [`chol_pivoted_in_place`]): an unpivoted zero pivot can come out as
/// `1e-8`. Pivoting every candidate costs 16% of the pricing, so the plain
/// Cholesky runs first and its answer stands only when every pivot exceeds
/// [`SUSPECT_PIVOT`] — a polluted zero needs an earlier pivot about that
/// small to be amplified that far. Otherwise (and on refusal) the pivoted
/// factorization decides, as the state's update does.
pub(crate) fn exchange_out_ln_det(
    t: usize,
    la: &[f64; MAX_T * MAX_T],
    v_out: &[f64],
    w: impl Fn(usize, usize) -> f64,
    floor: f64,
) -> Result<f64, f64> {
    // Y = L_A⁻¹ W (t×t, row-major), forward substitution column by column.
    let mut y = [0.0f64; MAX_T * MAX_T];
    for c in 0..t {
        for r in 0..t {
            let mut s = w(r, c);
            for j in 0..r {
                s -= la[r * t + j] * y[j * t + c];
            }
            y[r * t + c] = s / la[r * t + r];
        }
    }
    // B = I − V_out + Yᵀ Y; `upper` also fills the upper triangle, which
    // only the pivoted factorization reads.
    let fill = |b: &mut [f64; MAX_T * MAX_T], upper: bool| {
        for r in 0..t {
            for c in 0..=r {
                let mut s = if r == c { 1.0 } else { 0.0 } - v_out[pk(r, c)];
                for j in 0..t {
                    s += y[j * t + r] * y[j * t + c];
                }
                b[r * t + c] = s;
                if upper {
                    b[c * t + r] = s;
                }
            }
        }
    };
    // The pivots are in (floor, ~1+‖Y‖²] (B ⪯ I + YᵀY), so their product
    // (t ≤ 6 of them) neither overflows nor underflows.
    let mut b = [0.0f64; MAX_T * MAX_T];
    fill(&mut b, false);
    let (mut det, mut lo) = (1.0f64, f64::INFINITY);
    let plain = chol_pivots_in_place(&mut b[..t * t], t, floor, |d| {
        det *= d;
        lo = lo.min(d);
    });
    if plain.is_ok() && lo > SUSPECT_PIVOT {
        return Ok(det.ln());
    }
    fill(&mut b, true);
    let mut det = 1.0;
    let mut perm = [0usize; MAX_T];
    chol_pivoted_pivots_in_place(&mut b[..t * t], t, floor, &mut perm[..t], |d| det *= d)?;
    Ok(det.ln())
}

/// Exchange gain `ln det [[I + V_in, W], [−Wᵀ, I − V_out]]` by block
/// elimination, `det(I + V_in) · det(I − V_out + Wᵀ(I + V_in)⁻¹W)`;
/// `Err(pivot)` when the result is numerically singular.
pub(crate) fn exchange_ln_det(
    t: usize,
    v_in: &[f64],
    v_out: &[f64],
    w: impl Fn(usize, usize) -> f64,
    floor: f64,
) -> Result<f64, f64> {
    let mut la = [0.0f64; MAX_T * MAX_T];
    let ln_a = exchange_in_factor(t, v_in, &mut la)?;
    Ok(ln_a + exchange_out_ln_det(t, &la, v_out, w, floor)?)
}

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
pub(crate) fn norm1(m: &[f64], p: usize) -> f64 {
    m.chunks(p.max(1))
        .map(|c| c.iter().map(|x| x.abs()).sum::<f64>())
        .fold(0.0, f64::max)
}

/// A `p×p` column-major slice viewed as a faer matrix.
pub(crate) fn view(m: &[f64], p: usize) -> MatRef<'_, f64> {
    MatRef::from_column_major_slice(m, p, p)
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
    // The kernel writes the lower triangle; mirror it.
    for j in 0..p {
        for i in j + 1..p {
            inv[i * p + j] = inv[j * p + i];
        }
    }
    Ok((inv, ln_det))
}

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

#[cfg(test)]
mod tests {
    use super::*;

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

    #[test]
    fn chol_matches_known_determinant() {
        // [[4, 2], [2, 3]]: det = 8.
        let mut a = [4.0, 0.0, 2.0, 3.0];
        let ld = chol_in_place(&mut a, 2, 0.0).unwrap();
        assert!((ld - 8f64.ln()).abs() < 1e-14);
        assert!((min_pivot(&a, 2) - 2.0).abs() < 1e-14);
        let mut s = [1.0, 0.0, 1.0, 1.0];
        assert!(chol_in_place(&mut s, 2, 1e-12).is_err());
    }

    #[test]
    fn pivoted_cholesky_reconstructs_and_detects_projections() {
        // B = P A Pᵀ = L Lᵀ for a 4×4 SPD matrix.
        let n = 4;
        let a0: Vec<f64> = (0..n * n)
            .map(|k| {
                let (i, j) = (k / n, k % n);
                if i == j {
                    1.0 + i as f64
                } else {
                    0.3 / (1.0 + (i + j) as f64)
                }
            })
            .collect();
        let mut a = a0.clone();
        let mut perm = [0usize; 4];
        let ld = chol_pivoted_in_place(&mut a, n, 0.0, &mut perm).unwrap();
        let mut plain = a0.clone();
        assert!((ld - chol_in_place(&mut plain, n, 0.0).unwrap()).abs() < 1e-13);
        for i in 0..n {
            for j in 0..n {
                let s: f64 = (0..=i.min(j)).map(|k| a[i * n + k] * a[j * n + k]).sum();
                assert!((s - a0[perm[i] * n + perm[j]]).abs() < 1e-13);
            }
        }
        // I − v vᵀ/‖v‖² is singular; the pivoted factorization says so at a
        // floor far below the unpivoted rounding.
        let v = [1e-3, 1.0, 2e-3, 0.5, 1e-4, 0.7];
        let nv: f64 = v.iter().map(|x| x * x).sum();
        let mut b = vec![0.0; 36];
        for i in 0..6 {
            for j in 0..6 {
                b[i * 6 + j] = if i == j { 1.0 } else { 0.0 } - v[i] * v[j] / nv;
            }
        }
        let mut perm = [0usize; 6];
        assert!(chol_pivoted_in_place(&mut b, 6, 1e-14, &mut perm).is_err());
    }

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
}

//! Unit tests of [`super`] (the small-block kernels), beside it so that
//! `small.rs` stays under 700 lines.

use super::*;

/// `ln det(I + V)` against the eigenvalues of `I + V` (nalgebra's
/// symmetric eigensolver, an independent route): `Σ ln(1 + λ_k(V))`.
/// Blocks `V = B Bᵀ` with entries from 1e-3 to 1e3 (V up to 1e6), t = 1…8
/// (3 is the unrolled path). Both sides are sums of `t` logarithms of
/// numbers `≥ 1` computed stably (the pivots of `I + V ⪰ I` and its
/// eigenvalues carry relative errors of a few `t·ε·κ`, κ ≤ 1 + ‖V‖): a
/// tolerance of `1e-12·(1 + ln det)` is loose for that and far tighter
/// than any wrong pivot (a dropped term changes ln det by O(1)).
#[test]
fn add_gain_equals_the_eigenvalue_sum() {
    let mut seed = 7u64;
    let mut rnd = || crate::linalg::test_rng::lcg(&mut seed);
    for t in 1..=8 {
        for case in 0..200 {
            let scale = 10f64.powf(-3.0 + 6.0 * (case as f64 / 199.0));
            let b = nalgebra::DMatrix::from_fn(t, t, |_, _| scale * rnd());
            let v = &b * b.transpose();
            let packed: Vec<f64> = (0..t)
                .flat_map(|r| (0..=r).map(move |c| (r, c)))
                .map(|(r, c)| v[(r, c)])
                .collect();
            let got = ln_det_i_plus(&packed, t);
            let want: f64 = v
                .symmetric_eigenvalues()
                .iter()
                .map(|l| (1.0 + l.max(0.0)).ln())
                .sum();
            assert!(
                (got - want).abs() <= 1e-12 * (1.0 + want.abs()),
                "t = {t}, case {case}: {got} vs {want}"
            );
        }
    }
    assert_eq!(
        ln_det_i_plus(&[f64::NAN, 0.0, 0.0, 0.0, 0.0, 0.0], 3),
        f64::NEG_INFINITY
    );
    // Overflowing product: the logarithms are summed.
    let big = [1e200, 0.0, 1e200, 0.0, 0.0, 1e200];
    let g = ln_det_i_plus(&big, 3);
    assert!((g - 3.0 * 1e200f64.ln()).abs() < 1e-9, "{g}");
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

/// Complete (diagonal) pivoting picks the largest remaining diagonal
/// entry, so the pivots of an SPD matrix come out non-increasing (each
/// step's Schur complement only lowers the remaining diagonal), and
/// their product is the determinant whatever the order. Random SPD
/// `A = B Bᵀ + I`, `n = 2…8`; the comparison allows rounding of a few
/// ulps of `max A_ii` (a tie decided either way by rounding is fine).
#[test]
fn pivoted_cholesky_takes_the_pivots_largest_first() {
    let mut seed = 11u64;
    let mut rnd = || crate::linalg::test_rng::lcg(&mut seed);
    for n in 2..=8 {
        for case in 0..50 {
            let b = nalgebra::DMatrix::from_fn(n, n, |_, _| rnd());
            let a0 = &b * b.transpose() + nalgebra::DMatrix::identity(n, n);
            let mut a: Vec<f64> = (0..n * n).map(|k| a0[(k / n, k % n)]).collect();
            let mut perm = vec![0usize; n];
            let mut pivots = Vec::new();
            chol_pivoted_pivots_in_place(&mut a, n, 0.0, &mut perm, |d| pivots.push(d)).unwrap();
            let top = (0..n).map(|i| a0[(i, i)]).fold(0.0f64, f64::max);
            for k in 1..n {
                assert!(
                    pivots[k] <= pivots[k - 1] + 1e-14 * top,
                    "n = {n}, case {case}: pivots {pivots:?}"
                );
            }
            let ln_det: f64 = pivots.iter().map(|d| d.ln()).sum();
            let want = a0.determinant().ln();
            assert!((ln_det - want).abs() < 1e-10, "n = {n}, case {case}");
        }
    }
}

// Issue #30's mutation sample of this file: the kernels against
// independent references (nalgebra's determinants, inverses and Cholesky
// on the same matrices), each value and each refusal.

/// A pair of `t`-row blocks and the information matrix they live in:
/// `M = M' + X_outᵀX_out` with `M' = GᵀG/p + I/2 ⪰ I/2`, `p = t + 2`
/// parameters, entries of `G`, `X_in`, `X_out` in [−1, 1). `M'` (the
/// matrix once `out` is removed) and `M` are then well conditioned (`κ`
/// below `2·(1 + (t + 1)·p) ≤ 200` for `t ≤ 8`), which the tolerances
/// below rely on.
struct Blocks {
    t: usize,
    m: nalgebra::DMatrix<f64>,
    x_in: nalgebra::DMatrix<f64>,
    x_out: nalgebra::DMatrix<f64>,
}

impl Blocks {
    fn new(t: usize, seed: &mut u64) -> Self {
        let p = t + 2;
        let mut rnd = || crate::linalg::test_rng::lcg(seed);
        let g = nalgebra::DMatrix::from_fn(p, p, |_, _| rnd());
        let x_in = nalgebra::DMatrix::from_fn(t, p, |_, _| rnd());
        let x_out = nalgebra::DMatrix::from_fn(t, p, |_, _| rnd());
        let m_removed = g.transpose() * &g / p as f64 + nalgebra::DMatrix::identity(p, p) * 0.5;
        let m = m_removed + x_out.transpose() * &x_out;
        Blocks { t, m, x_in, x_out }
    }

    /// `A M⁻¹ Bᵀ` (`t×t`).
    fn cross(
        &self,
        a: &nalgebra::DMatrix<f64>,
        b: &nalgebra::DMatrix<f64>,
    ) -> nalgebra::DMatrix<f64> {
        let mi = self.m.clone().try_inverse().unwrap();
        a * mi * b.transpose()
    }

    fn v_in(&self) -> nalgebra::DMatrix<f64> {
        self.cross(&self.x_in, &self.x_in)
    }

    fn v_out(&self) -> nalgebra::DMatrix<f64> {
        self.cross(&self.x_out, &self.x_out)
    }

    /// `W = X_in M⁻¹ X_outᵀ`, row-major.
    fn w(&self) -> Vec<f64> {
        row_major(&self.cross(&self.x_in, &self.x_out))
    }

    /// `M` without `out`.
    fn m_removed(&self) -> nalgebra::DMatrix<f64> {
        &self.m - self.x_out.transpose() * &self.x_out
    }
}

/// The packed lower triangle (by rows) of a symmetric matrix.
fn packed_of(v: &nalgebra::DMatrix<f64>) -> Vec<f64> {
    let t = v.nrows();
    (0..t)
        .flat_map(|r| (0..=r).map(move |c| (r, c)))
        .map(|(r, c)| v[(r, c)])
        .collect()
}

fn row_major(a: &nalgebra::DMatrix<f64>) -> Vec<f64> {
    (0..a.nrows() * a.ncols())
        .map(|k| a[(k / a.ncols(), k % a.ncols())])
        .collect()
}

/// `ln det` of an SPD matrix by nalgebra's Cholesky.
fn ln_det_spd(a: &nalgebra::DMatrix<f64>) -> f64 {
    let l = a.clone().cholesky().unwrap().unpack();
    l.diagonal().iter().map(|x| 2.0 * x.ln()).sum()
}

/// Tolerance of the comparisons on [`Blocks`]: every quantity is of order
/// 1–10 and comes from matrices of condition below 200, so the two routes
/// differ by a few hundred `t·ε` at most (≲ 1e-12); 1e-10 leaves room for
/// that and is far below any mutated term (order 0.01 and up).
const TOL: f64 = 1e-10;

#[test]
fn packed_indices_run_over_the_lower_triangle_by_rows() {
    for t in 0..9 {
        let mut k = 0;
        for r in 0..t {
            for c in 0..=r {
                assert_eq!(pk(r, c), k, "pk({r}, {c})");
                k += 1;
            }
        }
        assert_eq!(packed_len(t), k, "t = {t}");
    }
}

#[test]
fn scratch_holds_its_values_on_the_stack_up_to_its_size() {
    let mut s = Scratch::<f64, 4>::new(3);
    assert!(matches!(s, Scratch::Stack(_, 3)));
    assert_eq!(s.len(), 3);
    s.copy_from_slice(&[1.0, 2.0, 3.0]);
    assert_eq!(&*s, &[1.0, 2.0, 3.0]);
    let mut h = Scratch::<f64, 4>::new(5);
    assert!(matches!(h, Scratch::Heap(_)));
    assert_eq!(&*h, &[0.0; 5]);
    h[4] = 7.0;
    assert_eq!(h[4], 7.0);
    // Every block up to STACK_T × STACK_T without allocating.
    assert!(matches!(
        BlockScratch::new(STACK_T * STACK_T),
        Scratch::Stack(..)
    ));
    assert!(matches!(
        BlockScratch::new(STACK_T * STACK_T + 1),
        Scratch::Heap(..)
    ));
}

/// The plain Cholesky against nalgebra's on random SPD matrices
/// `A = B Bᵀ + I` (`n = 1…8`, entries of `B` in [−1, 1): κ ≤ 1 + n² = 65,
/// so factors and `ln det` agree to a few hundred ε; 1e-12 allows that),
/// and its refusals: the first pivot `≤ floor`, its value returned.
#[test]
fn cholesky_factors_and_refuses_the_first_small_pivot() {
    let mut seed = 3u64;
    let mut rnd = || crate::linalg::test_rng::lcg(&mut seed);
    for n in 1..=8 {
        let b = nalgebra::DMatrix::from_fn(n, n, |_, _| rnd());
        let a0 = &b * b.transpose() + nalgebra::DMatrix::identity(n, n);
        let want = a0.clone().cholesky().unwrap().unpack();
        let mut a = row_major(&a0);
        let ld = chol_in_place(&mut a, n, 0.0).unwrap();
        assert!((ld - ln_det_spd(&a0)).abs() < 1e-12, "n = {n}");
        let mut lo = f64::INFINITY;
        for i in 0..n {
            for j in 0..=i {
                assert!((a[i * n + j] - want[(i, j)]).abs() < 1e-12, "n = {n}");
            }
            lo = lo.min(want[(i, i)] * want[(i, i)]);
        }
        assert!((min_pivot(&a, n) - lo).abs() < 1e-12, "n = {n}");
    }
    // diag(4, 1, −2, 5): the third pivot, −2, is the first refused.
    let diag = |d: &[f64]| {
        let n = d.len();
        let mut a = vec![0.0; n * n];
        for (i, x) in d.iter().enumerate() {
            a[i * n + i] = *x;
        }
        a
    };
    assert_eq!(
        chol_in_place(&mut diag(&[4.0, 1.0, -2.0, 5.0]), 4, 0.0),
        Err(-2.0)
    );
    // A pivot equal to the floor is refused, one above it accepted.
    assert_eq!(chol_in_place(&mut diag(&[4.0, 0.5]), 2, 0.5), Err(0.5));
    let ld = chol_in_place(&mut diag(&[4.0, 0.5]), 2, 0.25).unwrap();
    assert!((ld - 2f64.ln()).abs() < 1e-15);
    let mut pivots = Vec::new();
    chol_pivots_in_place(&mut diag(&[4.0, 0.5, 9.0]), 3, 0.0, |d| pivots.push(d)).unwrap();
    assert_eq!(pivots, [4.0, 0.5, 9.0]);
    assert!(
        chol_in_place(&mut diag(&[f64::NAN, 1.0]), 2, 0.0)
            .unwrap_err()
            .is_nan()
    );
}

/// `min_pivot` reads the diagonal of `L` only: `min L_kk²`.
#[test]
fn min_pivot_is_the_smallest_squared_diagonal() {
    let l = [2.0, 0.0, 0.0, 9.0, 0.5, 0.0, 9.0, 9.0, 3.0];
    assert_eq!(min_pivot(&l, 3), 0.25);
    assert_eq!(min_pivot(&l, 1), 4.0);
}

/// The pivoted Cholesky takes the largest remaining diagonal first and
/// refuses at the first pivot `≤ floor`, with `perm` the chosen order.
#[test]
fn pivoted_cholesky_orders_and_refuses_the_pivots() {
    let n = 4;
    let d = [1.0, 5.0, -3.0, 2.0];
    let mut a = vec![0.0; n * n];
    for (i, x) in d.iter().enumerate() {
        a[i * n + i] = *x;
    }
    let mut perm = [9usize; 4];
    let mut pivots = Vec::new();
    let r = chol_pivoted_pivots_in_place(&mut a, n, 0.0, &mut perm, |d| pivots.push(d));
    assert_eq!(r, Err(-3.0));
    assert_eq!(pivots, [5.0, 2.0, 1.0]);
    assert_eq!(&perm[..3], &[1, 3, 0]);
}

/// `det(I + V)` of a packed 3×3 block against nalgebra's determinant, on
/// the add blocks of [`Blocks`] (det of order 1–100; relative 1e-12, as
/// [`TOL`]).
#[test]
fn the_unrolled_add_determinant_is_det_i_plus_v() {
    let mut seed = 5u64;
    for _ in 0..50 {
        let b = Blocks::new(3, &mut seed);
        let v = b.v_in();
        let want = (nalgebra::DMatrix::identity(3, 3) + &v).determinant();
        let got = det_i_plus3(&packed_of(&v));
        assert!((got - want).abs() <= 1e-12 * want.abs(), "{got} vs {want}");
    }
}

/// `ln det(I − V)` of the removal block against `ln det M' − ln det M`
/// (the determinant lemma), `t = 1…8`; and its refusal of a projection.
#[test]
fn the_removal_loss_is_the_change_of_ln_det_m() {
    let mut seed = 13u64;
    for t in 1..=8 {
        for _ in 0..10 {
            let b = Blocks::new(t, &mut seed);
            let want = ln_det_spd(&b.m_removed()) - ln_det_spd(&b.m);
            let got = ln_det_i_minus(&packed_of(&b.v_out()), t, 1e-12).unwrap();
            assert!((got - want).abs() < TOL, "t = {t}: {got} vs {want}");
        }
    }
    // V = v vᵀ/‖v‖²: I − V is singular, its last pivot rounding-small.
    let v = nalgebra::DVector::from_vec(vec![0.3, -1.0, 0.5, 0.2]);
    let p = &v * v.transpose() / v.norm_squared();
    let e = ln_det_i_minus(&packed_of(&p), 4, 1e-12).unwrap_err();
    assert!(e <= 1e-12, "{e}");
}

/// `U` from `removal_inverse_factor` is upper triangular with
/// `U Uᵀ = (I − V_out)⁻¹`, its `ln det` that of `I − V_out`, `t = 1…8`
/// (3 is the unrolled path).
#[test]
fn the_removal_inverse_factor_inverts_i_minus_v() {
    let mut seed = 17u64;
    for t in 1..=8 {
        for _ in 0..10 {
            let b = Blocks::new(t, &mut seed);
            let v = b.v_out();
            let i_minus_v = nalgebra::DMatrix::identity(t, t) - &v;
            let (ld, u) = removal_inverse_factor(&packed_of(&v), t, 1e-4).unwrap();
            assert!((ld - ln_det_spd(&i_minus_v)).abs() < TOL, "t = {t}");
            let u = nalgebra::DMatrix::from_row_slice(t, t, &u);
            for r in 0..t {
                for c in 0..r {
                    assert_eq!(u[(r, c)], 0.0, "t = {t}: U[{r}][{c}]");
                }
            }
            let id = &u * u.transpose() * &i_minus_v;
            assert!(
                (id - nalgebra::DMatrix::identity(t, t)).amax() < TOL,
                "t = {t}"
            );
        }
    }
}

/// Each pivot of `I − V_out` below `min_pivot` refuses the fast path,
/// one above it does not; non-finite entries refuse it too. Diagonal
/// blocks, whose pivots are `1 − v_kk`. (A pivot equal to `min_pivot` is
/// accepted at `t = 3` and refused by the general path's Cholesky, whose
/// floor is strict; no caller depends on the tie.)
#[test]
fn the_removal_inverse_factor_refuses_small_pivots() {
    for t in [3, 4] {
        for k in 0..t {
            let mut v = vec![0.0; packed_len(t)];
            v[pk(k, k)] = 0.75;
            assert!(
                removal_inverse_factor(&v, t, 0.5).is_none(),
                "t = {t}, k = {k}"
            );
            let (ld, u) = removal_inverse_factor(&v, t, 0.2).unwrap();
            assert!((ld - 0.25f64.ln()).abs() < 1e-15, "t = {t}, k = {k}");
            assert_eq!(u[k * t + k], 2.0);
        }
        let mut v = vec![0.0; packed_len(t)];
        v[pk(t - 1, t - 1)] = f64::NAN;
        assert!(removal_inverse_factor(&v, t, 0.2).is_none());
        v[pk(t - 1, t - 1)] = f64::NEG_INFINITY;
        assert!(removal_inverse_factor(&v, t, 0.2).is_none(), "t = {t}");
    }
}

/// The variance of a candidate once `out` is removed, `V_i + Z Zᵀ` with
/// `Z = W U`, against `X_in M'⁻¹ X_inᵀ` directly, `t = 1…8`, both the
/// general kernel and the unrolled `t = 3` one.
#[test]
fn the_variance_after_removal_is_that_of_m_without_out() {
    let mut seed = 19u64;
    for t in 1..=8 {
        for _ in 0..10 {
            let b = Blocks::new(t, &mut seed);
            let mri = b.m_removed().try_inverse().unwrap();
            let want = packed_of(&(&b.x_in * mri * b.x_in.transpose()));
            let (_, u) = removal_inverse_factor(&packed_of(&b.v_out()), t, 1e-4).unwrap();
            let (v, w) = (packed_of(&b.v_in()), b.w());
            let mut got = vec![f64::NAN; packed_len(t)];
            variance_after_removal(&v, &w, &u, t, &mut got);
            for (g, x) in got.iter().zip(&want) {
                assert!((g - x).abs() < TOL, "t = {t}: {got:?} vs {want:?}");
            }
            if t == 3 {
                let got3 = variance_after_removal3(
                    &v,
                    &w.clone().try_into().unwrap(),
                    &u.clone().try_into().unwrap(),
                );
                for (g, x) in got3.iter().zip(&want) {
                    assert!((g - x).abs() < TOL, "{got3:?} vs {want:?}");
                }
            }
        }
    }
}

/// The exchange gain against `ln det(M − X_outᵀX_out + X_inᵀX_in) −
/// ln det M`, `t = 1…8`, with its first factor `ln det(I + V_in)`.
#[test]
fn the_exchange_gain_is_the_change_of_ln_det_m() {
    let mut seed = 23u64;
    for t in 1..=8 {
        for _ in 0..10 {
            let b = Blocks::new(t, &mut seed);
            let m_new = b.m_removed() + b.x_in.transpose() * &b.x_in;
            let want = ln_det_spd(&m_new) - ln_det_spd(&b.m);
            let (v_in, v_out, w) = (packed_of(&b.v_in()), packed_of(&b.v_out()), b.w());
            let got = exchange_ln_det(t, &v_in, &v_out, |r, c| w[r * t + c], 1e-12).unwrap();
            assert!((got - want).abs() < TOL, "t = {t}: {got} vs {want}");
            let mut la = vec![0.0; t * t];
            let ln_a = exchange_in_factor(t, &v_in, &mut la).unwrap();
            let i_plus_v = nalgebra::DMatrix::identity(t, t) + b.v_in();
            assert!((ln_a - ln_det_spd(&i_plus_v)).abs() < TOL, "t = {t}");
        }
    }
}

/// An exchange that loses rank is refused: `M' = GᵀG` with `G` of rank
/// `p − 1` (its last column zero), `out` supplies the last direction of
/// `M`, and `in` has none of it.
#[test]
fn an_exchange_that_loses_rank_is_refused() {
    let mut seed = 29u64;
    let mut rnd = || crate::linalg::test_rng::lcg(&mut seed);
    for t in 1..=8 {
        let p = t + 2;
        let mut g = nalgebra::DMatrix::from_fn(p, p, |_, _| rnd());
        g.column_mut(p - 1).fill(0.0);
        let x_out = nalgebra::DMatrix::from_fn(t, p, |_, _| rnd() + 2.0);
        let mut x_in = nalgebra::DMatrix::from_fn(t, p, |_, _| rnd());
        x_in.column_mut(p - 1).fill(0.0);
        let m = g.transpose() * &g + x_out.transpose() * &x_out;
        let b = Blocks { t, m, x_in, x_out };
        let (v_in, v_out, w) = (packed_of(&b.v_in()), packed_of(&b.v_out()), b.w());
        let got = exchange_ln_det(b.t, &v_in, &v_out, |r, c| w[r * t + c], 1e-12);
        assert!(got.unwrap_err() <= 1e-12, "t = {t}: {got:?}");
    }
}

/// The plain factorization's verdict on the exchange's `B` stands only
/// when every pivot exceeds [`SUSPECT_PIVOT`]. `V_in = W = 0` (so
/// `B = I − V_out`) with `V_out = s·v vᵀ/‖v‖²`, `v` of mixed scales: at
/// `s = 1` (singular) the plain Cholesky accepts a polluted pivot
/// between the floor and SUSPECT_PIVOT (7.8e-10, checked here) and the
/// pivoted one refuses (8e-17); at `s = 1 − 1e-8` the plain factorization's
/// last pivot is again below SUSPECT_PIVOT (5.9e-7) and the pivoted one
/// prices it:
/// `ln det(I − sP) = ln(1 − s)`, up to the rounding of `P`'s entries
/// (≈ 1e-16 against an eigenvalue of 1e-8: 1e-8 relative), so within 1e-6.
#[test]
fn the_pivoted_factorization_decides_small_exchange_pivots() {
    let v = [-0.3864, 0.1406, -0.0001];
    let nv: f64 = v.iter().map(|x| x * x).sum();
    let t = v.len();
    let floor = 1e-14;
    let v_in = vec![0.0; packed_len(t)];
    let v_out = |s: f64| -> Vec<f64> {
        (0..t)
            .flat_map(|r| (0..=r).map(move |c| s * v[r] * v[c] / nv))
            .collect()
    };
    // The plain Cholesky's smallest pivot of B = I − V_out.
    let plain_lo = |v_out: &[f64]| {
        let mut b = vec![0.0; t * t];
        for r in 0..t {
            for c in 0..=r {
                b[r * t + c] = f64::from(u8::from(r == c)) - v_out[pk(r, c)];
            }
        }
        let mut lo = f64::INFINITY;
        chol_pivots_in_place(&mut b, t, floor, |d| lo = lo.min(d)).map(|()| lo)
    };
    let singular = v_out(1.0);
    let lo = plain_lo(&singular).unwrap();
    assert!(lo > floor && lo <= SUSPECT_PIVOT, "plain pivot {lo}");
    let got = exchange_ln_det(t, &v_in, &singular, |_, _| 0.0, floor);
    assert!(got.unwrap_err() <= floor, "{got:?}");
    let s = 1.0 - 1e-8;
    let lo = plain_lo(&v_out(s)).unwrap();
    assert!(lo <= SUSPECT_PIVOT, "plain pivot {lo}");
    let got = exchange_ln_det(t, &v_in, &v_out(s), |_, _| 0.0, floor).unwrap();
    let want = (1.0 - s).ln();
    assert!((got - want).abs() < 1e-6, "{got} vs {want}");
}

/// The pivoted factorization refuses a pivot equal to the floor, as the
/// plain one does (`Err(d)` for the first `d ≤ floor`), and accepts one
/// above it.
#[test]
fn pivoted_cholesky_refuses_a_pivot_at_the_floor() {
    let mut perm = [0usize; 2];
    let mut a = [4.0, 0.0, 0.0, 0.5];
    assert_eq!(chol_pivoted_in_place(&mut a, 2, 0.5, &mut perm), Err(0.5));
    let mut a = [4.0, 0.0, 0.0, 0.5];
    let ld = chol_pivoted_in_place(&mut a, 2, 0.25, &mut perm).unwrap();
    assert!((ld - 2f64.ln()).abs() < 1e-15, "{ld}");
}

/// An add block whose determinant overflows (`ln det` summed pivot by
/// pivot) keeps its moderate pivots: `V = diag(1e200, 1e200, 1e-3)`
/// (and with a fourth entry 0.5 for the general path) gives
/// `2 ln(1 + 1e200) + ln(1.001) (+ ln 1.5)`. Each logarithm is within an
/// ulp of its value (≤ 461, so ~1e-13); 1e-9 allows that, far below
/// the `ln(1e-3/1.001) ≈ −6.9` of a diagonal that dropped the identity.
#[test]
fn an_overflowing_add_determinant_keeps_its_small_pivots() {
    let want = 2.0 * 1e200f64.ln() + 1.001f64.ln();
    let got = ln_det_i_plus(&[1e200, 0.0, 1e200, 0.0, 0.0, 1e-3], 3);
    assert!((got - want).abs() < 1e-9, "{got} vs {want}");
    let v4 = [1e200, 0.0, 1e200, 0.0, 0.0, 1e-3, 0.0, 0.0, 0.0, 0.5];
    let got = ln_det_i_plus(&v4, 4);
    let want = want + 1.5f64.ln();
    assert!((got - want).abs() < 1e-9, "{got} vs {want}");
}

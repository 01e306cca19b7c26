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

//! The one numerical-rank and conditioning rule of every command, decided on
//! the column-scaled (equilibrated) problem so that units cannot change it.
//!
//! For an information matrix `M = XᵀX` (`p×p`) with `D = diag(M)`, the
//! equilibrated matrix
//!
//! `M̃ = D^-½ M D^-½ = X̃ᵀX̃`,  `X̃ = X` with every column scaled to unit norm,
//!
//! does not change when a column of `X` is multiplied by a constant — a unit
//! change (metres to millimetres, a sensor 900 km away that makes one column
//! 10⁶ times the others). Every decision about rank is taken on it:
//!
//! * `M` is **regular** when `λ_max(M̃) < MAX_CONDITION · λ_min(M̃)`;
//! * the **rank** of `M` is the number of eigenvalues `λ` of `M̃` with
//!   `λ · MAX_CONDITION > λ_max(M̃)` — for `X`, the singular values `σ` of
//!   `X̃` with `σ² · MAX_CONDITION > σ_max²`.
//!
//! `select` (the information state's singularity rule, its rank estimate,
//! the OI criterion), `bound` (the pool check), `score`, `gap` and
//! `calibrate` (identifiability) all use it, so they agree on whether a pool
//! or a design determines every unknown.
//!
//! Why `1e13`: equilibration is within a factor `p` of the best diagonal
//! scaling (van der Sluis 1969), and the rounding of Cholesky, of the
//! products `X M⁻¹ Xᵀ` and of the Woodbury updates is componentwise, hence
//! governed by `κ(M̃)`, not by the raw `κ(M)` that graded columns inflate.
//! An update then errs by about `p·u·κ(M̃)`, `≈ 0.02` in `ln det` at
//! `κ(M̃) = 1e13` and `p = 30`: beyond it a selection would be ranking
//! rounding. Eigenvalues of `M̃` are accurate to `≈ p·ε·λ_max`, so the test
//! itself is reliable up to `κ(M̃) ≈ 1e14`.

use super::eigen::EigenScratch;
use super::gram::view;
use faer::{Mat, MatRef};

/// Largest accepted condition number of the equilibrated information
/// matrix `M̃` (see the module docs); `1/√MAX_CONDITION ≈ 3.2e-7` is the
/// matching smallest singular-value ratio of the unit-column Jacobian `X̃`.
pub const MAX_CONDITION: f64 = 1e13;

/// Column scales of the equilibration: `s_j = √M_jj`, or `1` where `M_jj` is
/// not positive and finite (a zero column: its row and column of `M̃` stay
/// zero, so it counts as rank deficient).
#[must_use]
pub fn equilibration_scales(m: MatRef<'_, f64>) -> Vec<f64> {
    (0..m.nrows())
        .map(|j| {
            let d = m[(j, j)];
            if d > 0.0 && d.is_finite() {
                d.sqrt()
            } else {
                1.0
            }
        })
        .collect()
}

/// `M̃ = S⁻¹ M S⁻¹` with the [`equilibration_scales`] `S`, written to `out`
/// (`p×p` column-major); returns the scales.
pub fn equilibrate_into(m: MatRef<'_, f64>, out: &mut Vec<f64>) -> Vec<f64> {
    let p = m.nrows();
    let s = equilibration_scales(m);
    out.clear();
    out.extend((0..p * p).map(|k| {
        let (i, j) = (k % p, k / p);
        m[(i, j)] / (s[i] * s[j])
    }));
    s
}

/// `M̃` as a faer matrix, with the scales.
#[must_use]
pub fn equilibrated(m: MatRef<'_, f64>) -> (Mat<f64>, Vec<f64>) {
    let s = equilibration_scales(m);
    let p = m.nrows();
    (Mat::from_fn(p, p, |i, j| m[(i, j)] / (s[i] * s[j])), s)
}

/// Number of eigenvalues `λ` with `λ · max_condition > λ_max` (0 when none
/// is positive or any is NaN).
#[must_use]
pub fn rank_of_eigenvalues(ev: &[f64], max_condition: f64) -> usize {
    if ev.iter().any(|v| v.is_nan()) {
        return 0;
    }
    let top = ev.iter().copied().fold(0.0, f64::max);
    if !(top > 0.0) {
        return 0;
    }
    ev.iter().filter(|&&l| l * max_condition > top).count()
}

/// Number of singular values `σ` with `σ² · max_condition > σ_max²` — the
/// rank rule on `X̃` when `s` are its singular values (unit-norm columns).
#[must_use]
pub fn rank_of_singular_values(s: &[f64], max_condition: f64) -> usize {
    let sq: Vec<f64> = s.iter().map(|v| v * v).collect();
    rank_of_eigenvalues(&sq, max_condition)
}

/// Whether eigenvalues pass the regularity test
/// `λ_max < max_condition · λ_min` (false for an empty list, a NaN, or a
/// non-positive `λ_min`).
#[must_use]
pub fn eigenvalues_regular(ev: &[f64], max_condition: f64) -> bool {
    if ev.is_empty() || ev.iter().any(|v| v.is_nan()) {
        return false;
    }
    let lo = ev.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = ev.iter().copied().fold(0.0, f64::max);
    lo * max_condition > hi
}

/// Eigenvalues of the equilibrated `M̃` (nondecreasing), computed in
/// `scratch`; `None` if the symmetric eigenvalue iteration fails.
pub(crate) fn equilibrated_eigenvalues(
    m: MatRef<'_, f64>,
    scratch: &mut Vec<f64>,
    eig: &mut EigenScratch,
) -> Option<Vec<f64>> {
    let p = m.nrows();
    equilibrate_into(m, scratch);
    eig.eigenvalues(view(scratch, p)).map(<[f64]>::to_vec)
}

/// Rank of a symmetric positive semidefinite `M` under the rule, on its
/// equilibrated form (0 if the eigenvalue iteration fails).
#[must_use]
pub fn equilibrated_rank(m: MatRef<'_, f64>, max_condition: f64) -> usize {
    let mut es = EigenScratch::new(m.nrows());
    equilibrated_eigenvalues(m, &mut Vec::new(), &mut es)
        .map_or(0, |ev| rank_of_eigenvalues(&ev, max_condition))
}

/// `ln det M` of a symmetric `M` that passes the rule (`κ(M̃) <
/// max_condition`), by Cholesky of the equilibrated `M̃`
/// (`ln det M = ln det M̃ + 2 Σ ln s_j`); `None` when it fails the rule or
/// is not numerically positive definite.
#[must_use]
pub fn ln_det_regular(m: MatRef<'_, f64>, max_condition: f64) -> Option<f64> {
    let p = m.nrows();
    if p == 0 {
        return None;
    }
    let mut scaled = Vec::new();
    let s = equilibrate_into(m, &mut scaled);
    let mut es = EigenScratch::new(p);
    if !eigenvalues_regular(es.eigenvalues(view(&scaled, p))?, max_condition) {
        return None;
    }
    let ld = super::chol::ln_det_spd(view(&scaled, p))?;
    Some(ld + 2.0 * s.iter().map(|v| v.ln()).sum::<f64>())
}

/// `κ̂₁(M̃) = ‖M̃‖₁ ‖M̃⁻¹‖₁` of the equilibrated matrix from `M` and `M⁻¹`
/// (`p×p` column-major slices), in `O(p²)`: `M̃ = S⁻¹MS⁻¹`,
/// `M̃⁻¹ = S M⁻¹ S` with `s_j = √M_jj`. An upper bound of `κ₂(M̃)`, and
/// unchanged when a column of `X` is scaled.
#[must_use]
pub fn equilibrated_cond1(m: &[f64], m_inv: &[f64], p: usize) -> f64 {
    let s = equilibration_scales(view(m, p));
    let mut a: f64 = 0.0;
    let mut b: f64 = 0.0;
    for j in 0..p {
        let (mut ca, mut cb) = (0.0, 0.0);
        for i in 0..p {
            ca += m[j * p + i].abs() / (s[i] * s[j]);
            cb += m_inv[j * p + i].abs() * (s[i] * s[j]);
        }
        a = a.max(ca);
        b = b.max(cb);
    }
    a * b
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_rule_ignores_column_scales() {
        // M = S A S with A well conditioned and S spanning 12 orders of
        // magnitude: the raw κ is ~1e24, the equilibrated one that of A.
        let a = Mat::from_fn(3, 3, |i, j| if i == j { 2.0 } else { 0.5 });
        let s = [1e-6, 1.0, 1e6];
        let m = Mat::from_fn(3, 3, |i, j| a[(i, j)] * s[i] * s[j]);
        assert!(ln_det_regular(m.as_ref(), MAX_CONDITION).is_some());
        assert_eq!(equilibrated_rank(m.as_ref(), MAX_CONDITION), 3);
        let (e, sc) = equilibrated(m.as_ref());
        for i in 0..3 {
            assert!((sc[i] - s[i] * 2f64.sqrt()).abs() <= 1e-15 * sc[i]);
            for j in 0..3 {
                assert!((e[(i, j)] - a[(i, j)] / 2.0).abs() < 1e-15);
            }
        }
        // M̃ = A/2, so κ̂₁(M̃) = ‖A‖₁‖A⁻¹‖₁ whatever the scales.
        let inv = crate::linalg::chol::cholesky_inverse(m.as_ref()).unwrap().0;
        let mv: Vec<f64> = (0..9).map(|k| m[(k % 3, k / 3)]).collect();
        let k1 = equilibrated_cond1(&mv, &inv, 3);
        let av: Vec<f64> = (0..9).map(|k| a[(k % 3, k / 3)]).collect();
        let ainv = crate::linalg::chol::cholesky_inverse(a.as_ref()).unwrap().0;
        let want = crate::linalg::gram::norm1(&av, 3) * crate::linalg::gram::norm1(&ainv, 3);
        assert!((k1 - want).abs() < 1e-9 * want, "{k1} vs {want}");
    }

    #[test]
    fn rank_counts_against_the_largest() {
        assert_eq!(rank_of_eigenvalues(&[1e-14, 1e-12, 1.0], 1e13), 2);
        assert_eq!(rank_of_eigenvalues(&[0.0, 0.0], 1e13), 0);
        assert_eq!(rank_of_eigenvalues(&[f64::NAN, 1.0], 1e13), 0);
        assert_eq!(rank_of_singular_values(&[1.0, 1e-6, 1e-7], 1e13), 2);
        assert!(eigenvalues_regular(&[1e-12, 1.0], 1e13));
        assert!(!eigenvalues_regular(&[1e-13, 1.0], 1e13));
        assert!(!eigenvalues_regular(&[], 1e13));
        // A zero column is rank deficient, not a division by zero.
        let z = Mat::from_fn(2, 2, |i, j| if i == 0 && j == 0 { 4.0 } else { 0.0 });
        assert_eq!(equilibrated_rank(z.as_ref(), MAX_CONDITION), 1);
        assert!(ln_det_regular(z.as_ref(), MAX_CONDITION).is_none());
    }
}

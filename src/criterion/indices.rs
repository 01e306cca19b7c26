//! Eigenvalue (singular-value) observability indices of a design.
//!
//! With `σ_1 ≥ … ≥ σ_L` the singular values of the stacked design matrix `X`
//! (`m × p`, `m` rows), the eigenvalues of `M = XᵀX` are `σ_i²`. We take
//! `L = p`, the number of unknowns — the paper's "number of non-zero
//! eigenvalues" for an identifiable design; for a rank-deficient one the
//! products are then 0, which is what a selection criterion needs.

use faer::MatRef;
use serde::Serialize;

use crate::blocks::Blocks;
use crate::linalg::eigen::{EigenScratch, singular_values};
use crate::linalg::rank::{MAX_CONDITION, equilibrated_rank, rank_of_singular_values};

/// The singular-value indices of one design. Smaller-is-better indices are
/// marked; all others are larger-is-better. Infinite values (a singular
/// design) serialize as `null` in JSON.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Indices {
    /// `ln OI_D = ln det(XᵀX) = 2 Σ ln σ_i` (paper §III, the determinant that
    /// replaces eq. (1)); `-∞` if singular.
    pub ln_oid: f64,
    /// `log10 OI_D`.
    pub log10_oid: f64,
    /// The paper's eq. (1), `OI = (σ_1⋯σ_L)^{1/L} / L`, the minimum-variance
    /// index of its ref. \[19\]. Satisfies `OI_D = ((OI·L)^L)²` (§V-C).
    pub oi: f64,
    /// Borm & Menq's `O1 = (σ_1⋯σ_L)^{1/L} / √m`.
    pub o1: f64,
    /// `O2 = σ_max / σ_min`, the condition number of `X` (Driels & Pathre);
    /// smaller is better, `+∞` if singular.
    pub o2: f64,
    /// `O3 = σ_min`, the minimum singular value (Nahvi, Hollerbach &
    /// Hayward).
    pub o3: f64,
    /// `O4 = σ_min² / σ_max`, the noise amplification index (Nahvi &
    /// Hollerbach).
    pub o4: f64,
    /// `O5 = 1 / Σ (1/σ_i)` (Sun & Hollerbach).
    pub o5: f64,
    /// A-optimality `tr(M⁻¹) = Σ 1/σ_i²`; smaller is better, `+∞` if
    /// singular.
    pub a_trace: f64,
    /// Numerical rank by the rule every command shares
    /// (`linalg::rank`): the number of singular values `σ̃` of the
    /// column-scaled `X` (unit-norm columns) with
    /// `σ̃² · MAX_CONDITION > σ̃_max²`, so that units cannot change it
    /// ([`from_singular_values`](Self::from_singular_values), which has no
    /// columns to scale, applies it to the `σ` given).
    pub rank: usize,
}

impl Indices {
    /// Indices from the singular values of `X` (any order; `p` values,
    /// zeros for a rank-deficient `X`) and its number of rows `m`.
    #[must_use]
    pub fn from_singular_values(sigma: &[f64], m: usize) -> Self {
        let p = sigma.len();
        let l = p as f64;
        let s_max = sigma.iter().copied().fold(0.0, f64::max);
        let s_min = sigma.iter().copied().fold(f64::INFINITY, f64::min);
        let ln_oid: f64 = sigma.iter().map(|&s| 2.0 * s.ln()).sum();
        let ln_oid = if ln_oid.is_nan() {
            f64::NEG_INFINITY
        } else {
            ln_oid
        };
        // Geometric mean of the σ_i: exp(ln OI_D / (2L)).
        let geo = if p == 0 {
            0.0
        } else {
            (ln_oid / (2.0 * l)).exp()
        };
        let recip: f64 = sigma.iter().map(|&s| 1.0 / s).sum();
        let recip2: f64 = sigma.iter().map(|&s| 1.0 / (s * s)).sum();
        Self {
            ln_oid,
            log10_oid: ln_oid / std::f64::consts::LN_10,
            oi: if p == 0 { 0.0 } else { geo / l },
            o1: if m == 0 { 0.0 } else { geo / (m as f64).sqrt() },
            o2: if s_min > 0.0 {
                s_max / s_min
            } else {
                f64::INFINITY
            },
            o3: s_min,
            o4: if s_max > 0.0 {
                s_min * s_min / s_max
            } else {
                0.0
            },
            o5: 1.0 / recip,
            a_trace: recip2,
            rank: rank_of_singular_values(sigma, MAX_CONDITION),
        }
    }

    /// Indices of the design `poses` of `pool`, from the singular values of
    /// the explicitly stacked `X` (faer SVD).
    #[must_use]
    pub fn from_design(pool: &Blocks, poses: &[usize]) -> Self {
        let x = pool.select(poses);
        let mut ix = Self::from_singular_values(&singular_values(x.mat()), x.mat().nrows());
        ix.rank = equilibrated_rank(pool.information(poses).as_ref(), MAX_CONDITION);
        ix
    }

    /// Indices from an information matrix `M = XᵀX` (its eigenvalues are
    /// `σ_i²`, negative rounding clamped to 0) and the row count `m`. Less
    /// accurate than [`from_design`](Self::from_design) for small `σ_i`.
    #[must_use]
    pub fn from_information(m_info: MatRef<'_, f64>, m: usize) -> Self {
        let mut es = EigenScratch::new(m_info.nrows());
        let sigma: Vec<f64> = es
            .eigenvalues(m_info)
            .map(|ev| ev.iter().map(|&l| l.max(0.0).sqrt()).collect())
            .unwrap_or_else(|| vec![0.0; m_info.nrows()]);
        let mut ix = Self::from_singular_values(&sigma, m);
        ix.rank = equilibrated_rank(m_info, MAX_CONDITION);
        ix
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::Mat;

    #[test]
    fn known_values_and_identity() {
        let s = [4.0, 2.0, 1.0];
        let ix = Indices::from_singular_values(&s, 12);
        assert!((ix.ln_oid - 2.0 * 8f64.ln()).abs() < 1e-14);
        assert!((ix.oi - 2.0 / 3.0).abs() < 1e-14);
        assert!((ix.o1 - 2.0 / 12f64.sqrt()).abs() < 1e-14);
        assert_eq!(ix.o2, 4.0);
        assert_eq!(ix.o3, 1.0);
        assert_eq!(ix.o4, 0.25);
        assert!((ix.o5 - 1.0 / 1.75).abs() < 1e-14);
        assert!((ix.a_trace - (1.0 / 16.0 + 0.25 + 1.0)).abs() < 1e-14);
        assert_eq!(ix.rank, 3);
        // OI_D = ((OI·L)^L)², in logs.
        let l = 3.0;
        assert!((ix.ln_oid - 2.0 * l * (ix.oi * l).ln()).abs() < 1e-13);
        let sing = Indices::from_singular_values(&[1.0, 0.0], 4);
        assert_eq!(sing.ln_oid, f64::NEG_INFINITY);
        assert_eq!(sing.o2, f64::INFINITY);
        assert_eq!(sing.o5, 0.0);
        assert_eq!(sing.rank, 1);
        assert!(serde_json::to_string(&sing).is_ok());
    }

    #[test]
    fn design_and_information_agree() {
        let x = Mat::from_fn(12, 4, |i, j| {
            ((i * 7 + j * 3) % 11) as f64 - 5.0 + (i == j) as u8 as f64
        });
        let pool = Blocks::new(x.clone(), 3);
        let a = Indices::from_design(&pool, &[0, 1, 2, 3]);
        let b = Indices::from_information((x.transpose() * &x).as_ref(), 12);
        assert!((a.ln_oid - b.ln_oid).abs() < 1e-9);
        assert!((a.oi - b.oi).abs() < 1e-12);
        assert_eq!(a.rank, 4);
    }
}

//! Strategies and direct reference computations for the property tests of
//! `activecal` (the tests themselves live in `tests/`).
//!
//! Every reference value is computed directly on the changed matrix with
//! nalgebra (Cholesky, symmetric eigenvalues, SVD) — an independent library,
//! never the update formulas under test.
//!
//! # Tolerances
//!
//! All comparisons use [`ln_det_tol`] and [`inverse_tol`], which scale with
//! the unit roundoff `u`, the sizes, and the condition numbers of the
//! matrices before and after the change:
//!
//! * forming `M = XᵀX` from `m` rows and factoring it perturbs `M` by
//!   `‖δM‖ ≲ (m + p)·u·‖M‖` (Higham, *Accuracy and Stability*, Thm 10.3 and
//!   §3.5), which moves `ln det M = Σ ln λ_i` by
//!   `|tr(M⁻¹δM)| ≲ (m + p)·u·κ(M)` in a typical direction (the worst case
//!   has an extra factor `p`; observed errors sit far below either);
//! * the update formulas start from the maintained `M⁻¹`, whose relative
//!   error `r` is of the same order `(m + p)·u·κ(M)`; the determinant lemma
//!   turns it into an error `≲ t·r·‖S‖·‖(I ± S)⁻¹‖` of `ln det(I ± S)`. For an
//!   addition `‖S₊₊‖ ≤ g − 1` with `g = 1 + ‖X₊‖²‖M⁻¹‖`; for a removal
//!   `‖(I − S₋₋)⁻¹‖ = 1/μ` with `μ = λ_min(I − S₋₋)`, the fraction of
//!   information the worst direction retains (downdating cancels). So the
//!   update errs by `≲ (m + p)·u·κ(M)·a` with the *amplification*
//!   `a = g + 1/μ` (`μ` of the exchange's Schur complement for an exchange);
//!   the small `t×t` factorizations add `t²·u·a`, covered by the same term;
//! * so both sides differ by `≲ c·(m + p)·u·(κ(M)·a + κ(M'))`, with `c = 8`
//!   (in units of `ε = 2u`) as a safety factor, plus `64·ε·|ln det|` for the
//!   rounding of the sum itself.
//!
//! The amplification is inherent to updating: `κ(M)·a` can exceed both
//! `κ(M)` and `κ(M')` (removing most of the information along a strong
//! direction, or adding a block that dwarfs the design), while a direct
//! factorization of `M'` only pays `κ(M')`. The state's singularity rule
//! refuses changes with `κ̂(M)/d ≥ max_condition`, which caps it.
// Index loops mirror the matrix formulas they check; `!(x > 0)` is true
// for NaN on purpose.
#![allow(clippy::needless_range_loop, clippy::neg_cmp_op_on_partial_ord)]

pub mod dd;
pub mod reference;

use activecal::blocks::Blocks;
use activecal::criterion::Status;
use faer::Mat;
use nalgebra::DMatrix;
use proptest::prelude::*;

/// Machine epsilon `2⁻⁵²` (twice the unit roundoff `u = 2⁻⁵³`).
pub const EPS: f64 = f64::EPSILON;

/// Deterministic generator (SplitMix64) for the bulk entries of one test
/// case; proptest draws and shrinks its seed.
#[derive(Clone, Debug)]
pub struct CaseRng(u64);

impl CaseRng {
    /// A generator from a seed.
    #[must_use]
    pub fn new(seed: u64) -> Self {
        Self(seed)
    }

    /// Next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `[-1, 1)`.
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    }

    /// Standard normal (Box–Muller).
    pub fn normal(&mut self) -> f64 {
        let u1 = ((self.next_u64() >> 11) as f64 + 0.5) / (1u64 << 53) as f64;
        let u2 = (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
        (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
    }

    /// Uniform index in `0..n`.
    pub fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n as u64) as usize
    }

    /// `rows × cols` matrix of uniform `[-1, 1)` entries.
    pub fn matrix(&mut self, rows: usize, cols: usize) -> DMatrix<f64> {
        DMatrix::from_fn(rows, cols, |_, _| self.uniform())
    }

    /// `rows × cols` (`rows ≥ cols`) matrix with orthonormal columns.
    pub fn orthonormal(&mut self, rows: usize, cols: usize) -> DMatrix<f64> {
        let g = DMatrix::from_fn(rows, cols, |_, _| self.normal());
        g.qr().q().columns(0, cols).into_owned()
    }
}

/// An `m × p` matrix (`m ≥ p`) whose singular values are log-spaced from 1
/// down to `10^(-log10_cond/2)`, so that `κ(XᵀX) = 10^log10_cond` exactly
/// (up to rounding): `X = Q Σ Vᵀ` with random orthonormal `Q`, `V`.
#[must_use]
pub fn conditioned(m: usize, p: usize, log10_cond: f64, rng: &mut CaseRng) -> DMatrix<f64> {
    assert!(m >= p);
    let q = rng.orthonormal(m, p);
    let v = rng.orthonormal(p, p);
    let sigma = DMatrix::from_fn(p, p, |i, j| {
        if i == j {
            let f = if p > 1 {
                i as f64 / (p - 1) as f64
            } else {
                0.0
            };
            10f64.powf(-f * log10_cond / 2.0)
        } else {
            0.0
        }
    });
    q * sigma * v.transpose()
}

/// A random `rows × p` matrix of rank `rank` (product of random factors).
#[must_use]
pub fn rank_deficient(rows: usize, p: usize, rank: usize, rng: &mut CaseRng) -> DMatrix<f64> {
    rng.matrix(rows, rank) * rng.matrix(rank, p)
}

/// nalgebra → faer.
#[must_use]
pub fn to_faer(x: &DMatrix<f64>) -> Mat<f64> {
    Mat::from_fn(x.nrows(), x.ncols(), |i, j| x[(i, j)])
}

/// faer → nalgebra.
#[must_use]
pub fn to_nalgebra(x: faer::MatRef<'_, f64>) -> DMatrix<f64> {
    DMatrix::from_fn(x.nrows(), x.ncols(), |i, j| x[(i, j)])
}

/// The rows of `x` as a pool of `t`-row blocks.
#[must_use]
pub fn to_blocks(x: &DMatrix<f64>, t: usize) -> Blocks {
    Blocks::new(to_faer(x), t)
}

/// The rows of the given poses (`t` rows each) of `x`, stacked in order.
#[must_use]
pub fn stacked(x: &DMatrix<f64>, t: usize, design: &[usize]) -> DMatrix<f64> {
    let parts: Vec<DMatrix<f64>> = design
        .iter()
        .map(|&i| x.rows(i * t, t).into_owned())
        .collect();
    let refs: Vec<&DMatrix<f64>> = parts.iter().collect();
    vstack(&refs)
}

/// Stacks matrices vertically.
#[must_use]
pub fn vstack(parts: &[&DMatrix<f64>]) -> DMatrix<f64> {
    let p = parts[0].ncols();
    let m: usize = parts.iter().map(|x| x.nrows()).sum();
    let mut out = DMatrix::zeros(m, p);
    let mut r = 0;
    for x in parts {
        out.rows_mut(r, x.nrows()).copy_from(x);
        r += x.nrows();
    }
    out
}

/// `XᵀX`.
#[must_use]
pub fn gram(x: &DMatrix<f64>) -> DMatrix<f64> {
    x.transpose() * x
}

/// `ln det M` by nalgebra's Cholesky; `None` if `M` is not positive definite.
#[must_use]
pub fn direct_ln_det(m: &DMatrix<f64>) -> Option<f64> {
    let c = m.clone().cholesky()?;
    Some(c.ln_determinant())
}

/// `M⁻¹` by nalgebra's Cholesky; `None` if `M` is not positive definite.
#[must_use]
pub fn direct_inverse(m: &DMatrix<f64>) -> Option<DMatrix<f64>> {
    Some(m.clone().cholesky()?.inverse())
}

/// Eigenvalues of a symmetric matrix (nalgebra), ascending.
#[must_use]
pub fn eigenvalues(m: &DMatrix<f64>) -> Vec<f64> {
    let mut ev: Vec<f64> = m
        .clone()
        .symmetric_eigen()
        .eigenvalues
        .iter()
        .copied()
        .collect();
    ev.sort_by(f64::total_cmp);
    ev
}

/// 2-norm condition number of a symmetric matrix from its eigenvalues;
/// `+∞` unless positive definite.
#[must_use]
pub fn cond2(m: &DMatrix<f64>) -> f64 {
    let ev = eigenvalues(m);
    let lo = ev[0];
    let hi = ev[ev.len() - 1];
    if lo > 0.0 { hi / lo } else { f64::INFINITY }
}

/// Smallest generalized eigenvalue `λ_min(M₀⁻¹ᐟ² M₁ M₀⁻¹ᐟ²)`: how much of
/// the information of `M₀` survives in `M₁` in the worst direction
/// (`= λ_min(I − S)` for a removal). `M₀` must be positive definite.
#[must_use]
pub fn retained_fraction(m0: &DMatrix<f64>, m1: &DMatrix<f64>) -> f64 {
    let l = m0.clone().cholesky().expect("M0 positive definite").l();
    let li = l
        .clone()
        .try_inverse()
        .expect("triangular factor invertible");
    let c = &li * m1 * li.transpose();
    let c = (&c + c.transpose()) * 0.5;
    eigenvalues(&c)[0]
}

/// Largest absolute entry.
#[must_use]
pub fn max_abs(m: &DMatrix<f64>) -> f64 {
    m.iter().fold(0.0, |a, &b| a.max(b.abs()))
}

/// Tolerance for `ln det` obtained by an update against a direct
/// factorization (see the crate docs): `8·(m + p)·ε·(κ(M)·a + κ(M'))` plus
/// `64·ε·|ln det|`, with `a ≥ 1` the amplification of the change
/// ([`amplification`]).
#[must_use]
pub fn ln_det_tol(
    m: usize,
    p: usize,
    kappa_before: f64,
    kappa_after: f64,
    a: f64,
    ln_det: f64,
) -> f64 {
    8.0 * (m + p) as f64 * EPS * (kappa_before * a + kappa_after) + 64.0 * EPS * ln_det.abs()
}

/// Tolerance for `max|M⁻¹(update) − M⁻¹(direct)|`, relative to
/// `max(‖M⁻¹‖_max, ‖M'⁻¹‖_max)` (an addition subtracts `F₊F₊ᵀ ≈ M⁻¹ − M'⁻¹`
/// from `M⁻¹`, so the absolute error scales with the larger of the two):
/// the relative error of an inverse is `≲ (m + p)·u·κ`, and the Woodbury
/// factors carry the amplification `a` (see [`ln_det_tol`]), hence
/// `8·(m + p)·ε·(κ(M)·a + κ(M'))`.
#[must_use]
pub fn inverse_tol(m: usize, p: usize, kappa_before: f64, kappa_after: f64, a: f64) -> f64 {
    8.0 * (m + p) as f64 * EPS * (kappa_before * a + kappa_after)
}

/// The amplification `a = g + 1/μ` of changing `M` into
/// `M' = M + X₊ᵀX₊ − X₋ᵀX₋`, computed directly: `g = 1 + ‖X₊‖_F²/λ_min(M)`
/// (`≥ κ(I + S₊₊)`) and `μ = λ_min((M + X₊ᵀX₊)^-½ M' (M + X₊ᵀX₊)^-½)`
/// (`1/μ = 0` when nothing is removed).
#[must_use]
pub fn amplification(m: &DMatrix<f64>, plus: &DMatrix<f64>, minus: &DMatrix<f64>) -> f64 {
    let g = 1.0 + plus.norm_squared() / eigenvalues(m)[0];
    if minus.nrows() == 0 {
        return g;
    }
    let mid = m + gram(plus);
    let after = &mid - gram(minus);
    g + 1.0 / retained_fraction(&mid, &after).max(f64::MIN_POSITIVE)
}

/// The amplification of one applied update estimated from its status:
/// `1 + ‖X₊‖_F²·‖M⁻¹‖₁ + 1/d` with `d` the smallest pivot of the removal
/// Schur complement (`d ≥ μ`, exact for `t = 1`; an estimate of `1/μ`
/// otherwise) and `‖M⁻¹‖₁ ≥ ‖M⁻¹‖₂` taken before the update. `1` for a
/// refused update (nothing changed).
#[must_use]
pub fn step_amplification(status: &Status, added_frob2: f64, m_inv_norm1: f64) -> f64 {
    match *status {
        Status::Regular { min_pivot, .. } => 1.0 + added_frob2 * m_inv_norm1 + 1.0 / min_pivot,
        Status::Singular { .. } => 1.0,
    }
}

/// Induced 1-norm (largest absolute column sum).
#[must_use]
pub fn norm1(m: &DMatrix<f64>) -> f64 {
    (0..m.ncols())
        .map(|c| m.column(c).iter().map(|x| x.abs()).sum::<f64>())
        .fold(0.0, f64::max)
}

/// Induced 1-norm of a faer matrix (no copy).
#[must_use]
pub fn norm1_faer(m: faer::MatRef<'_, f64>) -> f64 {
    (0..m.ncols())
        .map(|c| m.col(c).iter().map(|x| x.abs()).sum::<f64>())
        .fold(0.0, f64::max)
}

/// Largest absolute entry of a faer matrix (no copy).
#[must_use]
pub fn max_abs_faer(m: faer::MatRef<'_, f64>) -> f64 {
    (0..m.ncols())
        .flat_map(|c| m.col(c).iter().map(|x| x.abs()))
        .fold(0.0, f64::max)
}

/// A test case's shape and conditioning.
#[derive(Clone, Debug)]
pub struct Case {
    /// Rows per pose, `1..=6`.
    pub t: usize,
    /// Parameters, `1..=40`.
    pub p: usize,
    /// `log10 κ(M)` of the starting design, `0..=10`.
    pub log10_cond: f64,
    /// Seed of the entries.
    pub seed: u64,
}

/// `t ∈ 1..=6`, `p ∈ 1..=40`, `κ(M) ∈ [1, 1e10]`, any seed.
pub fn case() -> impl Strategy<Value = Case> {
    (1usize..=6, 1usize..=40, 0.0f64..=10.0, any::<u64>()).prop_map(|(t, p, log10_cond, seed)| {
        Case {
            t,
            p,
            log10_cond,
            seed,
        }
    })
}

/// Like [`case`] with `κ(M) ≤ 1e3` (well conditioned).
pub fn well_conditioned_case() -> impl Strategy<Value = Case> {
    (1usize..=6, 1usize..=40, 0.0f64..=3.0, any::<u64>()).prop_map(|(t, p, log10_cond, seed)| {
        Case {
            t,
            p,
            log10_cond,
            seed,
        }
    })
}

/// Number of proptest cases per property: `PROPTEST_CASES` when set (lower
/// values for quick iteration), else 256.
#[must_use]
pub fn cases() -> u32 {
    std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|s| s.parse::<u32>().ok())
        .map_or(256, |n| n.max(1))
}

/// Number of cases of an expensive property: `PROPTEST_CASES` when set
/// lower than `default`, else `default`.
#[must_use]
pub fn cases_or(default: u32) -> u32 {
    std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|s| s.parse::<u32>().ok())
        .map_or(default, |n| n.min(default).max(1))
}

/// A case with graded, PUMA-like columns: `X = X_s · diag(s)` where `X_s`
/// has `κ(X_sᵀX_s) = 10^log10_cond` ([`conditioned`]) and the column scales
/// `s_j` are log-uniform in `[1e-2, 1]` with one column at `100` (the
/// PUMA's 27 unknowns span column norms `1e-2…1e2`, and the 20 m tracker
/// distance makes the `gamma_a` column about 100 times the others). Raw
/// `κ(M)` then reaches `10^log10_cond · 1e8`.
#[derive(Clone, Debug)]
pub struct GradedCase {
    /// Rows per pose, `1..=6`.
    pub t: usize,
    /// Parameters, `1..=40`.
    pub p: usize,
    /// `log10 κ` of the equilibrated starting design.
    pub log10_cond: f64,
    /// Whether the columns are graded (else all scales are 1).
    pub graded: bool,
    /// Seed of the entries.
    pub seed: u64,
}

impl GradedCase {
    /// The column scales of this case (drawn from `rng`).
    pub fn scales(&self, rng: &mut CaseRng) -> Vec<f64> {
        if !self.graded {
            return vec![1.0; self.p];
        }
        let mut s: Vec<f64> = (0..self.p)
            .map(|_| 10f64.powf(-1.0 + rng.uniform()))
            .collect();
        let big = rng.below(self.p);
        s[big] = 100.0;
        s
    }
}

/// Scales column `j` of `x` by `s[j]`.
#[must_use]
pub fn scale_columns(x: &DMatrix<f64>, s: &[f64]) -> DMatrix<f64> {
    DMatrix::from_fn(x.nrows(), x.ncols(), |i, j| x[(i, j)] * s[j])
}

/// Graded cases: `t ∈ 1..=6`, `p ∈ 1..=40`, graded columns in 3 cases of
/// 4, and the equilibrated `log10 κ` uniform in `[0, 5]` for 39 cases in 40
/// and in `[5, 7]` for the rest, so that raw `κ(M)` spans `1…1e15` (beyond
/// `1e13` the state's singularity rule decides). An equilibrated `κ` above
/// `~1e7` would make the rounding error of an accepted update itself exceed
/// the `1e-6` cap of the tolerances (`8·(m+p)·ε·κ_s ≈ 1e-6` at
/// `κ_s = 1e7`, `m + p = 60`), so such designs are covered by the
/// refusal properties instead, where the answer is a status, not a number.
/// Likewise `t ≤ p`: a block of more rows than parameters, added at a large
/// scale, makes `I + X₊M⁻¹X₊ᵀ` as ill-conditioned as the block is large
/// (`t − p` unit eigenvalues next to huge ones), and the block formula's
/// `t×t` Cholesky then loses `u·κ(I + S)` — more than `1e-6` — by design.
pub fn graded_case() -> impl Strategy<Value = GradedCase> {
    (
        1usize..=6,
        1usize..=40,
        prop_oneof![39 => 0.0f64..=5.0, 1 => 5.0f64..=7.0],
        prop::bool::weighted(0.75),
        any::<u64>(),
    )
        .prop_map(|(t, p, log10_cond, graded, seed)| GradedCase {
            t: t.min(p),
            p,
            log10_cond,
            graded,
            seed,
        })
}

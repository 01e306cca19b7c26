//! Extended-precision references for the update formulas, tolerances
//! derived from the reference alone, and the guard that keeps those
//! tolerances meaningful.
//!
//! # Reference
//!
//! [`Reference::of`] factors a double-double information matrix (built from
//! the `f64` rows by exact products, [`DdMat::gram`]) and returns `ln det`,
//! the inverse, and condition numbers, all to about `1e-16` relative for
//! every `κ ≤ 1e13` (see [`crate::dd`]): for the purpose of judging an `f64`
//! computation the reference is exact. Nothing in it comes from the state
//! under test.
//!
//! # Tolerance
//!
//! An update of `M` into `M'` (`m` rows, `p` columns) errs by
//! `≲ c·(m + p)·u·κ_s(M)·a` in `ln det` and in the scaled
//! relative error of the inverse (the crate docs derive it, with
//! `c = 8` in units of `ε = 2u`), where
//!
//! * `κ_s` is the 2-norm condition number of the *equilibrated* matrix
//!   `D M D`, `D = diag(M_jj^-½)`. Cholesky, the products `X M⁻¹ Xᵀ` and the
//!   Woodbury factors all have componentwise backward errors
//!   (`|δM| ≲ p·u·|L||Lᵀ|`, Higham Thm 10.3; `|δ(AB)| ≤ k·u·|A||B|`), which
//!   are invariant under column scaling, so the forward error is governed by
//!   `κ_s` (van der Sluis 1969; Demmel 1989), not by `κ(M)` that graded
//!   columns inflate by `(max s / min s)²`;
//! * `a = g + 1/μ` is the amplification of the change: `g = 1 + λ_max(S₊₊)`
//!   with `S₊₊ = X₊M⁻¹X₊ᵀ` (the largest factor `I + S₊₊` multiplies an
//!   error by), and `μ = λ_min((M + X₊ᵀX₊)^-½ M' (M + X₊ᵀX₊)^-½)` the
//!   fraction of information the worst direction retains after a removal
//!   (downdating cancels; `1/μ` bounds `‖(I − S)⁻¹‖`). Both are
//!   scale-invariant and computed from the reference.
//!
//! [`update_tol`] is that bound; a property passes it through
//! [`Guard::tol`], which caps it at [`CAP`] `= 1e-6` — so an answer wrong by
//! `1e-6` (relative, or in nats for `ln det`) always fails — and counts the
//! cases whose uncapped bound exceeded the cap. [`run_property`] fails a
//! property when more than 5% of its cases were such "loose" cases: the
//! strategies must produce mostly cases where the bound is tight enough to
//! catch a wrong kernel.

use std::cell::Cell;

use nalgebra::DMatrix;
use proptest::strategy::Strategy;
use proptest::test_runner::{Config, TestCaseError, TestCaseResult, TestRunner};

use crate::dd::{DdMat, Ldlt};
use crate::{EPS, eigenvalues};

/// Largest tolerance any comparison may use: `1e-6` (relative, or nats).
pub const CAP: f64 = 1e-6;

/// Largest fraction of a property's cases allowed a bound above [`CAP`].
pub const MAX_LOOSE_FRACTION: f64 = 0.05;

/// An information matrix factored in double-double precision.
#[derive(Clone, Debug)]
pub struct Reference {
    /// The matrix itself (double-double).
    pub m: DdMat,
    /// Its `LDLᵀ` factors.
    pub ldlt: Ldlt,
    /// `ln det M` (about `1e-16` absolute).
    pub ln_det: f64,
    /// `M⁻¹` rounded to `f64` (relative error `≤ u` per entry).
    pub inv: DMatrix<f64>,
    /// 2-norm condition number `λ_max/λ_min`.
    pub kappa: f64,
    /// 2-norm condition number of the equilibrated `D M D`,
    /// `D = diag(M_jj^-½)`.
    pub kappa_scaled: f64,
    /// `‖M‖₁‖M⁻¹‖₁` of the raw matrix.
    pub kappa_1: f64,
    /// `‖DMD‖₁‖(DMD)⁻¹‖₁` of the equilibrated matrix, the quantity the
    /// state's singularity rule uses (unchanged by column scaling).
    pub kappa_1_scaled: f64,
    /// `sqrt(M_jj)`: the column scales of the equilibration.
    pub col_scale: Vec<f64>,
}

impl Reference {
    /// Factors `m`; `None` if it is not positive definite in double-double
    /// precision (singular, to 32 digits).
    #[must_use]
    pub fn of(m: &DdMat) -> Option<Self> {
        let ldlt = m.ldlt()?;
        let ln_det = ldlt.ln_det();
        let inv_dd = ldlt.inverse();
        let inv = inv_dd.to_f64();
        let mf = m.to_f64();
        let lmax = |x: &DMatrix<f64>| eigenvalues(x).last().copied().unwrap_or(0.0);
        // λ_min(M) = 1/λ_max(M⁻¹): both largest eigenvalues are computed to
        // relative accuracy from accurately rounded matrices.
        let kappa = lmax(&mf) * lmax(&inv);
        let col_scale: Vec<f64> = (0..m.n).map(|j| mf[(j, j)].sqrt()).collect();
        let ms = DMatrix::from_fn(m.n, m.n, |i, j| mf[(i, j)] / (col_scale[i] * col_scale[j]));
        let msi = DMatrix::from_fn(m.n, m.n, |i, j| inv[(i, j)] * col_scale[i] * col_scale[j]);
        let kappa_scaled = lmax(&ms) * lmax(&msi);
        let kappa_1 = m.norm1() * crate::norm1(&inv);
        let kappa_1_scaled = crate::norm1(&ms) * crate::norm1(&msi);
        Some(Self {
            m: m.clone(),
            ldlt,
            ln_det,
            inv,
            kappa,
            kappa_scaled,
            kappa_1,
            kappa_1_scaled,
            col_scale,
        })
    }

    /// The reference of `XᵀX + diag(ridge)` (`ridge` empty: no ridge).
    #[must_use]
    pub fn of_rows(x: &DMatrix<f64>, ridge: &[f64]) -> Option<Self> {
        let mut m = DdMat::gram(x);
        m.add_diagonal_entries(ridge);
        Self::of(&m)
    }

    /// Largest scaled entry `max |D A D|` of a `p×p` matrix, with this
    /// reference's column scales `D = diag(sqrt(M_jj))`.
    #[must_use]
    pub fn scaled_max(&self, a: &DMatrix<f64>) -> f64 {
        let s = &self.col_scale;
        let mut out: f64 = 0.0;
        for j in 0..a.ncols() {
            for i in 0..a.nrows() {
                out = out.max((a[(i, j)] * s[i] * s[j]).abs());
            }
        }
        out
    }

    /// Scaled relative error of an inverse computed in `f64`:
    /// `max|D(got − M⁻¹)D| / max(max|D M⁻¹ D|, max|D other D|)`. `other` is
    /// the inverse the update started from (an addition subtracts a term
    /// of that size, so its rounding scales with it).
    #[must_use]
    pub fn inverse_error(&self, got: &DMatrix<f64>, other: &DMatrix<f64>) -> f64 {
        let diff = got - &self.inv;
        self.scaled_max(&diff) / self.scaled_max(&self.inv).max(self.scaled_max(other))
    }
}

/// The reference of a change `M' = M + X₊ᵀX₊ − X₋ᵀX₋`.
#[derive(Clone, Debug)]
pub struct Change {
    /// `M`.
    pub before: Reference,
    /// `M'`, `None` when it is not positive definite (to 32 digits).
    pub after: Option<Reference>,
    /// `g = 1 + λ_max(X₊M⁻¹X₊ᵀ)` (`1` when nothing is added).
    pub g: f64,
    /// `κ₂` of the equilibrated `I + X₊M⁻¹X₊ᵀ` (`1` when nothing is
    /// added): the `t×t` factor of an addition loses this much (large when a
    /// block of `t` rows adds much information in fewer than `t`
    /// directions).
    pub kappa_a: f64,
    /// Rows of the larger block (`t`).
    pub t: usize,
    /// Retained fraction `μ = λ_min((M + X₊ᵀX₊)^-½ M' (M + X₊ᵀX₊)^-½)`
    /// (`1` when nothing is removed; `≤ 0` for a singular result, to
    /// about `1e-16` absolute).
    pub mu: f64,
}

impl Change {
    /// The reference of adding `plus` and removing `minus` from `m`
    /// (positive definite).
    #[must_use]
    pub fn of(m: &DdMat, plus: &DMatrix<f64>, minus: &DMatrix<f64>) -> Self {
        let before = Reference::of(m).expect("the starting matrix is positive definite");
        let (g, kappa_a) = if plus.nrows() == 0 {
            (1.0, 1.0)
        } else {
            let s = plus * &before.inv * plus.transpose();
            let s = (&s + s.transpose()) * 0.5;
            let g = 1.0 + eigenvalues(&s).last().unwrap().max(0.0);
            // Cholesky's error is governed by the equilibrated matrix
            // (van der Sluis), so κ_a is that of D(I + S)D.
            let a = DMatrix::identity(s.nrows(), s.nrows()) + &s;
            let d: Vec<f64> = (0..a.nrows()).map(|i| a[(i, i)].sqrt()).collect();
            let ev = eigenvalues(&DMatrix::from_fn(a.nrows(), a.ncols(), |i, j| {
                a[(i, j)] / (d[i] * d[j])
            }));
            (g, ev.last().unwrap() / ev[0].max(f64::MIN_POSITIVE))
        };
        let mut mid = m.clone();
        mid.add_gram(plus, 1.0);
        let mut after = mid.clone();
        after.add_gram(minus, -1.0);
        let mu = if minus.nrows() == 0 {
            1.0
        } else {
            let f = mid.ldlt().expect("M + X₊ᵀX₊ is positive definite");
            eigenvalues(&f.congruence(&after))[0]
        };
        Self {
            t: plus.nrows().max(minus.nrows()),
            after: Reference::of(&after),
            before,
            g,
            kappa_a,
            mu,
        }
    }

    /// The amplification of the `ln det` error, `a = 1 + 1/μ` (`1` when
    /// nothing is removed). An addition needs no factor `g`: with
    /// `S = X₊M⁻¹X₊ᵀ`, a relative error `η` of `S` moves
    /// `ln det(I + S)` by `tr((I + S)⁻¹δS) ≤ t·η·‖(I + S)⁻¹S‖ ≤ t·η`; a removal
    /// divides by `λ_min(I − S) = μ` instead. The inverse error is measured
    /// relative to the larger of `M⁻¹` and `M'⁻¹` (see
    /// [`Reference::inverse_error`]), which absorbs `g` likewise.
    #[must_use]
    pub fn amplification(&self) -> f64 {
        if self.mu >= 1.0 {
            1.0
        } else {
            1.0 + 1.0 / self.mu.max(f64::MIN_POSITIVE)
        }
    }

    /// [`update_tol`] for this change in a design of `rows` rows, plus the
    /// error of the small factorizations: the `t×t` factor `L_A` of
    /// `I + S₊₊` errs by `≲ t²·u·κ_a` relative, which reaches `ln det` and
    /// (through `Y = L_A⁻¹S₊₋`, `‖Y‖² ≤ ‖S₋₋‖ ≤ 1`) the removal factor, whose
    /// smallest eigenvalue is `μ`: `8·t²·ε·κ_a·(1 + 1/μ)`.
    #[must_use]
    pub fn tol(&self, rows: usize) -> f64 {
        self.tol_after(rows, self.before.kappa_scaled)
    }

    /// [`tol`](Self::tol) for an update that starts from an inverse which
    /// is not freshly factored: `kappa_in` replaces `κ_s(M)` as the relative
    /// error of the input `M⁻¹` in units of `8·(m + p)·ε`. After updates
    /// from a fresh factorization of `M₀`, the absolute error of `M⁻¹` stays
    /// at the size of `M₀⁻¹`'s, so relative to the current `M` it is
    /// `κ_s(M₀)·G` with `G = λ_max(M₀^-½ M M₀^-½)` ([`growth`]): how much
    /// the information grew in its strongest direction (the cancellation
    /// in `M⁻¹ − F₊F₊ᵀ`).
    #[must_use]
    pub fn tol_after(&self, rows: usize, kappa_in: f64) -> f64 {
        let after = self.after.as_ref().expect("a regular change");
        let a = self.amplification();
        let t = self.t as f64;
        update_tol(rows, self.before.m.n, kappa_in, a, after.ln_det)
            + 8.0 * t * t * EPS * self.kappa_a * a
    }

    /// Slack on the retained fraction `μ` when judging a refusal: the
    /// state computes the pivot that `μ` bounds from `M⁻¹` and the added
    /// block, with error `≲ 8·(m + p)·ε·κ_s(M)·g` (see the module docs).
    #[must_use]
    pub fn refusal_slack(&self, rows: usize) -> f64 {
        8.0 * (rows + self.before.m.n) as f64 * EPS * self.before.kappa_scaled * self.g
    }
}

/// `G = λ_max(M₀^-½ M M₀^-½)`: the growth of the information `M` over the
/// freshly factored `M₀` in its strongest direction (see
/// [`Change::tol_after`]).
#[must_use]
pub fn growth(m0: &Reference, m: &DdMat) -> f64 {
    let ev = eigenvalues(&m0.ldlt.congruence(m));
    ev.last().copied().unwrap_or(1.0).max(1.0)
}

/// The error bound of an update (see the module docs):
/// `8·(m + p)·ε·κ_s(M)·a + 64·ε·|ln det M'|`.
///
/// No `κ(M')` term: the reference is exact to the precision that matters,
/// so only the update's own rounding counts — it starts from `M⁻¹` and the
/// blocks, and `M'` enters only through `μ` (in `a`).
#[must_use]
pub fn update_tol(m: usize, p: usize, ks_before: f64, a: f64, ln_det: f64) -> f64 {
    8.0 * (m + p) as f64 * EPS * ks_before * a + 64.0 * EPS * ln_det.abs()
}

/// Counts, per property, the cases whose error bound exceeded [`CAP`].
#[derive(Debug, Default)]
pub struct Guard {
    case_max: Cell<f64>,
    worst: Cell<f64>,
    total: Cell<usize>,
    loose: Cell<usize>,
}

impl Guard {
    /// The tolerance to use for a comparison whose error bound is `bound`:
    /// `min(bound, CAP)`; records `bound` for the loose-case count.
    pub fn tol(&self, bound: f64) -> f64 {
        self.case_max.set(self.case_max.get().max(bound));
        bound.min(CAP)
    }

    /// Records an observed error against its (uncapped) bound, for the
    /// margin report of [`run_property`].
    pub fn observe(&self, err: f64, bound: f64) {
        if bound > 0.0 {
            self.worst.set(self.worst.get().max(err / bound));
        }
    }

    /// Cases run (that were not rejected) and loose ones among them.
    #[must_use]
    pub fn counts(&self) -> (usize, usize) {
        (self.total.get(), self.loose.get())
    }

    fn finish_case(&self, counted: bool) {
        if counted {
            self.total.set(self.total.get() + 1);
            if self.case_max.get() > CAP {
                self.loose.set(self.loose.get() + 1);
            }
        }
        self.case_max.set(0.0);
    }
}

/// The seed of [`run_property`] when `PROPTEST_RNG_SEED` is not set.
pub const FIXED_SEED: u64 = 0x5eed_ac7e;

/// Runs a property over `cases` cases of `strategy` (seed from
/// `PROPTEST_RNG_SEED` when set), then fails unless at most
/// [`MAX_LOOSE_FRACTION`] of the cases had an error bound above [`CAP`].
/// Prints the fraction (`--nocapture` shows it).
///
/// # Panics
///
/// On a failing case (after shrinking) or too many loose cases.
pub fn run_property<S: Strategy>(
    name: &str,
    cases: u32,
    strategy: S,
    test: impl Fn(S::Value, &Guard) -> TestCaseResult,
) {
    let guard = Guard::default();
    let mut config = Config {
        cases,
        failure_persistence: None,
        ..Config::default()
    };
    // A fixed seed unless PROPTEST_RNG_SEED asks for another: the guard
    // counts a fraction of random cases (about 2 % loose on average), and a
    // suite must not pass or fail by the draw. Other seeds are explored by
    // setting the variable (20 seeds were run when the guard was set up).
    if std::env::var_os("PROPTEST_RNG_SEED").is_none() {
        config.rng_seed = proptest::test_runner::RngSeed::Fixed(FIXED_SEED);
    }
    let mut runner = TestRunner::new(config);
    let result = runner.run(&strategy, |v| {
        let r = test(v, &guard);
        guard.finish_case(!matches!(r, Err(TestCaseError::Reject(_))));
        r
    });
    if let Err(e) = result {
        panic!("{name}: {e}");
    }
    let (total, loose) = guard.counts();
    let frac = loose as f64 / total.max(1) as f64;
    eprintln!(
        "guard {name}: {loose}/{total} cases with a bound above {CAP:e} ({:.1}%), largest error/bound {:.2e}",
        100.0 * frac,
        guard.worst.get()
    );
    assert!(
        frac <= MAX_LOOSE_FRACTION,
        "{name}: {loose} of {total} cases needed a tolerance above {CAP:e}"
    );
}

//! The observability-criterion engine: the information state of a design
//! (`M = XᵀX (+ δR)`, `M⁻¹`, `ln det M`), its rank-`t` updates by the
//! matrix determinant lemma and Woodbury (paper §III, eq. (4)–(22)), batched
//! pricing of every candidate pose of a pool, eigenvalue-based observability
//! indices, and the [`Criterion`] trait the selection algorithms are written
//! against.
//!
//! # Pieces
//!
//! * [`InfoState`] — a design (pool indices) with `M`, `M⁻¹`, `ln det M`,
//!   updated by adding, removing or exchanging one pose (a `t`-row block);
//!   optionally on top of a [`Prior`] `M0` (poses measured before), so that
//!   `M = M0 + XᵀX`.
//! * [`lowrank`] — the update kernels on raw matrices: the block form
//!   ([`lowrank::woodbury`]) and the paper's row-by-row cascade
//!   ([`lowrank::cascade`]) kept as a reference implementation.
//! * [`PoolVariances`] — `V_i = X_i M⁻¹ X_iᵀ` for every pool pose, kept up to
//!   date by one `O(n·p·k)` product per update, and the cross terms
//!   `W = X_pool M⁻¹ X_Dᵀ` that price every exchange.
//! * [`Indices`] — the singular-value indices (OI, O1–O5, A-optimality, rank).
//! * [`Criterion`] with [`DCriterion`] (fast, `ln det`), [`OiCriterion`]
//!   (the paper's eigenvalue OI, recomputed per candidate) and [`ICriterion`]
//!   (the linear criterion `−tr(M⁻¹W)` of a weight moment: I-/A-optimality).
//! * [`bench_scan`] — side-by-side timings of the two.
//!
//! # Failures
//!
//! Bad input (an index outside the pool, a duplicate pose, a NaN in the pool,
//! an invalid setting) is an `Err(`[`CriterionError`]`)` naming the offending
//! value. A design whose `M` is numerically singular cannot be factored, so
//! [`InfoState::new`], [`InfoState::set_ridge`] and [`InfoState::refactorize`]
//! return the dedicated variant [`CriterionError::Singular`] with a rank
//! estimate (retry with more poses or a ridge). A *change* that would make `M`
//! singular is a numerical outcome, not an error: pricing and update methods
//! return [`Status::Singular`] and leave the state unchanged, and the batched
//! pricing of a [`Criterion`] writes `f64::NEG_INFINITY`. No path produces NaN
//! from finite input.
//!
//! # Singularity rule
//!
//! Every condition number here is that of the *equilibrated* matrix
//! `M̃ = D^-½ M D^-½` (`D = diag M`), the rule of `linalg::rank`
//! that every command decides rank by, so that scaling a column of the pool
//! (a unit change: millimetres for metres) changes no decision. `M` is
//! accepted at construction when the eigenvalues of `M̃` satisfy
//! `λ_max < max_condition · λ_min` ([`StateSettings::max_condition`],
//! default `1e13`; the rank estimate counts eigenvalues of `M̃` above
//! `λ_max / max_condition`). A change that removes rows is refused when a
//! pivot `d` of the (diagonally pivoted) Cholesky factor of its Schur
//! complement `B = I − S_oo (+ S_oi(I + S_ii)⁻¹S_io)` satisfies
//! `d ≤ κ̂(M̃) / max_condition`, with `κ̂(M̃) = ‖M̃‖₁‖M̃⁻¹‖₁ ≥ κ₂(M̃)`
//! (`S_ab = X_a M⁻¹ X_bᵀ`, hence `B` and `d`, are invariant under column
//! scaling too). The rounding of the updates is componentwise, so an update
//! errs by about `p·u·κ(M̃)·a` with the amplification `a ≈ 1/d` of a
//! removal (downdating cancels), and the rule caps it at
//! `p·u·max_condition`; since `M' ⪰ λ_min(B)·M` with `λ_min(B) ≤ d`,
//! `κ̂(M̃)/d` also estimates the condition number of the result. A refused
//! change thus certifies that the exact retained fraction `λ_min(B)` is at
//! most `d ≤ κ̂(M̃)/max_condition` (up to rounding).
//!
//! A ridge ([`StateSettings::ridge`]) is relative and per column,
//! `M = XᵀX + δ·diag(r_j)` with `r_j` the mean information of column `j`
//! per pool pose, so it scales with the units of its column as well.
//!
//! # Drift
//!
//! `M` itself is updated by adding and subtracting `X_qᵀX_q` blocks, so it
//! drifts only by the rounding of those additions; `M⁻¹` and `ln det M` are
//! updated by Woodbury and the determinant lemma, whose rounding error is
//! amplified by `κ(M)` and by the amplification `a` of the change
//! (`a = 1 + ‖X_in‖²‖M⁻¹‖ + 1/d`: large when an added block dwarfs the
//! design or a removal keeps little information in some direction). Every
//! [`StateSettings::refactor_every`] updates (`K`, default 64) the state
//! recomputes `M` from the design, refactors it by Cholesky and recomputes
//! `M⁻¹` and `ln det M`, so errors never accumulate over more than `K`
//! updates. The bound, after any number of updates:
//!
//! `|Δ ln det M| ≤ c·K·(m + p)·ε·max(κ̂(M)·a)` and
//! `‖ΔM⁻¹‖_max ≤ c·K·(m + p)·ε·max(κ̂(M)·a)·max‖M⁻¹‖_max`,
//!
//! the maxima over the updates since the last refactorization, `m` the rows
//! of the design, `ε = 2⁻⁵²`; the property tests check `c = 4` over random
//! walks of 10,000 updates (typical errors are far below it; they add up
//! like a random walk, `√K` rather than `K`). [`InfoState::drift`] measures
//! the actual error against a fresh factorization; [`InfoState::refactorize`]
//! forces one. [`PoolVariances`] follow the same low-rank updates and are
//! recomputed at every refactorization, so they obey the same bound
//! relative to `‖X_i‖²‖M⁻¹‖`.

#![warn(missing_docs)]
// `!(x > floor)` is deliberate throughout: unlike `x <= floor` it is true
// for NaN, so a NaN pivot is treated as singular.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

mod bench;
mod criteria;
mod indices;
mod linear;
pub mod lowrank;
mod pricing;
mod prior;
mod state;
#[cfg(test)]
mod test_util;
mod variances;

pub use bench::{ScanTimings, bench_scan, bench_scan_with_threads};
pub use criteria::{Criterion, DCriterion, OiCriterion, argmax};
pub use indices::Indices;
pub use linear::ICriterion;
pub use pricing::exchange_gain;
pub use prior::Prior;
pub use state::{Drift, InfoState, StateSettings, Status};
pub use variances::PoolVariances;

use thiserror::Error;

/// `ln OI_D` of a design, recomputed from scratch: `ln det(M0 + Σ_{i∈design}
/// X_iᵀX_i)` with the prior information `M0` when there is one. Without a
/// prior, `None` when the design is singular by the rank rule every command
/// shares (`linalg::rank`, on unit-norm columns); with one, `None`
/// when the sum is not positive definite (on an equilibrated copy, so that
/// the units of the parameters cannot change the decision). The one
/// direct evaluation that selection, bounds and reports check their
/// updated values against.
#[must_use]
pub fn design_ln_det(
    x: &crate::blocks::Blocks,
    prior: Option<&Prior>,
    design: &[usize],
) -> Option<f64> {
    use crate::linalg::rank::{MAX_CONDITION, ln_det_regular};
    match prior {
        None => ln_det_regular(x.information(design).as_ref(), MAX_CONDITION),
        Some(pr) => crate::linalg::chol::ln_det_spd_equilibrated(
            (x.information(design) + pr.matrix()).as_ref(),
        ),
    }
}

/// Bad input to the criterion engine, and the one numerical failure that
/// leaves nothing to work with: an information matrix that cannot be factored.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum CriterionError {
    /// A pose index outside the pool.
    #[error("pose {pose} is outside the pool of {n_poses} poses")]
    PoseOutOfRange {
        /// The index given.
        pose: usize,
        /// Number of poses in the pool.
        n_poses: usize,
    },
    /// A pose listed twice in a design (multiplicity is not allowed).
    #[error("pose {pose} appears more than once in the design")]
    DuplicatePose {
        /// The repeated index.
        pose: usize,
    },
    /// Removing or exchanging out a pose that is not in the design.
    #[error("pose {pose} is not in the design")]
    NotInDesign {
        /// The index given.
        pose: usize,
    },
    /// Adding or exchanging in a pose that is already in the design.
    #[error("pose {pose} is already in the design")]
    AlreadyInDesign {
        /// The index given.
        pose: usize,
    },
    /// A NaN or infinite entry in the pool's Jacobian blocks.
    #[error("pool entry ({row}, {col}) is not finite ({value})")]
    NonFinite {
        /// Row of the stacked matrix.
        row: usize,
        /// Column (parameter).
        col: usize,
        /// The value.
        value: f64,
    },
    /// A pool shape the engine does not support.
    #[error("unsupported pool shape: {reason}")]
    UnsupportedShape {
        /// What is wrong.
        reason: String,
    },
    /// A setting outside its valid range.
    #[error("invalid setting {name} = {value}: {reason}")]
    InvalidSetting {
        /// Setting name.
        name: &'static str,
        /// The value given.
        value: f64,
        /// The valid range.
        reason: &'static str,
    },
    /// Numerical: the information matrix `M` of the design is singular or its
    /// condition number exceeds [`StateSettings::max_condition`]. Not bad
    /// input in the usual sense; retry with more poses or a ridge.
    #[error(
        "information matrix is numerically singular (rank estimate {rank_estimate} of {p}); \
         add poses or use a ridge"
    )]
    Singular {
        /// Number of eigenvalues of `M` above `λ_max / max_condition`.
        rank_estimate: usize,
        /// Number of parameters (columns).
        p: usize,
    },
}

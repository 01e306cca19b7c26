//! The convex D-optimal relaxation as a certified upper bound on OI_D.
//!
//! For a pool of poses with Jacobian blocks `X_i` (`t × p`) and designs of
//! `N` poses, the relaxation
//!
//! `maximise ln det M(w),  M(w) = Σ_i w_i X_iᵀX_i,  0 ≤ w_i ≤ 1,  Σ_i w_i = N`   (R)
//!
//! contains every `N`-pose design (`w` = its indicator vector), so its optimum
//! `ln det M*` bounds `ln OI_D` of all of them from above. Every design then
//! carries a certified gap, its D-efficiency
//! `(det M_design / det M*)^{1/p}` ([`gap::DesignGap`]).
//!
//! The pipeline ([`relaxation_bound`]):
//! 1. scale the Jacobian columns to a common size ([`variance::scale_columns`];
//!    `ln det` shifts by the known `2·Σ ln s_j`);
//! 2. a first-order solver ([`first_order`]) gives a warm point and its variances
//!    `d_i = tr(X_i M(w)⁻¹ X_iᵀ)`;
//! 3. Clarabel ([`conic`]) solves (R) on the candidates that can carry weight
//!    (support ∪ the largest `d_i`); the optimality conditions
//!    (`w_i = 1 ⇒ d_i ≥ c`, `0 < w_i < 1 ⇒ d_i = c`, `w_i = 0 ⇒ d_i ≤ c`) are
//!    checked on the whole pool, violators added and (R) re-solved;
//! 4. the bound reported is the certificate (eq. C, [`variance::certificate`])
//!    `ln det M(w) + p·ln(S_N(w)/p)`, valid at any positive definite `M(w)`:
//!    it never depends on a solver having converged. Solver objective values
//!    are reported beside it but never used as the bound.
//!
//! **Prior information** ([`relaxation_bound`]): with poses
//! already measured, `M(w) = M0 + Σ_i w_i X_iᵀX_i` in (R); every stage
//! carries `M0` (the scaled `M̃0` of [`variance::Scaled`], the constant of
//! Clarabel's PSD block, Newton's `ln det`), and the certificate becomes
//! eq. (C0) `ln det M(w) + p·ln((tr(M(w)⁻¹M0) + S_N)/p)`, which equals (C)
//! when `M0 = 0`. `N·t < p` is then allowed.

pub mod conic;
mod error;
mod exchange_step;
pub mod first_order;
pub mod gap;
pub mod newton;
mod outcome;
mod pair;
mod relaxation;
mod settings;
mod support;
pub mod variance;

pub use error::BoundError;
pub use gap::{DesignGap, design_gap};
pub use outcome::{Bound, BoundStatus, ConicSummary, ExchangeSummary, SUPPORT_TOL};
pub use relaxation::{pool_bound, relaxation_bound};
pub use settings::{BoundSettings, BoundSettingsBuilder, RelaxationSolver};

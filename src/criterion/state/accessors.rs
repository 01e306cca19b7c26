//! What an [`InfoState`](super::InfoState) can be asked without changing
//! it: its shape, design, settings, matrices, `ln det`, condition and
//! update counters.

use super::{InfoState, NOT_IN_DESIGN, StateSettings};
use crate::criterion::lowrank::LowRank;
use crate::criterion::prior::Prior;
use crate::linalg::gram::view;
use faer::MatRef;

impl InfoState {
    /// Identity of this state (fresh for every construction and clone); with
    /// [`version`](Self::version) it keys caches.
    #[must_use]
    pub fn id(&self) -> u64 {
        self.id
    }

    /// Rows per pose.
    #[must_use]
    pub fn t(&self) -> usize {
        self.t
    }

    /// Number of parameters.
    #[must_use]
    pub fn p(&self) -> usize {
        self.p
    }

    /// Number of poses in the pool.
    #[must_use]
    pub fn n_pool(&self) -> usize {
        self.n_pool
    }

    /// Design poses (pool indices) in design order. Additions append,
    /// removals keep the order of the rest, exchanges replace in place.
    #[must_use]
    pub fn design(&self) -> &[usize] {
        &self.design
    }

    /// Position of pool pose `q` in [`design`](Self::design), if there.
    #[must_use]
    pub fn position_of(&self, q: usize) -> Option<usize> {
        self.position
            .get(q)
            .copied()
            .filter(|&k| k != NOT_IN_DESIGN)
    }

    /// Whether pool pose `q` is in the design.
    #[must_use]
    pub fn contains(&self, q: usize) -> bool {
        self.position_of(q).is_some()
    }

    /// The settings.
    #[must_use]
    pub fn settings(&self) -> &StateSettings {
        &self.settings
    }

    /// The prior information `M0`, if any.
    #[must_use]
    pub fn prior(&self) -> Option<&Prior> {
        self.prior.as_ref()
    }

    /// The relative ridge `δ`.
    #[must_use]
    pub fn ridge(&self) -> f64 {
        self.settings.ridge
    }

    /// `r_j`, the ridge's column scales: `M = XᵀX + δ·diag(r_j)` with
    /// `r_j = ‖X_pool[:, j]‖² / n_pool` (`1` for a column that is zero on the
    /// whole pool).
    #[must_use]
    pub fn ridge_scales(&self) -> &[f64] {
        &self.ridge_scale
    }

    /// `M = XᵀX + δR` (exactly symmetric).
    #[must_use]
    pub fn m(&self) -> MatRef<'_, f64> {
        view(&self.m, self.p)
    }

    /// `M⁻¹` (exactly symmetric).
    #[must_use]
    pub fn m_inv(&self) -> MatRef<'_, f64> {
        view(&self.m_inv, self.p)
    }

    /// `ln det M` (the log of the paper's `OI_D` when `δ = 0`).
    #[must_use]
    pub fn ln_det(&self) -> f64 {
        self.ln_det
    }

    /// `κ̂(M̃) = ‖M̃‖₁‖M̃⁻¹‖₁` of the equilibrated `M̃ = D^-½ M D^-½`
    /// (`D = diag M`): an upper bound of its 2-norm condition number, and
    /// unchanged when a column of the pool is scaled.
    #[must_use]
    pub fn condition_estimate(&self) -> f64 {
        self.cond1
    }

    /// Pivot floor of the singularity rule: `κ̂(M̃) / max_condition`.
    #[must_use]
    pub fn pivot_floor(&self) -> f64 {
        self.cond1 / self.settings.max_condition
    }

    /// Updates applied since the last refactorization.
    #[must_use]
    pub fn updates_since_refactor(&self) -> usize {
        self.since_refactor
    }

    /// Counter of changes (updates and refactorizations) since construction.
    #[must_use]
    pub fn version(&self) -> u64 {
        self.version
    }

    /// Counter of refactorizations since construction.
    #[must_use]
    pub fn epoch(&self) -> u64 {
        self.epoch
    }

    /// The low-rank updates applied since the last refactorization (at most
    /// the latest 128), oldest first, and the version before the first of
    /// them: update `k` took the state from version `base + k` to
    /// `base + k + 1`.
    #[must_use]
    pub fn updates_since(&self) -> (u64, &[LowRank]) {
        (self.log_base, &self.log)
    }

    // --------------------------------------------------------------- pricing
}

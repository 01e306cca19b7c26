//! What an [`InfoState`](super::InfoState)(super::InfoState) is configured with
//! ([`StateSettings`]), what an update reports ([`Status`]), and the drift
//! of its maintained quantities ([`Drift`]).

use super::super::CriterionError;
use crate::linalg::rank::MAX_CONDITION;
use serde::{Deserialize, Serialize};

/// Settings of an [`InfoState`](super::InfoState): build with
/// [`StateSettings::builder`] or take the default; validated again by
/// [`InfoState::new`](super::InfoState::new).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
#[non_exhaustive]
pub struct StateSettings {
    /// Relative ridge `δ ≥ 0`: `M = XᵀX + δR`, `R = diag(r_j)` with `r_j`
    /// the mean information of column `j` per pool pose
    /// ([`InfoState::ridge_scales`](super::InfoState::ridge_scales)), so that scaling a column (a unit
    /// change) scales its ridge with it. Lets a selection start from fewer
    /// than `p/t` poses. Default `0`.
    pub ridge: f64,
    /// Refactorize (recompute `M` from the design, Cholesky, `M⁻¹`,
    /// `ln det M`) after this many updates, `≥ 1`. Default `64`.
    pub refactor_every: usize,
    /// Largest accepted condition number of the equilibrated `M` (see the
    /// module docs' singularity rule), `> 1`. Default
    /// `linalg::rank::MAX_CONDITION` `= 1e13`, the
    /// rule every command decides rank by.
    pub max_condition: f64,
}

impl Default for StateSettings {
    fn default() -> Self {
        Self {
            ridge: 0.0,
            refactor_every: 64,
            max_condition: MAX_CONDITION,
        }
    }
}

crate::settings::settings_builder! {
    /// Validated construction of [`StateSettings`].
    StateSettingsBuilder for StateSettings, error CriterionError {
        /// Relative ridge `δ ≥ 0` (default 0).
        ridge: f64,
        /// Updates between refactorizations, `≥ 1` (default 64).
        refactor_every: usize,
        /// Largest accepted condition number, `> 1` (default 1e13).
        max_condition: f64,
    }
}

impl StateSettings {
    /// Checks every field's range.
    pub fn validate(&self) -> Result<(), CriterionError> {
        if !(self.ridge.is_finite() && self.ridge >= 0.0) {
            return Err(CriterionError::InvalidSetting {
                name: "ridge",
                value: self.ridge,
                reason: "need a finite ridge >= 0",
            });
        }
        if self.refactor_every == 0 {
            return Err(CriterionError::InvalidSetting {
                name: "refactor_every",
                value: 0.0,
                reason: "need at least 1",
            });
        }
        if !(self.max_condition.is_finite() && self.max_condition > 1.0) {
            return Err(CriterionError::InvalidSetting {
                name: "max_condition",
                value: self.max_condition,
                reason: "need a finite value > 1",
            });
        }
        Ok(())
    }
}

/// Outcome of pricing or applying a change (numerical, not an error).
#[must_use]
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub enum Status {
    /// `M` stays positive definite; `ln det M` changes by `delta_ln_det`.
    /// For an update method, the change was applied.
    Regular {
        /// `ln det M' − ln det M`.
        delta_ln_det: f64,
        /// Smallest pivot `d` of the removal Schur complement (`+∞` when
        /// nothing is removed; in `(0, 1]` for a pure removal). The rounding
        /// error of the change is amplified by about `1/d`, and the singularity
        /// rule keeps `κ̂(M̃)/d < max_condition` (`M̃` the equilibrated `M`).
        min_pivot: f64,
    },
    /// The change would make `M` numerically singular: a pivot of the
    /// removal Schur complement was `≤ pivot_floor`
    /// (`= κ̂(M̃)/max_condition`). For an update method, nothing was changed.
    Singular {
        /// The offending pivot (may be `≤ 0`).
        pivot: f64,
        /// The floor it was compared with.
        pivot_floor: f64,
    },
}

impl Status {
    /// The change of `ln det M`, or `None` if singular.
    #[must_use]
    pub fn delta(&self) -> Option<f64> {
        match *self {
            Status::Regular { delta_ln_det, .. } => Some(delta_ln_det),
            Status::Singular { .. } => None,
        }
    }

    /// Whether the change keeps `M` positive definite.
    #[must_use]
    pub fn is_regular(&self) -> bool {
        matches!(self, Status::Regular { .. })
    }
}

/// Errors of the maintained quantities against a fresh recomputation from the
/// design (see the module docs on drift).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Drift {
    /// `|ln det M (maintained) − ln det M (fresh)|`; `+∞` if the fresh `M`
    /// cannot be factored.
    pub ln_det: f64,
    /// `max |M_fresh · M⁻¹ (maintained) − I|`.
    pub inverse: f64,
    /// `max |M (maintained) − M_fresh| / max |M_fresh|`.
    pub information: f64,
}

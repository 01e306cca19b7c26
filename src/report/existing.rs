//! The poses measured before a selection (`--existing`), as `select`,
//! `bound` and `gap` report them.

use crate::blocks::Blocks;
use crate::criterion::Indices;
use serde::Serialize;

/// Poses measured before a selection (`--existing`): the prior information
/// `M0 = Σ XᵢᵀXᵢ` every reported `ln OI_D` and bound then includes.
#[derive(Clone, Debug, Serialize)]
pub struct ExistingReport {
    /// The file they were read from.
    pub file: String,
    /// Poses in it.
    pub poses: usize,
    /// Numerical rank of their stacked Jacobian.
    pub rank: usize,
    /// `ln det M0`; `None` when `M0` is singular (rank < p).
    pub ln_det: Option<f64>,
    /// `log10 det M0`; `None` when singular.
    pub log10_det: Option<f64>,
    /// What the reader ignored (columns, keys).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub notes: Vec<String>,
}

impl ExistingReport {
    /// The report of the poses in `file`, whose identification Jacobian is
    /// `x`, and the prior made of them.
    #[must_use]
    pub fn new(
        file: String,
        x: &Blocks,
        prior: &crate::criterion::Prior,
        notes: Vec<String>,
    ) -> Self {
        let all: Vec<usize> = (0..x.n_poses()).collect();
        let rank = Indices::from_design(x, &all).rank;
        let ln_det = if rank == x.p() { prior.ln_det() } else { None };
        Self {
            file,
            poses: x.n_poses(),
            rank,
            ln_det,
            log10_det: ln_det.map(|v| v / std::f64::consts::LN_10),
            notes,
        }
    }
}

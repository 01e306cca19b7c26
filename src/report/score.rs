//! `score`'s report: the observability indices of a design.

use super::PoolInfo;
use crate::blocks::Blocks;
use crate::criterion::Indices;
use serde::Serialize;

/// `score`: the observability indices of a design.
#[derive(Clone, Debug, Serialize)]
pub struct ScoreReport {
    /// The pool.
    #[serde(flatten)]
    pub pool: PoolInfo,
    /// Pose ids of the design.
    pub poses: Vec<usize>,
    /// The indices.
    #[serde(flatten)]
    pub indices: Indices,
    /// Unknowns.
    pub p: usize,
    /// `rank < p`.
    pub singular: bool,
}

impl ScoreReport {
    /// Scores the design whose Jacobian is `x_design` (one block per pose).
    #[must_use]
    pub fn new(pool: PoolInfo, poses: Vec<usize>, x_design: &Blocks) -> Self {
        let all: Vec<usize> = (0..x_design.n_poses()).collect();
        let indices = Indices::from_design(x_design, &all);
        Self {
            pool,
            poses,
            p: x_design.p(),
            singular: indices.rank < x_design.p(),
            indices,
        }
    }
}

//! `bound`'s report: the certified bound over a pool and the poses that
//! carry its weight.

use super::{ExistingReport, PoolInfo};
use crate::bound::{Bound, SUPPORT_TOL};
use crate::model::{ParamSet, Robot};
use crate::pool::Pool;
use serde::Serialize;

/// A pose carrying relaxation weight.
#[derive(Clone, Debug, Serialize)]
pub struct WeightedPose {
    /// Pose id.
    pub pose: usize,
    /// Its weight.
    pub w: f64,
}

/// `bound`: the certified bound over a pool.
#[derive(Clone, Debug, Serialize)]
pub struct BoundCommandReport {
    /// The bound.
    #[serde(flatten)]
    pub bound: Bound,
    /// The pool.
    #[serde(flatten)]
    pub pool: PoolInfo,
    /// Parameter set of the Jacobian.
    pub params: ParamSet,
    /// The settings the bound was computed with.
    pub settings: crate::bound::BoundSettings,
    /// Poses with weight above [`SUPPORT_TOL`] (when asked for).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub support: Option<Vec<WeightedPose>>,
    /// The poses measured before (`--existing`), whose information the
    /// relaxation includes.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub existing: Option<ExistingReport>,
}

impl BoundCommandReport {
    /// The report of bound `b` over `pool`.
    #[must_use]
    pub fn new(
        robot: &Robot,
        pool: &Pool,
        b: &Bound,
        params: ParamSet,
        settings: crate::bound::BoundSettings,
        with_support: bool,
    ) -> Self {
        Self {
            bound: b.clone(),
            pool: PoolInfo::new(robot, pool),
            params,
            settings,
            support: with_support.then(|| {
                b.support(SUPPORT_TOL)
                    .into_iter()
                    .map(|k| WeightedPose {
                        pose: pool.id(k),
                        w: b.weights[k],
                    })
                    .collect()
            }),
            existing: None,
        }
    }
}

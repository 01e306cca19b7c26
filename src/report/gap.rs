//! `gap`'s report: a design's D-efficiency against the bound over its pool.

use super::{ExistingReport, PoolInfo};
use crate::bound::{Bound, DesignGap};
use crate::model::ParamSet;
use serde::Serialize;

/// `gap`: a design's D-efficiency against the bound over its pool.
#[derive(Clone, Debug, Serialize)]
pub struct GapReport {
    /// The pool.
    #[serde(flatten)]
    pub pool: PoolInfo,
    /// Parameter set of the Jacobian.
    pub params: ParamSet,
    /// Pose ids of the design.
    pub poses: Vec<usize>,
    /// Poses in the design.
    pub n: usize,
    /// Unknowns.
    pub p: usize,
    /// `ln OI_D` of the design; `None` when singular.
    pub ln_oid: Option<f64>,
    /// `log10 OI_D`; `None` when singular.
    pub log10_oid: Option<f64>,
    /// Whether the design is singular.
    pub singular: bool,
    /// The bound on `ln OI_D`.
    pub ln_bound: f64,
    /// Its `log10`.
    pub log10_bound: f64,
    /// D-efficiency (eq. G).
    pub d_efficiency: f64,
    /// Ids of the design poses with relaxation weight.
    pub weighted_poses: Vec<usize>,
    /// Relaxation weight of every design pose.
    pub weights: Vec<f64>,
    /// The bound.
    pub bound: Bound,
    /// The poses measured before, when the design was chosen on top of
    /// them (`ln_oid` and the bound then include their information).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub existing: Option<ExistingReport>,
    /// Whether the design was refined off the pool (`select --refine`):
    /// the bound is then the pool's, which does not bound it, and
    /// `d_efficiency` may exceed 1.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub refined: bool,
    /// For a refined design: whether it exceeds the pool's certified bound.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub exceeds_bound: Option<bool>,
}

impl GapReport {
    /// The report of gap `g` of the design `poses` (ids) to bound `b`.
    #[must_use]
    pub fn new(
        pool: PoolInfo,
        params: ParamSet,
        poses: Vec<usize>,
        g: &DesignGap,
        b: &Bound,
    ) -> Self {
        Self {
            pool,
            params,
            weighted_poses: g.weighted.iter().map(|&k| poses[k]).collect(),
            poses,
            n: g.n,
            p: g.p,
            ln_oid: g.ln_oid,
            log10_oid: g.log10_oid,
            singular: g.ln_oid.is_none(),
            ln_bound: g.ln_bound,
            log10_bound: g.log10_bound,
            d_efficiency: g.d_efficiency,
            weights: g.weights.clone(),
            bound: b.clone(),
            existing: None,
            refined: false,
            exceeds_bound: None,
        }
    }
}

//! `select`'s report: the chosen design, its trace, its poses' joint
//! values, and (with `--refine`) the design moved off the pool.

use super::{ExistingReport, PoolInfo};
use crate::bound::DesignGap;
use crate::model::Robot;
use crate::pool::Pool;
use crate::select::{Algorithm, CriterionKind, Selection, Settings, StepKind};
use serde::Serialize;

/// One pose of a refined design (`select --refine`).
#[derive(Clone, Debug, Serialize)]
pub struct RefinedPoseReport {
    /// Id of the pool pose it started from.
    pub pose: usize,
    /// Joint values after refinement.
    pub q: Vec<f64>,
    /// Increase of `ln OI_D` from moving it.
    pub ln_gain: f64,
    /// Largest joint move.
    pub max_move: f64,
}

/// `select --refine`: the design moved off the pool, and how it compares
/// with the pool's certified bound.
#[derive(Clone, Debug, Serialize)]
pub struct RefinementReport {
    /// `ln OI_D` before (the pool design).
    pub ln_oid_before: f64,
    /// `ln OI_D` after.
    pub ln_oid: f64,
    /// `log10 OI_D` after.
    pub log10_oid: f64,
    /// `ln_oid − ln_oid_before`.
    pub ln_gain: f64,
    /// Every pose.
    pub poses: Vec<RefinedPoseReport>,
    /// Passes over the poses.
    pub sweeps: usize,
    /// Objective evaluations.
    pub evaluations: usize,
    /// With `--gap`: `exp((ln_oid − ln_bound)/p)` against the pool's bound;
    /// above 1 when the refined design beats every pool design.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub d_efficiency_vs_pool_bound: Option<f64>,
    /// With `--gap`: whether the refined design exceeds the pool's certified
    /// bound (no design of the pool can reach it; a continuous design can).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub exceeds_pool_bound: Option<bool>,
}

impl RefinementReport {
    /// The report of `r`, refined from pool positions `positions`.
    #[must_use]
    pub fn new(pool: &Pool, positions: &[usize], r: &crate::select::Refinement) -> Self {
        Self {
            ln_oid_before: r.ln_oid_before,
            ln_oid: r.ln_oid,
            log10_oid: r.ln_oid / std::f64::consts::LN_10,
            ln_gain: r.gain,
            poses: r
                .poses
                .iter()
                .map(|p| RefinedPoseReport {
                    pose: pool.id(positions[p.index]),
                    q: p.q.clone(),
                    ln_gain: p.gain,
                    max_move: p.max_move,
                })
                .collect(),
            sweeps: r.sweeps,
            evaluations: r.evaluations,
            d_efficiency_vs_pool_bound: None,
            exceeds_pool_bound: None,
        }
    }

    /// Compares the refined design with the pool's bound `ln_bound` for `p`
    /// unknowns.
    pub fn set_bound(&mut self, ln_bound: f64, p: usize) {
        self.d_efficiency_vs_pool_bound = Some(crate::bound::gap::d_efficiency(
            Some(self.ln_oid),
            ln_bound,
            p,
        ));
        self.exceeds_pool_bound = Some(self.ln_oid > ln_bound);
    }
}

/// One step of a selection trace, with pose ids.
#[derive(Clone, Debug, Serialize)]
pub struct TraceStep {
    /// Step number, 0 for the initial design.
    pub step: usize,
    /// What the step did.
    pub kind: StepKind,
    /// Id of the pose added.
    pub added: Option<usize>,
    /// Id of the pose removed.
    pub removed: Option<usize>,
    /// Design size after the step.
    pub size: usize,
    /// `ln OI_D` after the step.
    pub ln_oid: f64,
    /// `log10 OI_D` after the step.
    pub log10_oid: f64,
    /// The paper's OI after the step.
    pub oi: f64,
    /// Whether the ridge was on.
    pub ridge: bool,
}

/// `select`: the chosen design, how it was found, and (with `--gap`) its
/// D-efficiency.
#[derive(Clone, Debug, Serialize)]
pub struct SelectReport {
    /// The pool.
    #[serde(flatten)]
    pub pool: PoolInfo,
    /// Poses in the pool.
    pub pool_size: usize,
    /// Pose ids of the design, in the order they entered.
    pub poses: Vec<usize>,
    /// `ln OI_D` of the design.
    pub ln_oid: f64,
    /// `log10 OI_D`.
    pub log10_oid: f64,
    /// The paper's OI.
    pub oi: f64,
    /// One row per step.
    pub trace: Vec<TraceStep>,
    /// Wall-clock seconds of the selection.
    pub seconds: f64,
    /// The algorithm.
    pub algorithm: Algorithm,
    /// The criterion.
    pub criterion: CriterionKind,
    /// Seed.
    pub seed: u64,
    /// Starts.
    pub starts: usize,
    /// Fedorov polish.
    pub polish: bool,
    /// Rounds of iterated local search per start (0: the algorithm alone).
    pub ils: usize,
    /// Design poses exchanged at random per round of iterated local search.
    pub kick: usize,
    /// The start that won.
    pub best_start: usize,
    /// Ids of the fixed poses.
    pub fixed: Vec<usize>,
    /// `log10` of the relaxation bound (`--gap`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub log10_bound: Option<f64>,
    /// D-efficiency against the bound (`--gap`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub d_efficiency: Option<f64>,
    /// The bound's status (`--gap`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bound_status: Option<crate::bound::BoundStatus>,
    /// The poses measured before (`--existing`): `ln_oid`, the trace and
    /// the bound are then of `M0 + XᵀX`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub existing: Option<ExistingReport>,
    /// With `--existing`: `ln det XᵀX` of the new poses alone (`None` when
    /// they are singular without the prior).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ln_oid_new_only: Option<Option<f64>>,
    /// With `--existing`: `ln_oid − ln det M0`, what the new poses add
    /// (`None` when `M0` is singular).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ln_gain: Option<Option<f64>>,
    /// With `--refine`: the design moved continuously off the pool.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub refinement: Option<RefinementReport>,
    /// The errors predicted after calibrating with the chosen poses, for a
    /// given sensor noise (at random configurations).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub predicted: Option<PredictedAfter>,
    /// The chain's joint names, in configuration order.
    pub joint_names: Vec<String>,
    /// The design's poses with their joint values (refined ones with
    /// `--refine`), in visiting order (once a tour is planned; the
    /// selection's order until then).
    pub configurations: Vec<PoseConfig>,
    /// The visiting order's figures, when one was planned.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tour: Option<crate::select::tour::TourReport>,
    /// The tour's moves checked for collision (pools with a collision
    /// filter).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub moves: Option<crate::select::moves::MovesReport>,
    /// Design poses exchanged because the tour could not leave or reach
    /// them without a collision (the search's design, then these
    /// exchanges).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub swapped: Vec<crate::select::swap::SwappedPose>,
}

/// One pose of a design with its joint values.
#[derive(Clone, Debug, Serialize)]
pub struct PoseConfig {
    /// Its id in the pool.
    pub id: usize,
    /// Joint values, radians or metres, in the order of `joint_names`.
    pub q: Vec<f64>,
}

/// The errors predicted after a calibration with a design's poses: the
/// covariance `σ² (XᵀX)⁻¹` carried to the measured point at random
/// configurations ([`crate::how_many::predicted_errors`]).
#[derive(Clone, Debug, Serialize)]
pub struct PredictedAfter {
    /// The sensor noise σ per coordinate, metres.
    pub noise_m: f64,
    /// How many random configurations (seed 0) the errors are over.
    pub configurations: usize,
    /// The errors.
    #[serde(flatten)]
    pub errors: crate::how_many::PredictedErrors,
}

/// Random configurations (seed 0) the errors predicted after a selection
/// are taken over, as `select --report`'s curve takes them.
pub const PREDICTION_CONFIGURATIONS: usize = 1000;

impl PredictedAfter {
    /// The errors predicted after calibrating with the pool positions
    /// `poses` of `pool` (its identification Jacobian at `table`) with noise
    /// σ `noise` metres per coordinate, at [`PREDICTION_CONFIGURATIONS`]
    /// random configurations of seed 0; `None` for a singular design.
    #[must_use]
    pub fn of_design(
        robot: &Robot,
        table: &crate::model::ParamTable,
        pool: &crate::blocks::Blocks,
        poses: &[usize],
        noise: f64,
    ) -> Option<Self> {
        let info = pool.information(poses);
        let qs = crate::how_many::random_configurations(robot, PREDICTION_CONFIGURATIONS, 0);
        let eval = crate::blocks::jacobian_of(robot, table, qs.len(), |k, q| {
            q.copy_from_slice(&qs[k]);
        });
        let errors = crate::how_many::predicted_errors(robot, &eval, info.as_ref(), noise)?;
        Some(Self {
            noise_m: noise,
            configurations: qs.len(),
            errors,
        })
    }
}

impl SelectReport {
    /// The report of `sel`, chosen from `pool` with settings `s`.
    #[must_use]
    pub fn new(
        robot: &Robot,
        pool: &Pool,
        sel: &Selection,
        criterion: CriterionKind,
        s: &Settings,
        seconds: f64,
    ) -> Self {
        let id = |k: usize| pool.id(k);
        let l10 = |v: f64| v / std::f64::consts::LN_10;
        Self {
            pool: PoolInfo::new(robot, pool),
            pool_size: pool.len(),
            poses: pool.ids_of(&sel.poses),
            joint_names: crate::pool::file::joint_names(robot),
            configurations: sel
                .poses
                .iter()
                .map(|&k| PoseConfig {
                    id: pool.id(k),
                    q: pool.q(k),
                })
                .collect(),
            tour: None,
            moves: None,
            swapped: Vec::new(),
            ln_oid: sel.ln_oid,
            log10_oid: l10(sel.ln_oid),
            oi: sel.oi,
            trace: sel
                .trace
                .iter()
                .map(|r| TraceStep {
                    step: r.step,
                    kind: r.kind,
                    added: r.added.map(id),
                    removed: r.removed.map(id),
                    size: r.size,
                    ln_oid: r.ln_oid,
                    log10_oid: l10(r.ln_oid),
                    oi: r.oi,
                    ridge: r.ridge,
                })
                .collect(),
            seconds,
            algorithm: sel.algorithm,
            criterion,
            seed: s.seed,
            starts: s.starts,
            polish: s.polish,
            ils: s.ils,
            kick: s.kick,
            best_start: sel.start,
            fixed: pool.ids_of(&s.fixed),
            log10_bound: None,
            d_efficiency: None,
            bound_status: None,
            existing: None,
            ln_oid_new_only: None,
            ln_gain: None,
            refinement: None,
            predicted: None,
        }
    }

    /// Records the poses measured before (the prior of the selection) and
    /// `ln det XᵀX` of the new poses alone.
    pub fn set_existing(&mut self, existing: ExistingReport, ln_oid_new_only: Option<f64>) {
        self.ln_gain = Some(existing.ln_det.map(|l0| self.ln_oid - l0));
        self.ln_oid_new_only = Some(ln_oid_new_only);
        self.existing = Some(existing);
    }

    /// The report's figures a design file keeps beside its poses (its
    /// extra keys: `ln_oid`, `algorithm`, `seed`, …), as `select --out`
    /// writes them.
    #[must_use]
    pub fn design_keys(&self) -> serde_json::Map<String, serde_json::Value> {
        let v = serde_json::to_value(self).expect("a selection report serializes");
        [
            "ln_oid",
            "log10_oid",
            "oi",
            "algorithm",
            "criterion",
            "seed",
            "starts",
            "polish",
            "ils",
            "kick",
            "fixed",
        ]
        .into_iter()
        .map(|k| (k.to_string(), v[k].clone()))
        .collect()
    }

    /// Adds the design's gap to a bound.
    pub fn set_gap(&mut self, g: &DesignGap) {
        self.log10_bound = Some(g.log10_bound);
        self.d_efficiency = Some(g.d_efficiency);
        self.bound_status = Some(g.bound_status);
    }
}

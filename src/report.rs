//! Typed reports of the commands: what `select`, `score`, `bound` and `gap`
//! found, with pool positions translated to stable pose ids. Each derives
//! `Serialize`; the command line prints them as text or JSON and never
//! rebuilds them. (The bound's summary is [`BoundReport`]; the paper's
//! experiment is [`crate::experiment::paper::PaperReport`].)

use crate::blocks::Blocks;
use crate::bound::{Bound, BoundReport, DesignGap, SUPPORT_TOL};
use crate::criterion::Indices;
use crate::model::{ParamSet, Robot};
use crate::pool::{Pool, PoolSpec, PoolStats};
use crate::select::{Algorithm, CriterionKind, Selection, Settings, StepKind};
use serde::Serialize;

/// The chain a report used: the label of every frame a joint drives, in
/// joint order.
#[must_use]
pub fn chain(robot: &Robot) -> Vec<String> {
    robot
        .frames
        .iter()
        .filter(|f| f.joint.is_some())
        .map(|f| f.label.clone())
        .collect()
}

/// The pool a report refers to: robot, chain and spec.
#[derive(Clone, Debug, Serialize)]
pub struct PoolInfo {
    /// Robot name or description path.
    pub robot: String,
    /// Driven frames of the robot ([`chain`]).
    pub chain: Vec<String>,
    /// Lattice values per joint, when the pool is a lattice.
    pub levels: Option<usize>,
    /// How the pool was made.
    pub pool: PoolSpec,
    /// What building it did: candidates, what each filter removed, notes
    /// (absent when no pool was built).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pool_stats: Option<PoolStats>,
}

impl PoolInfo {
    /// The description of `pool` for `robot`.
    #[must_use]
    pub fn new(robot: &Robot, pool: &Pool) -> Self {
        Self {
            robot: robot.name.clone(),
            chain: chain(robot),
            levels: pool.spec.levels(),
            pool: pool.spec.clone(),
            pool_stats: Some(pool.stats.clone()),
        }
    }
}

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
    /// The chain's joint names, in configuration order.
    pub joint_names: Vec<String>,
    /// The design's poses with their joint values (refined ones with
    /// `--refine`), in visiting order ([`SelectReport::set_visit`]; the
    /// selection's order until then).
    pub configurations: Vec<PoseConfig>,
    /// The visiting order's figures, when one was planned.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tour: Option<crate::select::tour::TourReport>,
    /// The tour's moves checked for collision (pools with a collision
    /// filter).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub moves: Option<crate::select::moves::MovesReport>,
}

/// One pose of a design with its joint values.
#[derive(Clone, Debug, Serialize)]
pub struct PoseConfig {
    /// Its id in the pool.
    pub id: usize,
    /// Joint values, radians or metres, in the order of `joint_names`.
    pub q: Vec<f64>,
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
        }
    }

    /// Records the poses measured before (the prior of the selection) and
    /// `ln det XᵀX` of the new poses alone.
    pub fn set_existing(&mut self, existing: ExistingReport, ln_oid_new_only: Option<f64>) {
        self.ln_gain = Some(existing.ln_det.map(|l0| self.ln_oid - l0));
        self.ln_oid_new_only = Some(ln_oid_new_only);
        self.existing = Some(existing);
    }

    /// Adds the design's gap to a bound.
    pub fn set_gap(&mut self, g: &DesignGap) {
        self.log10_bound = Some(g.log10_bound);
        self.d_efficiency = Some(g.d_efficiency);
        self.bound_status = Some(g.bound_status);
    }
}

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
    pub bound: BoundReport,
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
            bound: BoundReport::from(b),
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
    pub bound: BoundReport,
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
            bound: BoundReport::from(b),
            existing: None,
            refined: false,
            exceeds_bound: None,
        }
    }
}

/// `{name: value}`, in name order.
fn named(names: &[String], values: &[f64]) -> std::collections::BTreeMap<String, f64> {
    names.iter().cloned().zip(values.iter().copied()).collect()
}

/// What every calibration reports about its identification.
#[derive(Clone, Debug, Serialize)]
pub struct IdentificationReport {
    /// Outcome.
    pub status: crate::identify::Status,
    /// Which rule stopped the iteration.
    pub stop: crate::identify::StopReason,
    /// Whether the status is converged.
    pub converged: bool,
    /// Outer iterations.
    pub iterations: usize,
    /// Residual evaluations.
    pub evaluations: usize,
    /// The estimate, by unknown.
    pub estimate: std::collections::BTreeMap<String, f64>,
    /// Standard deviations, by unknown (full rank only).
    pub std: Option<std::collections::BTreeMap<String, f64>>,
    /// The labelled correlation matrix (full rank only).
    pub correlation: Option<crate::identify::Correlation>,
    /// `σ̂`.
    pub sigma_hat: Option<f64>,
    /// Residual sum of squares at the estimate.
    pub rss: f64,
    /// Residual sum of squares at the start.
    pub initial_rss: f64,
    /// Numerical rank.
    pub rank: usize,
    /// Unknowns in the null space.
    pub unidentifiable: Vec<String>,
}

impl From<&crate::identify::Identification> for IdentificationReport {
    fn from(id: &crate::identify::Identification) -> Self {
        let names = &id.names;
        Self {
            status: id.status,
            stop: id.stop,
            converged: id.converged(),
            iterations: id.iterations,
            evaluations: id.evaluations,
            estimate: named(names, &id.estimate),
            std: id.covariance.as_ref().map(|c| named(names, &c.std)),
            correlation: id.covariance.as_ref().map(|c| c.correlation.clone()),
            sigma_hat: id.sigma_hat,
            rss: id.rss,
            initial_rss: id.initial_rss,
            rank: id.rank,
            unidentifiable: id.unidentifiable.clone(),
        }
    }
}

/// `calibrate --measurements`: identification from measured data.
#[derive(Clone, Debug, Serialize)]
pub struct MeasuredCalibrationReport {
    /// The identification.
    #[serde(flatten)]
    pub identification: IdentificationReport,
    /// Robot name or description path.
    pub robot: String,
    /// Driven frames.
    pub chain: Vec<String>,
    /// The measurement file.
    pub measurements: String,
    /// Measured poses.
    pub poses: usize,
    /// What was measured.
    pub measurement: crate::model::MeasurementKind,
    /// Estimate − start, by unknown.
    pub change: std::collections::BTreeMap<String, f64>,
    /// RMS weighted residual per row at the estimate.
    pub rms_residual: f64,
    /// RMS weighted residual per row of the nominal model.
    pub initial_rms_residual: f64,
    /// The calibrated robot's files written (none when not asked or not
    /// converged).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub out: Vec<String>,
    /// Wall-clock seconds.
    pub elapsed_seconds: f64,
}

impl MeasuredCalibrationReport {
    /// The report of `id`, identified from `poses` measured poses in `file`.
    #[must_use]
    pub fn new(
        robot: &Robot,
        id: &crate::identify::Identification,
        file: String,
        poses: usize,
    ) -> Self {
        let rows = (robot.rows_per_pose() * poses) as f64;
        let change: Vec<f64> = id
            .estimate
            .iter()
            .zip(&id.start)
            .map(|(e, s)| e - s)
            .collect();
        Self {
            identification: IdentificationReport::from(id),
            robot: robot.name.clone(),
            chain: chain(robot),
            measurements: file,
            poses,
            measurement: robot.measurement,
            change: named(&id.names, &change),
            rms_residual: (id.rss / rows).sqrt(),
            initial_rms_residual: (id.initial_rss / rows).sqrt(),
            out: Vec::new(),
            elapsed_seconds: 0.0,
        }
    }
}

/// `calibrate --design`: simulated calibration at a design, validated on
/// held-out poses of the design's pool.
#[derive(Clone, Debug, Serialize)]
pub struct SimulatedCalibrationReport {
    /// The identification (trial 0 of the seed).
    #[serde(flatten)]
    pub identification: IdentificationReport,
    /// Robot name or description path.
    pub robot: String,
    /// Driven frames.
    pub chain: Vec<String>,
    /// The design file.
    pub design: String,
    /// The design's pool.
    pub pool: PoolSpec,
    /// Poses in that pool.
    pub pool_size: usize,
    /// Poses in the design.
    pub poses: usize,
    /// What is measured.
    pub measurement: crate::model::MeasurementKind,
    /// Noise σ per coordinate, metres.
    pub noise: f64,
    /// Orientation noise, radians (full-pose robots).
    pub orientation_noise: Option<f64>,
    /// Seed.
    pub seed: u64,
    /// Real − estimate, by unknown.
    pub residual: std::collections::BTreeMap<String, f64>,
    /// Held-out validation poses.
    pub validation_poses: usize,
    /// Validation RMS position error of the nominal model.
    pub validation_rms_before: f64,
    /// Validation RMS position error of the estimate.
    pub validation_rms_after: f64,
    /// Validation RMS orientation error of the nominal model.
    pub validation_orientation_rms_before: Option<f64>,
    /// Validation RMS orientation error of the estimate.
    pub validation_orientation_rms_after: Option<f64>,
    /// Monte-Carlo summary (`--trials` > 1).
    pub monte_carlo: Option<crate::identify::MonteCarloSummary>,
    /// Seconds of the Monte-Carlo.
    pub monte_carlo_seconds: Option<f64>,
    /// The calibrated robot's measurement frame, tool and joint origins
    /// (URDF robots).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub frames: Option<crate::frames::report::FramesReport>,
    /// Wall-clock seconds.
    pub elapsed_seconds: f64,
}

/// `fk`: forward kinematics (and the identification Jacobian) at one joint
/// vector.
#[derive(Clone, Debug, Serialize)]
pub struct FkReport {
    /// Robot name or description path.
    pub robot: String,
    /// Driven frames.
    pub chain: Vec<String>,
    /// Parameter set.
    pub params: ParamSet,
    /// Joint values, radians (or metres).
    pub q: Vec<f64>,
    /// End point.
    pub position: [f64; 3],
    /// The end frame's orientation, for robots whose sensor measures or
    /// observes it (full poses, several markers).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub orientation: Option<Orientation>,
    /// Predicted marker positions (a marker robot).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub markers: Option<Vec<[f64; 3]>>,
    /// Identification Jacobian, `t` rows of `p` (when asked for).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub jacobian: Option<Vec<Vec<f64>>>,
    /// Names of its columns (when the Jacobian is asked for).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub parameter_names: Option<Vec<String>>,
}

impl FkReport {
    /// Forward kinematics of `robot` at `q` with table `params`, and the
    /// Jacobian when `jacobian` is set.
    pub fn new(
        robot: &Robot,
        params: ParamSet,
        q: Vec<f64>,
        jacobian: bool,
    ) -> crate::Result<Self> {
        let table = robot.params(params);
        let p = crate::kinematics::position_checked(robot, table, &q)?;
        let sensor = crate::measure::sensor_for(robot);
        let (rot, _) = crate::kinematics::pose(robot, table, &q);
        let orientation = sensor.observes_orientation().then(|| Orientation::of(&rot));
        let markers = (robot.measurement.markers() > 0).then(|| {
            table
                .markers
                .iter()
                .map(|o| (p + rot * nalgebra::Vector3::from(*o)).into())
                .collect()
        });
        let jac = jacobian.then(|| {
            let n = robot.n_params();
            let mut jac = vec![0.0; robot.rows_per_pose() * n];
            crate::measure::JacobianEvaluator::new(robot, table).eval(&q, &mut jac);
            jac.chunks(n.max(1)).map(<[f64]>::to_vec).collect()
        });
        Ok(Self {
            robot: robot.name.clone(),
            chain: chain(robot),
            params,
            q,
            position: [p.x, p.y, p.z],
            orientation,
            markers,
            parameter_names: jac.as_ref().map(|_| robot.parameter_names()),
            jacobian: jac,
        })
    }
}

/// An orientation in the forms measurement files use.
#[derive(Clone, Debug, Serialize)]
pub struct Orientation {
    /// Rotation matrix, row-major (columns: the end frame's axes).
    pub matrix: [[f64; 3]; 3],
    /// Roll, pitch, yaw (radians): `R = Rz(yaw) · Ry(pitch) · Rx(roll)`, the
    /// `phix, phiy, phiz` of a measurement CSV.
    pub rpy: [f64; 3],
    /// Unit quaternion `[w, x, y, z]` with `w ≥ 0`.
    pub quaternion: [f64; 4],
}

impl Orientation {
    /// The forms of a rotation matrix.
    #[must_use]
    pub fn of(r: &nalgebra::Matrix3<f64>) -> Self {
        let rot = nalgebra::Rotation3::from_matrix_unchecked(*r);
        let (roll, pitch, yaw) = rot.euler_angles();
        let mut q = nalgebra::UnitQuaternion::from_rotation_matrix(&rot);
        if q.w < 0.0 {
            q = nalgebra::UnitQuaternion::new_unchecked(-q.into_inner());
        }
        Self {
            matrix: std::array::from_fn(|i| std::array::from_fn(|j| r[(i, j)])),
            rpy: [roll, pitch, yaw],
            quaternion: [q.w, q.i, q.j, q.k],
        }
    }
}

/// `pool`: the size of a lattice, and one pose of it.
#[derive(Clone, Debug, Serialize)]
pub struct LatticeReport {
    /// Robot name or description path.
    pub robot: String,
    /// Driven frames.
    pub chain: Vec<String>,
    /// Values per joint.
    pub levels: usize,
    /// Lattice poses.
    pub size: usize,
    /// Index of the pose asked for.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub index: Option<usize>,
    /// Its digits.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub digits: Option<Vec<usize>>,
    /// Its joint values.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub q: Option<Vec<f64>>,
}

impl LatticeReport {
    /// The lattice of `levels` for `robot`, and the pose of `digits` if given.
    pub fn new(robot: &Robot, levels: usize, digits: Option<Vec<usize>>) -> crate::Result<Self> {
        let lattice = crate::pool::Lattice::new(robot, levels)?;
        let index = digits.as_ref().map(|d| lattice.index_of(d)).transpose()?;
        Ok(Self {
            robot: robot.name.clone(),
            chain: chain(robot),
            levels,
            size: lattice.size(),
            q: index.map(|i| lattice.q(i)).transpose()?,
            index,
            digits,
        })
    }
}

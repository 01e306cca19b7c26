//! Typed reports of the commands: what `select`, `score`, `bound` and `gap`
//! found, with pool positions translated to stable pose ids. Each derives
//! `Serialize`; the command line prints them as text or JSON and never
//! rebuilds them. (The bound's summary is how [`crate::bound::Bound`] serialises; the paper's
//! experiment is [`crate::experiment::paper::PaperReport`].)

pub mod bag;
pub mod bench;
mod bound;
mod calibrate;
mod camera;
mod existing;
mod fk;
mod gap;
mod lattice;
pub mod measured;
mod robot;
mod score;
mod select;

pub use crate::frames::report::FramesReport;
pub use crate::how_many::{PoseCountCurve, Recommendation};
pub use crate::pool::PoolStats;
pub use crate::pool::summary::PoolSummary;
pub use bound::{BoundCommandReport, WeightedPose};
pub use calibrate::{MeasuredCalibrationReport, SimulatedCalibrationReport};
pub use camera::{
    CameraCalibrationReport, CameraDesignReport, CameraOutliers, CameraPoolInfo, CameraStartReport,
    xyz_rpy,
};
pub use existing::ExistingReport;
pub use fk::{FkReport, Orientation};
pub use gap::GapReport;
pub use lattice::LatticeReport;
pub use robot::{ContactEvaluationReport, RobotReport, RobotsReport, joint_kinds};
pub use score::ScoreReport;
pub use select::{
    PoseConfig, PredictedAfter, RefinedPoseReport, RefinementReport, SelectReport, TraceStep,
};

use crate::model::Robot;
use crate::pool::{Pool, PoolSpec};
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

//! The project's own benchmark's report ([`crate::experiment::bench`]).

use crate::bound::{BoundStatus, RelaxationSolver};
use crate::criterion::ScanTimings;
use serde::Serialize;

/// One row of the timing table.
#[derive(Clone, Debug, Serialize)]
pub struct TimingRow {
    /// What was timed.
    pub what: String,
    /// Its median, milliseconds (NaN, written as null: a ratio row).
    pub median_ms: f64,
    /// A per-item figure or a count.
    pub note: String,
}

/// The relaxation bound by one solver.
#[derive(Clone, Debug, Serialize)]
pub struct BoundRow {
    /// The solver.
    pub solver: RelaxationSolver,
    /// Wall time of the whole bound, seconds.
    pub seconds: f64,
    /// Time in the candidate-set solves, seconds.
    pub solver_seconds: f64,
    /// `ln` of the bound.
    pub ln_bound: f64,
    /// The certified gap.
    pub certificate_gap: f64,
}

/// The 10⁶-pose run.
#[derive(Clone, Debug, Serialize)]
pub struct ScaleRun {
    /// Poses in the pool.
    pub poses: usize,
    /// Forward kinematics and Jacobian, seconds.
    pub jacobian_s: f64,
    /// One EAE start, seconds.
    pub eae_s: f64,
    /// Poses chosen.
    pub n: usize,
    /// `log10 det` of the EAE design.
    pub log10_oid: f64,
    /// EAE steps.
    pub steps: usize,
    /// Peak memory after EAE, MiB.
    pub peak_mib_eae: f64,
    /// The bound for N = 30 (Newton), seconds.
    pub bound_s: f64,
    /// Its `log10`.
    pub bound_log10: f64,
    /// Its certified gap.
    pub bound_gap: f64,
    /// Its status.
    pub bound_status: BoundStatus,
    /// Peak memory after the bound, MiB.
    pub peak_mib: f64,
}

/// One robot of the side-by-side comparison.
#[derive(Clone, Debug, Serialize)]
pub struct RobotRow {
    /// Its label.
    pub robot: String,
    /// Its reference.
    pub spec: String,
    /// Unknowns.
    pub p: usize,
    /// Rows per pose.
    pub t: usize,
    /// Poses of its 5-level lattice.
    pub poses: usize,
    /// The certified bound (Newton), seconds.
    pub bound_s: f64,
    /// Its certified gap.
    pub bound_gap: f64,
    /// Its status.
    pub bound_status: BoundStatus,
    /// One EAE start, seconds.
    pub eae_s: f64,
    /// Its D-efficiency against the bound.
    pub eae_d_efficiency: f64,
    /// The default selection (2 starts, iterated local search), seconds.
    pub select_s: f64,
    /// Its local-search rounds.
    pub select_ils: usize,
    /// Its D-efficiency against the bound.
    pub select_d_efficiency: f64,
    /// Peak memory of this robot's run, MiB (`None` where the peak cannot
    /// be reset).
    pub peak_mib: Option<f64>,
}

/// The benchmark's report.
#[derive(Clone, Debug, Serialize)]
pub struct BenchReport {
    /// Threads of the pool the timings ran on.
    pub threads: usize,
    /// FK and Jacobian of the whole PUMA pool, milliseconds.
    pub jacobian_ms: f64,
    /// The same per pose, nanoseconds.
    pub jacobian_ns_per_pose: f64,
    /// The criterion's scans.
    pub scan: ScanTimings,
    /// One EAE start, milliseconds.
    pub eae_ms: f64,
    /// A Fedorov polish of an EAE design, milliseconds.
    pub polish_ms: f64,
    /// Its exchanges.
    pub polish_iterations: usize,
    /// One LM calibration from points (PUMA), milliseconds.
    pub lm_point_ms: f64,
    /// Its iterations.
    pub lm_point_iterations: usize,
    /// One LM calibration from full poses (UR5), milliseconds.
    pub lm_pose_ms: f64,
    /// Its iterations.
    pub lm_pose_iterations: usize,
    /// The bound by each solver.
    pub bounds: Vec<BoundRow>,
    /// The scale run, when asked for.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub scale: Option<ScaleRun>,
    /// Peak memory of the whole run, MiB.
    pub peak_mib: f64,
    /// The robots side by side, when asked for.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub robots: Option<Vec<RobotRow>>,
    /// Every timing as one table.
    pub table: Vec<TimingRow>,
    /// Robots of [`crate::experiment::bench::ROBOTS`] skipped (their file not found), with why.
    #[serde(skip)]
    pub skipped: Vec<String>,
    /// Repetitions per timing.
    #[serde(skip)]
    pub reps: usize,
}

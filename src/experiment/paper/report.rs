//! The experiment's typed report: what `report.json` holds, and the data the
//! figures plot.

use crate::bound::BoundStatus;
use crate::identify::{MonteCarloSummary, ParamGrid, Status};
use crate::pool::PoolSpec;
use serde::Serialize;
use std::collections::BTreeMap;

/// The settings as the report states them, with the pool size and `p`.
#[derive(Clone, Debug, Serialize)]
pub struct SettingsSummary {
    /// Lattice values per joint.
    pub levels: usize,
    /// Poses per design.
    pub n: usize,
    /// Initial EAE poses.
    pub initial: usize,
    /// Random designs.
    pub designs: usize,
    /// Multi-start starts.
    pub starts: usize,
    /// Monte-Carlo trials.
    pub trials: usize,
    /// Noise σ, metres.
    pub noise: f64,
    /// Seed.
    pub seed: u64,
    /// Poses in the pool.
    pub pool: usize,
    /// Unknowns.
    pub p: usize,
}

/// The random baseline (§V-C).
#[derive(Clone, Debug, Serialize)]
pub struct RandomSummary {
    /// `log10 OI_D` of the best random design.
    pub best_log10_oid: f64,
    /// Its OI.
    pub best_oi: f64,
    /// Median `log10 OI_D` over the random designs.
    pub median_log10_oid: f64,
    /// Pose ids of the best one.
    pub best_poses: Vec<usize>,
}

/// EAE with the paper's settings, determinant criterion.
#[derive(Clone, Debug, Serialize)]
pub struct EaeSummary {
    /// `log10 OI_D`.
    pub log10_oid: f64,
    /// OI.
    pub oi: f64,
    /// Seconds.
    pub seconds: f64,
    /// Pose ids.
    pub poses: Vec<usize>,
    /// `log10 OI_D` per step (Fig. 4).
    pub trace_log10_oid: Vec<f64>,
}

/// EAE from the same start with the eigenvalue OI.
#[derive(Clone, Debug, Serialize)]
pub struct EaeOiSummary {
    /// `log10 OI_D`.
    pub log10_oid: f64,
    /// OI.
    pub oi: f64,
    /// Whether it chose the same poses as the determinant.
    pub same_design: bool,
    /// Pose ids.
    pub poses: Vec<usize>,
}

/// Multi-start EAE with a Fedorov polish.
#[derive(Clone, Debug, Serialize)]
pub struct MultistartSummary {
    /// `log10 OI_D`.
    pub log10_oid: f64,
    /// OI.
    pub oi: f64,
    /// Seconds.
    pub seconds: f64,
    /// The winning start.
    pub best_start: usize,
}

/// A design's `log10 OI_D` alone.
#[derive(Clone, Debug, Serialize)]
pub struct Log10Oid {
    /// `log10 OI_D`.
    pub log10_oid: f64,
}

/// The Newton solver's bound, the cross-check.
#[derive(Clone, Debug, Serialize)]
pub struct NewtonCheck {
    /// `log10` of its bound.
    pub log10_bound: f64,
    /// Its bound.
    pub ln_bound: f64,
    /// Its feasible value.
    pub ln_primal: f64,
    /// Its certificate gap.
    pub certificate_gap: f64,
    /// Seconds.
    pub seconds: f64,
    /// Its status.
    pub status: BoundStatus,
}

/// The relaxation bound (Clarabel) and its Newton cross-check.
#[derive(Clone, Debug, Serialize)]
pub struct BoundSummary {
    /// `log10` of the bound.
    pub log10_bound: f64,
    /// The bound.
    pub ln_bound: f64,
    /// The feasible value.
    pub ln_primal: f64,
    /// Certificate gap.
    pub certificate_gap: f64,
    /// Poses carrying weight.
    pub support_size: usize,
    /// Seconds.
    pub seconds: f64,
    /// Status.
    pub status: BoundStatus,
    /// The Newton solver's bound.
    pub newton: NewtonCheck,
}

/// One design against the bound.
#[derive(Clone, Debug, Serialize)]
pub struct DesignRow {
    /// Its name.
    pub name: String,
    /// Pose ids.
    pub poses: Vec<usize>,
    /// `log10 OI_D` (`None` if singular).
    pub log10_oid: Option<f64>,
    /// D-efficiency against the bound.
    pub d_efficiency: f64,
}

/// Tables III and IV on the EAE design.
#[derive(Clone, Debug, Serialize)]
pub struct TablesSummary {
    /// Table III.
    pub estimate: ParamGrid,
    /// Table IV.
    pub residual: ParamGrid,
    /// Standard deviations.
    pub std: Option<ParamGrid>,
    /// LM iterations.
    pub iterations: usize,
    /// Identification status.
    pub status: Status,
}

/// One design's Monte-Carlo calibration, summarised.
#[derive(Clone, Debug, Serialize)]
pub struct MonteCarloRow {
    /// Design name.
    pub design: String,
    /// Trials.
    pub trials: usize,
    /// Trials that converged.
    pub converged: usize,
    /// Median of RMSE over predicted σ.
    pub rmse_median_over_predicted: Option<f64>,
    /// RMSE of each unknown.
    pub param_rmse: BTreeMap<String, f64>,
    /// `ln det C_emp − ln det C_pred`.
    pub ln_generalized_variance_ratio: Option<f64>,
    /// Validation RMS before calibration.
    pub validation_rms_before: f64,
    /// Median validation RMS after.
    pub validation_rms_after_median: Option<f64>,
}

/// What the figures plot (not part of `report.json`).
#[derive(Clone, Debug, Default)]
pub struct FigureData {
    /// OI of every random design (Fig. 2).
    pub random_oi: Vec<f64>,
    /// OI of the EAE design (Fig. 2's line).
    pub eae_oi: f64,
    /// OI per EAE step, determinant criterion (Fig. 5).
    pub eae_trace_oi: Vec<f64>,
    /// OI per EAE step, eigenvalue criterion (Fig. 5), when run.
    pub eae_oi_trace_oi: Option<Vec<f64>>,
    /// Lattice digits of the initial EAE poses (Fig. 3).
    pub initial_digits: Vec<Vec<usize>>,
    /// Lattice digits of the selected EAE poses (Fig. 4 A).
    pub selected_digits: Vec<Vec<usize>>,
}

/// The experiment's report: `report.json` is its serialisation.
#[derive(Clone, Debug, Serialize)]
pub struct PaperReport {
    /// Settings, pool size and `p`.
    pub settings: SettingsSummary,
    /// The pool.
    pub pool: PoolSpec,
    /// Driven frames of the robot.
    pub chain: Vec<String>,
    /// Random baseline.
    pub random: RandomSummary,
    /// EAE, determinant.
    pub eae: EaeSummary,
    /// EAE, eigenvalue OI.
    pub eae_oi: Option<EaeOiSummary>,
    /// Multi-start EAE + polish.
    pub multistart: MultistartSummary,
    /// Fedorov alone.
    pub fedorov: Log10Oid,
    /// DETMAX alone.
    pub detmax: Log10Oid,
    /// The bound.
    pub bound: BoundSummary,
    /// Every design against the bound.
    pub designs: Vec<DesignRow>,
    /// Tables III and IV.
    pub tables: TablesSummary,
    /// Monte-Carlo per design.
    pub monte_carlo: Vec<MonteCarloRow>,
    /// Wall-clock seconds.
    pub seconds: f64,
    /// The full Monte-Carlo summaries (for the Markdown report).
    #[serde(skip)]
    pub monte_carlo_full: Vec<MonteCarloSummary>,
    /// What the figures plot.
    #[serde(skip)]
    pub figures: FigureData,
}

//! The report of a calibration from measured data
//! ([`crate::experiment::measured`]): the fit, residuals, parameter
//! significance, the gross-error test, held-out splits, noise blocks and
//! the predicted error, as `calibrate --json` prints it and
//! [`crate::render::measured_text`] writes it as text.

use crate::identify::compliance::ComplianceComparison;
use crate::identify::evaluation::ModelErrors;
use crate::identify::{FixedParameter, HoldoutSettings, LossChoice, ParameterTrust, SplitResult};
use crate::lsq::outliers::{Outlier, OutlierChoice};
use serde::Serialize;

/// The report of a calibration from measurements.
#[derive(Serialize)]
pub struct MeasuredReport {
    /// The plain identification report (status, estimate, covariance, …).
    #[serde(flatten)]
    pub base: super::MeasuredCalibrationReport,
    /// The loss.
    pub loss: LossChoice,
    /// Errors of the fitted model on the data, mm and degrees.
    pub residuals: ModelErrors,
    /// Errors of the nominal model on the data, as given (with the best
    /// marker offsets for it).
    pub nominal_residuals: ModelErrors,
    /// When the data are far from the nominal model (a tracker metres away
    /// and turned): the RMS position error, mm, of the nominal geometry
    /// placed by the rigid motion of the measurement frame (and the
    /// measured point on the tip) that fits the data best — what the
    /// robot's own geometry is off by.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub nominal_placed_position_rms_mm: Option<f64>,
    /// Each parameter's estimate, change, σ, t and verdict.
    pub parameters: Vec<ParameterTrust>,
    /// Unknowns the data do not determine, fixed at nominal, with why.
    pub fixed: Vec<FixedParameter>,
    /// Poses the robust loss down-weighted: `[pose, weight]`.
    pub downweighted: Vec<(usize, f64)>,
    /// The gross-error test ([`crate::lsq::outliers`]): its choice and
    /// the poses it left out, in the order it found them.
    pub outliers: OutlierReport,
    /// Held-out validation, if asked.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub holdout: Option<HoldoutReport>,
    /// What was adapted to the data (sensor, markers, ignored columns).
    pub notes: Vec<String>,
    /// The calibrated robot's measurement frame, tool or markers and joint
    /// origins (URDF robots).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub frames: Option<crate::frames::report::FramesReport>,
    /// The fitted joint compliances.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub compliance: Option<crate::identify::compliance::ComplianceReport>,
    /// Held-out errors with and without compliances on the same splits.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub compliance_comparison: Option<ComplianceComparison>,
    /// Each residual block's σ at the fit and the weights it ended with.
    pub noise: NoiseReport,
    /// The calibrated model's own predicted error at random configurations
    /// ([`PREDICTION_CONFIGURATIONS`] within the joint limits, seed 0),
    /// from the fit's covariance at σ̂; `None` when it has none (rank
    /// deficient, no degree of freedom).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub predicted: Option<crate::how_many::PredictedErrors>,
    /// σ̂ tested against the stated noise, when one was given.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub noise_test: Option<crate::identify::variance::NoiseTest>,
    /// The orientation σ tested against the stated one, if given.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub orientation_noise_test: Option<crate::identify::variance::BlockNoiseTest>,
    /// What the user should look at: the fit is written, but something in
    /// the data or the model is not as stated.
    pub warnings: Vec<String>,
    /// A restricted fit beside the full model fitted to the same data
    /// (with a restriction only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub full_model_gain: Option<FullModelGain>,
    /// The exit status the verdict implies (0: written; 3: not converged,
    /// implausible or too few rows).
    pub exit_status: i32,
    /// The ROS 2 bag the measurements were extracted from, when they were.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bag: Option<super::bag::BagSection>,
}

/// A restricted calibration beside the full model fitted to the same data
/// ([`crate::experiment::measured::full_model`]).
#[derive(Clone, Debug, Serialize)]
pub struct FullModelGain {
    /// The restriction of the fit compared.
    pub restricted: crate::identify::restriction::Restriction,
    /// Unknowns of the full fit (the robot's, with the sensor's own).
    pub full_unknowns: usize,
    /// The full model's predicted position RMS at the random
    /// configurations (mm), from its covariance at its σ̂.
    pub full_predicted_rms_mm: f64,
    /// The full model's held-out position RMS (mm, mean over splits), when
    /// held-out validation was asked: on the same splits as the restricted
    /// fit's.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub full_held_out_rms_mm: Option<f64>,
    /// RMS distance between the two fitted models' predicted points at the
    /// same configurations (mm).
    pub models_apart_rms_mm: f64,
    /// The restricted model's predicted position RMS (mm):
    /// `√(apart² + full²)`.
    pub restricted_predicted_rms_mm: f64,
    /// What the full model gains: restricted minus full predicted RMS (mm).
    pub gain_mm: f64,
    /// With the axis relations kept: each relation and the unknowns held
    /// for it ([`crate::identify::axis_relations`]).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub relations_held: Vec<crate::identify::axis_relations::HeldRelation>,
}

/// Random configurations the calibrated model's predicted error is averaged
/// over (as `select`'s prediction).
pub const PREDICTION_CONFIGURATIONS: usize = 1000;

/// Each residual block's estimated noise and how the blocks were weighed.
#[derive(Clone, Debug, Serialize)]
pub struct NoiseReport {
    /// Estimated from the residuals, or fixed.
    pub weights: crate::identify::Weights,
    /// Metres of position a radian of orientation counted as in the final
    /// fit (full poses).
    pub orientation_scale_m_per_rad: f64,
    /// Reweighting rounds.
    pub rounds: usize,
    /// Each block's σ (its unit beside it) and redundancy.
    pub blocks: Vec<crate::identify::variance::BlockSigma>,
}

/// Held-out figures over splits.
#[derive(Serialize)]
pub struct HoldoutReport {
    /// The settings.
    pub settings: HoldoutSettings,
    /// Held-out position RMS (mm): mean and per split.
    pub position_rms_mm: Stat,
    /// Held-out orientation RMS (degrees), full poses only.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub orientation_rms_deg: Option<Stat>,
    /// The nominal model's held-out position RMS (mm), mean over splits.
    pub nominal_position_rms_mm: f64,
    /// The fitted model's position RMS on its training poses, mean.
    pub fitted_position_rms_mm: f64,
    /// The pruned model (|t| ≥ 2 kept): unknowns per split and held-out
    /// position RMS.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pruned: Option<PrunedReport>,
    /// Every split.
    pub splits: Vec<SplitResult>,
}

/// A figure over splits.
#[derive(Serialize)]
pub struct Stat {
    /// Mean over splits.
    pub mean: f64,
    /// Each split's value.
    pub per_split: Vec<f64>,
}

impl Stat {
    /// The mean of `v` and `v`.
    #[must_use]
    pub fn of(v: Vec<f64>) -> Stat {
        Stat {
            mean: v.iter().sum::<f64>() / v.len().max(1) as f64,
            per_split: v,
        }
    }
}

/// The pruned model's held-out figures.
#[derive(Serialize)]
pub struct PrunedReport {
    /// Parameters identified per split.
    pub n_params: Vec<usize>,
    /// Held-out position RMS (mm).
    pub position_rms_mm: Stat,
    /// Held-out orientation RMS (degrees).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub orientation_rms_deg: Option<Stat>,
}

/// The gross-error test's part of a report.
#[derive(Clone, Debug, Serialize)]
pub struct OutlierReport {
    /// Drop (at a rate) or keep.
    pub choice: OutlierChoice,
    /// The poses left out, in the order the test found them.
    pub left_out: Vec<Outlier>,
}

/// `evaluate`'s report: a model's errors on measured data, no fit.
#[derive(Serialize)]
pub struct EvaluationReport {
    /// The robot's name.
    pub robot: String,
    /// Its chain, base to tip.
    pub chain: Vec<String>,
    /// The measurement file.
    pub measurements: String,
    /// Poses in it.
    pub poses: usize,
    /// The model's errors, per pose and pooled (mm, degrees).
    pub residuals: ModelErrors,
    /// What was adapted to the data.
    pub notes: Vec<String>,
}

//! "How many poses do I need?": for each design size `N`, the best design
//! the selection finds, its D-efficiency against the certified bound, and
//! the position (and orientation) error the calibrated robot is predicted to
//! keep at random configurations, from the design's covariance alone (no
//! fitting).
//!
//! With noise σ per measured coordinate (metres; a full pose's orientation
//! rows carry σ after their weight, see [`crate::measure::Sensor::weights`]),
//! the estimate's covariance is `C = σ² M⁻¹`, `M = XᵀX` of the design (plus
//! `M0` of poses already measured). At a configuration `q` with Jacobian
//! rows `J_q` the expected squared position error of a measured point is
//! `tr(J_pos C J_posᵀ)` (divided by the points per pose), and of the
//! orientation `tr(J_ori C J_oriᵀ) / w²` radians² ([`predicted_errors`]).
//! The curve reports the RMS over the configurations of that error and the
//! 95th percentile of its per-configuration root.

mod camera;
mod curve;
mod predict;
mod recommend;
#[cfg(test)]
mod tests;

pub use curve::{fewest_poses, pose_count_curve, pose_count_curve_on};
pub use predict::{
    ERROR_DRAWS, ErrorRows, PredictedErrors, predicted_errors, random_configurations,
};
pub use recommend::{KNEE_GAIN, KNEE_MORE_PERCENT, Recommendation, curve_sizes, recommend};

use crate::bound::{BoundError, BoundSettings};
use crate::select::{Algorithm, CriterionKind, Settings};
use serde::Serialize;
use thiserror::Error;

/// What can go wrong computing the curve.
#[derive(Debug, Error)]
pub enum HowManyError {
    /// Bad settings or a selection error.
    #[error(transparent)]
    Input(#[from] crate::Error),
    /// The bound refused its problem.
    #[error(transparent)]
    Bound(#[from] BoundError),
}

/// Settings of [`pose_count_curve`].
#[derive(Clone, Debug)]
pub struct CurveSettings {
    /// The selection run at every `N` (its `n` and `initial` are set per
    /// point; its prior, if any, is the poses already measured).
    pub select: Settings,
    /// The criterion of the selection.
    pub criterion: CriterionKind,
    /// The selection algorithm.
    pub algorithm: Algorithm,
    /// The bound's settings.
    pub bound: BoundSettings,
    /// Sensor noise σ per measured coordinate: metres (pixels for a
    /// camera's curve, [`NoiseUnit`]).
    pub noise: f64,
    /// Random configurations the errors are predicted at (uniform within
    /// the joint limits).
    pub configurations: usize,
    /// Seed of those configurations.
    pub seed: u64,
    /// Design sizes besides the curve's own range (e.g. the `N` asked for).
    pub also: Vec<usize>,
    /// Most sizes on the curve (evenly spaced beyond this, ends kept).
    pub max_points: usize,
    /// The position error (RMS, mm) the user wants to reach: the curve
    /// then recommends the smallest size predicted to reach it, else its
    /// knee ([`recommend`]).
    pub target_mm: Option<f64>,
}

impl CurveSettings {
    /// Settings with the selection `select`, noise `noise` (metres), 1,000
    /// configurations of seed 0, at most 20 sizes.
    #[must_use]
    pub fn new(select: Settings, noise: f64) -> Self {
        CurveSettings {
            select,
            criterion: CriterionKind::Det,
            algorithm: Algorithm::Eae,
            bound: BoundSettings::default(),
            noise,
            configurations: 1000,
            seed: 0,
            also: Vec::new(),
            max_points: 20,
            target_mm: None,
        }
    }
}

/// The unit of a curve's noise σ: the unit of its sensor's rows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NoiseUnit {
    /// Metres per coordinate (points, poses, markers).
    Metres,
    /// Pixels (a camera).
    Pixels,
}

/// One design size on the curve.
#[derive(Clone, Debug, Serialize)]
pub struct CurvePoint {
    /// Poses in the design.
    pub n: usize,
    /// `ln OI_D` of the best design found.
    pub ln_oid: f64,
    /// Certified upper bound on `ln OI_D` of every `N`-pose pool design.
    pub ln_bound: f64,
    /// D-efficiency `(det M / det M*)^(1/p)`, in `[0, 1]`.
    pub d_efficiency: f64,
    /// The errors predicted after calibrating with this design.
    pub predicted: PredictedErrors,
    /// Pose ids of the design, in selection order.
    pub poses: Vec<usize>,
}

/// The "how many poses" curve.
#[derive(Clone, Debug, Serialize)]
pub struct PoseCountCurve {
    /// Unknowns.
    pub p: usize,
    /// Rows per pose (for a camera, the rank of a pose's pixel
    /// information its rows were compressed to, [`Blocks::compressed`]).
    ///
    /// [`Blocks::compressed`]: crate::blocks::Blocks::compressed
    pub rows_per_pose: usize,
    /// The fewest poses whose information can determine the unknowns
    /// (`⌈p / r⌉`, `r` a pose's rank, 1 on top of poses already measured;
    /// [`fewest_poses`]).
    pub n_min: usize,
    /// Sensor noise σ per coordinate, metres (a point, pose or marker
    /// sensor's curve).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub noise_m: Option<f64>,
    /// Pixel noise σ, px (a camera's curve).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub noise_px: Option<f64>,
    /// Random configurations the errors are predicted at.
    pub configurations: usize,
    /// Their seed.
    pub seed: u64,
    /// One point per design size, increasing `N`.
    pub points: Vec<CurvePoint>,
    /// Sizes where no identifying design was found, with why.
    pub skipped: Vec<(usize, String)>,
    /// The largest step between consecutive sizes from `n_min` to
    /// `3·n_min` (1: every size; more when the range was thinned).
    pub step: usize,
    /// The size the curve recommends, and by which rule.
    pub recommended: Option<Recommendation>,
}

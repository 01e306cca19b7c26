//! `calibrate`'s reports: the measured-data and simulated (design)
//! calibrations around the identification every calibration reports (an
//! [`Identification`](crate::identify::Identification) serialises as that).

use super::chain;
use crate::model::Robot;
use crate::pool::PoolSpec;
use serde::Serialize;

/// `calibrate --measurements`: identification from measured data.
#[derive(Clone, Debug, Serialize)]
pub struct MeasuredCalibrationReport {
    /// The identification.
    #[serde(flatten)]
    pub identification: crate::identify::Identification,
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
            identification: id.clone(),
            robot: robot.name.clone(),
            chain: chain(robot),
            measurements: file,
            poses,
            measurement: robot.measurement,
            change: id.named(&change),
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
    pub identification: crate::identify::Identification,
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
    /// Validation RMS position error of the nominal model, metres, over
    /// the coordinates of the end point the sensor reads (a height gauge's:
    /// the height error).
    pub validation_rms_before: f64,
    /// Validation RMS position error of the estimate (likewise).
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
    /// The exit status: 0 when the fit converged, else 3 (nothing written).
    pub exit_status: i32,
}

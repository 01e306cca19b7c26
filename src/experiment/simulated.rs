//! A calibration simulated at a design: the pipeline behind `calibrate
//! --design`. The design's pool is rebuilt, its poses (after any poses
//! measured before it) are measured on the real robot with noise and
//! calibrated once (Tables III/IV of the paper), the model is judged at
//! held-out poses of the pool, and with several trials the calibration is
//! repeated over noise realisations (Monte-Carlo).

use super::paper::ExperimentError;
use crate::identify::montecarlo::{
    MonteCarloSettings, MonteCarloSummary, ValidationSet, monte_carlo,
};
use crate::identify::tables::{PaperTables, paper_tables};
use crate::io::design::DesignFile;
use crate::model::Robot;
use crate::pool::{Pool, PoolSpec};
use std::time::Instant;

/// What a simulated calibration at a design found.
#[derive(Debug)]
pub struct SimulatedCalibration {
    /// The design's pool, rebuilt.
    pub pool: Pool,
    /// Joint values calibrated from: the poses measured before the design
    /// (if any), then the design's.
    pub qs: Vec<Vec<f64>>,
    /// The calibration of trial 0 of the seed, with the simulated
    /// measurements (Tables III and IV).
    pub tables: PaperTables,
    /// The held-out poses of the pool (none of the design's).
    pub validation: ValidationSet,
    /// RMS position error at the held-out poses, nominal model, metres.
    pub rms_before: f64,
    /// RMS position error at the held-out poses, calibrated model, metres.
    pub rms_after: f64,
    /// RMS orientation error before, radians (full poses only).
    pub orientation_rms_before: Option<f64>,
    /// RMS orientation error after, radians (full poses only).
    pub orientation_rms_after: Option<f64>,
    /// The Monte-Carlo summary over the settings' trials (more than one).
    pub monte_carlo: Option<MonteCarloSummary>,
    /// Seconds the Monte-Carlo took.
    pub monte_carlo_seconds: f64,
}

/// Simulates the calibration of `robot` at `design` (pool `spec`, named
/// `name` in the Monte-Carlo summary) with `settings`: noise σ, seed,
/// trials, held-out poses and the Levenberg–Marquardt settings.
pub fn calibrate_design(
    robot: &Robot,
    design: &DesignFile,
    spec: &PoolSpec,
    name: &str,
    settings: &MonteCarloSettings,
) -> Result<SimulatedCalibration, ExperimentError> {
    settings.validate()?;
    design.check_robot(robot)?;
    let pool = design.build_pool(spec, robot, &robot.nominal)?;
    // A design chosen on top of poses already measured (`select
    // --existing`) is calibrated from all of them: the existing poses, then
    // the new ones, as they will be measured.
    let new_qs = design.joint_values(robot)?;
    let qs: Vec<Vec<f64>> = match &design.existing {
        Some(e) => e.q.iter().chain(&new_qs).cloned().collect(),
        None => new_qs,
    };
    let positions = design.positions_found_in(robot, &pool)?;
    let validation = ValidationSet::sample(
        robot,
        &pool,
        &positions,
        settings.validation_poses,
        settings.seed,
    )?;
    let tables = paper_tables(robot, &qs, settings.sigma, settings.seed, &settings.lm)?;
    let table = &tables.identification.table;
    let t_mc = Instant::now();
    let mc = if settings.trials > 1 {
        Some(monte_carlo(robot, name, &qs, &validation, settings)?)
    } else {
        None
    };
    Ok(SimulatedCalibration {
        rms_before: validation.rms(robot, &robot.nominal),
        rms_after: validation.rms(robot, table),
        orientation_rms_before: validation.orientation_rms(robot, &robot.nominal),
        orientation_rms_after: validation.orientation_rms(robot, table),
        monte_carlo_seconds: t_mc.elapsed().as_secs_f64(),
        monte_carlo: mc,
        pool,
        qs,
        tables,
        validation,
    })
}

//! A calibration simulated at a design: the pipeline behind `calibrate
//! --design`. The design's pool is rebuilt, its poses (after any poses
//! measured before it) are measured on the real robot with noise and
//! calibrated once (Tables III/IV of the paper), the model is judged at
//! held-out poses of the pool in the sensor's own terms (the coordinates of
//! the tool point it reads, and the orientation if it observes one), and
//! with several trials the calibration is repeated over noise realisations
//! (Monte-Carlo).

use super::paper::ExperimentError;
use crate::identify::montecarlo::{
    MonteCarloSettings, MonteCarloSummary, ValidationSet, monte_carlo,
};
use crate::identify::tables::{PaperTables, paper_tables};
use crate::io::design::DesignFile;
use crate::model::Robot;
use crate::pool::{Pool, PoolSpec};
use crate::report::SimulatedCalibrationReport;
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
    /// RMS position error at the held-out poses, nominal model, metres,
    /// over the coordinates of the end point the sensor reads
    /// ([`ValidationSet::rms`]: a height gauge's is the height error).
    pub rms_before: f64,
    /// RMS position error at the held-out poses, calibrated model, metres
    /// (over the same coordinates).
    pub rms_after: f64,
    /// RMS orientation error before, radians (full poses only).
    pub orientation_rms_before: Option<f64>,
    /// RMS orientation error after, radians (full poses only).
    pub orientation_rms_after: Option<f64>,
    /// The Monte-Carlo summary over the settings' trials (more than one).
    pub monte_carlo: Option<MonteCarloSummary>,
    /// Seconds the Monte-Carlo took.
    pub monte_carlo_seconds: f64,
    /// The calibrated frames of a URDF robot at the estimate of trial 0,
    /// with σ from its covariance (`None` for other robots).
    pub frames: Option<(
        crate::frames::CalibratedFrames,
        crate::frames::report::FramesReport,
    )>,
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
    let id = &tables.identification;
    let table = &id.table;
    let cov = id.covariance.as_ref().map(|c| c.matrix.as_slice());
    let frames = crate::frames::calibrated(robot, table, cov, None)?;
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
        frames,
        pool,
        qs,
        tables,
        validation,
    })
}

impl SimulatedCalibration {
    /// The report of this calibration of `robot` at the design `design`,
    /// simulated with noise σ `noise` (metres) and `seed`, with the
    /// calibrated frames (URDF robots), the seconds it took and the exit
    /// status its convergence implies.
    #[must_use]
    pub fn report(
        &self,
        robot: &Robot,
        design: &str,
        noise: f64,
        seed: u64,
        elapsed_seconds: f64,
    ) -> SimulatedCalibrationReport {
        let id = &self.tables.identification;
        let truth = robot.unknown_values(&robot.real);
        let full = crate::measure::sensor_for(robot).observes_orientation();
        SimulatedCalibrationReport {
            identification: id.clone(),
            robot: robot.name.clone(),
            chain: crate::report::chain(robot),
            design: design.to_string(),
            pool: self.pool.spec.clone(),
            pool_size: self.pool.len(),
            poses: self.qs.len(),
            measurement: robot.measurement,
            noise,
            orientation_noise: full.then(|| noise / robot.orientation_scale),
            seed,
            residual: id
                .names
                .iter()
                .cloned()
                .zip(truth.iter().zip(&id.estimate).map(|(t, e)| t - e))
                .collect(),
            validation_poses: self.validation.len(),
            validation_rms_before: self.rms_before,
            validation_rms_after: self.rms_after,
            validation_orientation_rms_before: self.orientation_rms_before,
            validation_orientation_rms_after: self.orientation_rms_after,
            monte_carlo_seconds: self.monte_carlo.as_ref().map(|_| self.monte_carlo_seconds),
            monte_carlo: self.monte_carlo.clone(),
            frames: self.frames.as_ref().map(|(_, r)| r.clone()),
            elapsed_seconds,
            exit_status: if id.converged() {
                0
            } else {
                super::measured::verdict::EXIT_REFUSED
            },
        }
    }
}

/// What the report folder shows of a simulated calibration of `robot` at
/// `design`: the errors at the held-out poses before and after, the
/// parameter changes, notes on the simulation (noise σ in metres with a
/// note on where it came from, `seed`); `json` is the command's report.
#[must_use]
pub fn summary<'a>(
    robot: &'a Robot,
    sim: &'a SimulatedCalibration,
    design: &str,
    (noise, noise_note): (f64, &str),
    seed: u64,
    json: &serde_json::Value,
) -> crate::render::summary::CalibrationSummary<'a> {
    let (qs, tables, validation) = (&sim.qs, &sim.tables, &sim.validation);
    let id = &tables.identification;
    let full = crate::measure::sensor_for(robot).observes_orientation();
    let mc = &sim.monte_carlo;
    let to_mm = |v: Vec<f64>| v.into_iter().map(|x| x * 1e3).collect::<Vec<_>>();
    let to_deg = |v: Vec<f64>| v.into_iter().map(f64::to_degrees).collect::<Vec<_>>();
    let nominal = robot.unknown_values(&robot.nominal);
    let std = id.covariance.as_ref().map(|c| c.std.clone());
    let mut notes = vec![format!(
        "Simulated measurements at the design's {} poses with noise σ = {} mm per coordinate{} (seed {}); errors at {} held-out poses of the design's pool.",
        qs.len(),
        noise * 1e3,
        if noise_note.is_empty() {
            String::new()
        } else {
            format!(" ({})", noise_note.trim_start_matches(", "))
        },
        seed,
        validation.len()
    )];
    if let Some(mc) = &mc {
        notes.push(format!(
            "Monte-Carlo over {} trials: validation RMS after calibration median {} mm, predicted {} mm.",
            mc.trials,
            mc.validation_rms_after.as_ref().map_or("-".into(), |v| format!("{:.4}", v.median * 1e3)),
            mc.validation_rms_predicted.map_or("-".into(), |p| format!("{:.4}", p * 1e3))
        ));
    }
    let s = crate::render::summary::CalibrationSummary {
        robot,
        id,
        source: format!("simulated, design `{design}`"),
        what: "held-out pose",
        position_mm: (
            to_mm(validation.position_errors(robot, &robot.nominal)),
            to_mm(validation.position_errors(robot, &id.table)),
        ),
        orientation_deg: full.then(|| {
            (
                to_deg(validation.orientation_errors(robot, &robot.nominal)),
                to_deg(validation.orientation_errors(robot, &id.table)),
            )
        }),
        params: id
            .names
            .iter()
            .enumerate()
            .map(|(k, n)| {
                (
                    n.clone(),
                    id.estimate[k] - nominal[k],
                    std.as_ref().map(|s| s[k]),
                )
            })
            .collect(),
        splits: None,
        notes,
        json: json.clone(),
        poses: Some(crate::render::pages::FitPoses {
            qs: qs.clone(),
            measured: None,
            flagged: Vec::new(),
        }),
    };
    s
}

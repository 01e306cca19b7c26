//! Calibration from pixels: a camera ([`crate::measure::camera`]) sees a
//! target at measured configurations; the robot's unknowns and the
//! camera's and target's placements are fitted to the pixels.
//!
//! Two steps ([`fit_camera`]):
//! 1. **rigid start**: the 12 placement unknowns alone, the robot at its
//!    nominal parameters, by Levenberg–Marquardt from the start placements
//!    the caller gives (rough: every seen point must lie in front of the
//!    camera there; the example files' fit converges from guesses 30 cm
//!    and 20° off), or computes from the pixels ([`start`]: per-pose PnP
//!    and the closed-form hand-eye placements);
//! 2. **full fit**: the robot's unknowns ([`unknowns::camera_robot`]) and
//!    the placements together, the placements' charts re-centred on the
//!    rigid start's.
//!
//! The pixel block's σ is the variance-component estimate of one block
//! (`σ̂² = rᵀr / (n − p)`, `n` the rows of seen points, `p` the unknowns;
//! [`super::variance`]), in pixels; the covariance of the estimate is
//! `σ̂² (XᵀX)⁻¹`.

pub mod predict;
pub mod screen;
pub mod simulate;
pub mod start;
pub mod unknowns;

pub use unknowns::camera_robot;

use super::lm::{LmSettings, Solution, StopReason, levenberg_marquardt};
use super::residual::{Calibration, Residuals};
use crate::data::CameraObservations;
use crate::identify::undetermined::{
    FixedParameter, GENERIC_REASON, PIVOT_TOL, undetermined_columns,
};
use crate::measure::camera::{CameraSensor, OWN_PARAMS};
use crate::model::{ParamTable, Robot};
use nalgebra::Isometry3;

/// A camera calibration's result.
#[derive(Clone, Debug)]
pub struct CameraFit {
    /// The robot as fitted (its unknowns those of [`camera_robot`]).
    pub robot: Robot,
    /// The calibrated parameter table.
    pub table: ParamTable,
    /// The sensor, its charts centred on the rigid start.
    pub sensor: CameraSensor,
    /// The camera's placement (in the base for eye-to-hand, in the end
    /// frame for eye-in-hand).
    pub camera: Isometry3<f64>,
    /// The target's placement (in the end frame for eye-to-hand, in the
    /// base for eye-in-hand).
    pub target: Isometry3<f64>,
    /// Names of the unknowns: the robot's, then `camera_x … target_rz`.
    pub names: Vec<String>,
    /// The unknowns at the start of the full fit (after the rigid start).
    pub start: Vec<f64>,
    /// The unknowns at the estimate.
    pub estimate: Vec<f64>,
    /// Their standard deviations (metres, radians), when the estimate's
    /// information is regular.
    pub std: Option<Vec<f64>>,
    /// Their covariance `σ̂² (XᵀX)⁻¹`, row-major.
    pub covariance: Option<Vec<Vec<f64>>>,
    /// RMS pixel error of the seen points with the start placements and
    /// the nominal robot, pixels.
    pub given_rms_px: f64,
    /// RMS pixel error after the rigid start (nominal robot), pixels.
    pub rigid_rms_px: f64,
    /// RMS pixel error at the estimate, pixels.
    pub rms_px: f64,
    /// The pixel block's σ (see the module documentation), pixels.
    pub sigma_px: Option<f64>,
    /// Rows of seen points (2 per point seen).
    pub rows: usize,
    /// Degrees of freedom of `sigma_px`: rows less unknowns.
    pub redundancy: usize,
    /// Whether both steps converged and the estimate has a covariance.
    pub converged: bool,
    /// Why the full fit stopped.
    pub stop: StopReason,
    /// Its iterations.
    pub iterations: usize,
    /// The intrinsics asked to be refined that the data do not determine,
    /// held at their given values, with the reason
    /// ([`crate::identify::undetermined`]'s rule, the intrinsics pivoted
    /// after every other unknown).
    pub fixed_intrinsics: Vec<FixedParameter>,
}

impl CameraFit {
    /// The intrinsics at the estimate: refined ones when the sensor
    /// refines them ([`CameraSensor::with_intrinsics_refined`]), else the
    /// sensor's.
    #[must_use]
    pub fn intrinsics(&self) -> crate::measure::pinhole::Intrinsics {
        self.sensor
            .intrinsics_at(&self.estimate[self.robot.n_unknowns()..])
    }
}

/// Why a camera fit could not be made at all (bad input, or a start from
/// which the camera does not see what the file says it saw).
#[derive(Debug, thiserror::Error)]
pub enum CameraFitError {
    /// The start placements put seen points behind the camera.
    #[error(
        "with the start placements of the camera and the target, {behind} seen point(s) lie behind the camera (first: pose {pose}); give start placements within a few centimetres and degrees of the real ones"
    )]
    BehindCamera {
        /// Seen points behind the camera.
        behind: usize,
        /// The first pose with one (its id).
        pose: i64,
    },
    /// Fewer rows than unknowns.
    #[error("{rows} pixel rows for {p} unknowns: observe more poses")]
    TooFewRows {
        /// Rows of seen points.
        rows: usize,
        /// Unknowns.
        p: usize,
    },
    /// The robot's unknowns could not be chosen.
    #[error(transparent)]
    Robot(#[from] crate::error::Error),
}

/// The RMS over seen rows of a problem's residuals at `theta`, pixels.
fn rms_px(prob: &mut Calibration<'_>, theta: &[f64], rows: usize) -> f64 {
    let mut r = vec![0.0; prob.n_residuals()];
    prob.eval(theta, &mut r, None);
    (r.iter().map(|v| v * v).sum::<f64>() / rows.max(1) as f64).sqrt()
}

/// Seen points predicted behind the camera by `sensor` at `own` with the
/// nominal robot, and the first pose with one.
fn behind(
    robot: &Robot,
    sensor: &CameraSensor,
    own: &[f64],
    obs: &CameraObservations,
) -> Option<(usize, i64)> {
    use crate::measure::Sensor;
    let mut ev = crate::kinematics::Evaluator::new(robot, &robot.nominal);
    let mut pred = vec![0.0; sensor.value_len()];
    let (mut n, mut first) = (0, None);
    for (i, q) in obs.qs.iter().enumerate() {
        sensor.predict(&ev.end_frame(q), own, &mut pred);
        for (k, s) in obs.seen[i].iter().enumerate() {
            if s.is_some() && pred[3 * k + 2] == 0.0 {
                n += 1;
                first.get_or_insert(obs.pose_ids[i]);
            }
        }
    }
    first.map(|p| (n, p))
}

/// Calibrates `robot` (nominal parameters) from `obs` seen by `sensor`
/// whose charts are centred on the start placements `own0` stands for
/// ([`CameraSensor::start_own`]); see the module documentation.
pub fn fit_camera(
    robot: &Robot,
    sensor: &CameraSensor,
    own0: &[f64],
    obs: &CameraObservations,
    lm: &LmSettings,
) -> Result<CameraFit, CameraFitError> {
    let robot = camera_robot(robot)?;
    let rows = 2 * obs.n_seen();
    let p = robot.n_unknowns() + crate::measure::Sensor::n_own_params(sensor);
    if rows <= p {
        return Err(CameraFitError::TooFewRows { rows, p });
    }
    if let Some((behind, pose)) = behind(&robot, sensor, own0, obs) {
        return Err(CameraFitError::BehindCamera { behind, pose });
    }
    let values = obs.values();
    // 1. The placements alone, the robot nominal.
    let mut rigid_robot = robot.clone();
    rigid_robot.unknowns.clear();
    // (with the intrinsics as given).
    let own0 = &own0[..OWN_PARAMS];
    let mut rigid = Calibration::with_sensor(
        &rigid_robot,
        &robot.nominal,
        &obs.qs,
        Box::new(sensor.clone().with_intrinsics_refined(false)),
        values.clone(),
    );
    let given_rms_px = rms_px(&mut rigid, own0, rows);
    let sol0 = levenberg_marquardt(&mut rigid, own0, lm);
    let rigid_rms_px = (sol0.rss / rows as f64).sqrt();
    // 2. Everything, the charts re-centred on the rigid start (the
    // intrinsics, when refined, starting from the sensor's).
    let (sensor, own1) = sensor.recentred(&sol0.theta);
    let (sensor, own1, fixed_intrinsics) = free_intrinsics(&robot, sensor, own1, obs);
    let mut theta0 = robot.unknown_values(&robot.nominal);
    theta0.extend_from_slice(&own1);
    let mut prob = Calibration::with_sensor(
        &robot,
        &robot.nominal,
        &obs.qs,
        Box::new(sensor.clone()),
        values,
    );
    let sol = levenberg_marquardt(&mut prob, &theta0, lm);
    let mut fit = finish(
        robot,
        sensor,
        theta0,
        sol,
        sol0.stop,
        given_rms_px,
        rigid_rms_px,
        rows,
    );
    fit.fixed_intrinsics = fixed_intrinsics;
    Ok(fit)
}

/// Whether a stop means the solver found a minimum.
fn converged(s: StopReason) -> bool {
    !matches!(
        s,
        StopReason::MaxIterations | StopReason::NonFinite | StopReason::DampingLimit
    )
}

#[allow(clippy::too_many_arguments)]
fn finish(
    robot: Robot,
    sensor: CameraSensor,
    theta0: Vec<f64>,
    sol: Solution,
    rigid_stop: StopReason,
    given_rms_px: f64,
    rigid_rms_px: f64,
    rows: usize,
) -> CameraFit {
    use crate::measure::Sensor;
    let p = theta0.len();
    let redundancy = rows - p;
    let sigma_px = (sol.rss.is_finite()).then(|| (sol.rss / redundancy as f64).sqrt());
    let (covariance, std) = sol.covariance(sigma_px);
    let n_kin = robot.n_unknowns();
    let (camera, target) = sensor.placements(&sol.theta[n_kin..]);
    let mut names = robot.parameter_names();
    names.extend(sensor.own_param_names());
    CameraFit {
        table: robot.with_unknowns(&robot.nominal, &sol.theta[..n_kin]),
        converged: sol.finite && std.is_some() && converged(sol.stop) && converged(rigid_stop),
        robot,
        sensor,
        camera,
        target,
        names,
        start: theta0,
        rms_px: (sol.rss / rows as f64).sqrt(),
        estimate: sol.theta,
        std,
        covariance,
        given_rms_px,
        rigid_rms_px,
        sigma_px,
        rows,
        redundancy,
        stop: sol.stop,
        iterations: sol.iterations,
        fixed_intrinsics: Vec::new(),
    }
}

/// The sensor and own start of the full fit, with the intrinsics refined
/// only where the data determine them: the own unknowns `own1` (the
/// placements) extended by the free intrinsics' given values, the
/// Jacobian at that start checked by [`undetermined_columns`] with the
/// intrinsics pivoted last; those left undetermined are fixed at their
/// given values, each with the reason.
fn free_intrinsics(
    robot: &Robot,
    sensor: CameraSensor,
    mut own1: Vec<f64>,
    obs: &CameraObservations,
) -> (CameraSensor, Vec<f64>, Vec<FixedParameter>) {
    if !sensor.refines_intrinsics() {
        return (sensor, own1, Vec::new());
    }
    let placed = own1.len();
    own1.extend(sensor.free_intrinsic_values());
    let mut theta = robot.unknown_values(&robot.nominal);
    theta.extend_from_slice(&own1);
    let mut prob = Calibration::with_sensor(
        robot,
        &robot.nominal,
        &obs.qs,
        Box::new(sensor.clone()),
        obs.values(),
    );
    let mut r = vec![0.0; prob.n_residuals()];
    let mut x = faer::Mat::<f64>::zeros(prob.n_residuals(), prob.n_params());
    prob.eval(&theta, &mut r, Some(&mut x));
    let first = robot.n_unknowns() + placed;
    let group: Vec<usize> = (0..x.ncols()).map(|c| usize::from(c >= first)).collect();
    let out = undetermined_columns(&x, &group, PIVOT_TOL);
    if out.is_empty() {
        return (sensor, own1, Vec::new());
    }
    let mut mask = sensor.free_intrinsics().to_vec();
    let free: Vec<usize> = (0..mask.len()).filter(|&j| mask[j]).collect();
    let given = sensor.intrinsics().values();
    let names = sensor.intrinsics().names();
    let fixed = out
        .iter()
        .map(|&c| {
            let j = free[c - first];
            mask[j] = false;
            FixedParameter {
                name: format!("camera_{}", names[j]),
                value: given[j],
                reason: GENERIC_REASON.to_string(),
            }
        })
        .collect();
    let sensor = sensor.with_free_intrinsics(mask);
    own1.truncate(placed);
    own1.extend(sensor.free_intrinsic_values());
    (sensor, own1, fixed)
}

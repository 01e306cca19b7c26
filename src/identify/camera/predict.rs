//! The true error a camera fit's covariance predicts: of the moving one's
//! origin (the target's on the flange in eye-to-hand, the camera's in
//! eye-in-hand) in the fixed one's frame, the figure a frames file's
//! `measurement_frame` and `tool` give (see [`crate::frames::camera`]).

use super::CameraFit;
use crate::blocks::Blocks;
use crate::kinematics::Evaluator;
use crate::measure::camera::{CameraSensor, Mounting};
use crate::model::Robot;
use nalgebra::{Isometry3, Point3, Rotation3, UnitQuaternion, Vector3};
use rayon::prelude::*;

/// The moving one's origin in the fixed one's frame at the fit's
/// parameters `theta` (robot unknowns, then own unknowns in the fit's
/// charts) and configuration `q`, metres.
#[must_use]
pub fn probe(fit: &CameraFit, theta: &[f64], q: &[f64]) -> Vector3<f64> {
    probe_of(&fit.robot, &fit.sensor, theta, q)
}

/// [`probe`] for `robot` (its unknowns, then `sensor`'s own, in
/// `theta`; other parameters nominal).
#[must_use]
pub fn probe_of(robot: &Robot, sensor: &CameraSensor, theta: &[f64], q: &[f64]) -> Vector3<f64> {
    let n = robot.n_unknowns();
    let table = robot.with_unknowns(&robot.nominal, &theta[..n]);
    let (cam, tgt) = sensor.placements(&theta[n..]);
    let e = Evaluator::new(robot, &table).end_frame(q);
    let end = Isometry3::from_parts(
        e.position.into(),
        UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(e.rotation)),
    );
    let p = match sensor.mounting() {
        Mounting::EyeToHand => cam.inverse() * end * tgt,
        Mounting::EyeInHand => tgt.inverse() * end * cam,
    };
    (p * Point3::origin()).coords
}

/// `√(mean_q tr(J_q C J_qᵀ))`, metres: the RMS error of [`probe`] at the
/// configurations `qs` that the fit's covariance `C` predicts, `J_q` the
/// probe's derivative in the parameters by central differences (step
/// 1e-7 m or rad: the probe is smooth and O(1); truncation ~1e-14, rounding
/// ~1e-9 relative). `None` without a covariance.
#[must_use]
pub fn predicted_error(fit: &CameraFit, qs: &[Vec<f64>]) -> Option<f64> {
    let cov = fit.covariance.as_ref()?;
    Some(predicted_error_of(
        &fit.robot,
        &fit.sensor,
        &fit.estimate,
        cov,
        qs,
    ))
}

/// [`predicted_error`] for `robot` and `sensor` at parameters `theta` with
/// covariance `cov` (row-major, `theta.len()` square).
#[must_use]
pub fn predicted_error_of(
    robot: &Robot,
    sensor: &CameraSensor,
    theta: &[f64],
    cov: &[Vec<f64>],
    qs: &[Vec<f64>],
) -> f64 {
    let jac = probe_jacobians(robot, sensor, theta, qs);
    let p = theta.len();
    let mut sum = 0.0;
    for k in 0..jac.n_poses() {
        let b = jac.block(k);
        for i in 0..p {
            for j in 0..p {
                let dot: f64 = (0..3).map(|r| b[(r, i)] * b[(r, j)]).sum();
                sum += dot * cov[i][j];
            }
        }
    }
    (sum / qs.len().max(1) as f64).sqrt()
}

/// The true error per unit of noise σ that a design whose information
/// (at σ = 1) is `info` predicts: [`predicted_error_of`] with the
/// covariance `info⁻¹` (inverted on its equilibrated form,
/// [`crate::linalg::chol::spd_inverse`]), metres per unit of σ; `None`
/// for a singular `info`.
#[must_use]
pub fn predicted_error_of_information(
    robot: &Robot,
    sensor: &CameraSensor,
    theta: &[f64],
    info: faer::MatRef<'_, f64>,
    qs: &[Vec<f64>],
) -> Option<f64> {
    let inv = crate::linalg::chol::spd_inverse(info)?;
    let cov: Vec<Vec<f64>> = (0..inv.nrows())
        .map(|i| (0..inv.ncols()).map(|j| inv[(i, j)]).collect())
        .collect();
    Some(predicted_error_of(robot, sensor, theta, &cov, qs))
}

/// The derivative of [`probe_of`] in the parameters `theta` at each of
/// `qs`: one 3-row block a configuration (metres per metre or radian), by
/// central differences (step 1e-7 m or rad: the probe is smooth and O(1);
/// truncation ~1e-14, rounding ~1e-9 relative). The rows a camera's
/// predicted errors are carried to ([`crate::how_many::ErrorRows`]).
#[must_use]
pub fn probe_jacobians(
    robot: &Robot,
    sensor: &CameraSensor,
    theta: &[f64],
    qs: &[Vec<f64>],
) -> Blocks {
    let p = theta.len();
    let h = 1e-7;
    let rows: Vec<f64> = qs
        .par_iter()
        .flat_map_iter(|q| {
            let cols: Vec<Vector3<f64>> = (0..p)
                .map(|k| {
                    let (mut a, mut b) = (theta.to_vec(), theta.to_vec());
                    a[k] += h;
                    b[k] -= h;
                    (probe_of(robot, sensor, &a, q) - probe_of(robot, sensor, &b, q)) / (2.0 * h)
                })
                .collect();
            let row_major: Vec<f64> = (0..3)
                .flat_map(|r| cols.iter().map(move |c| c[r]))
                .collect();
            row_major
        })
        .collect();
    Blocks::from_row_major(&rows, 3, p.max(1))
}

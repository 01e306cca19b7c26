//! Configurations that put the tool point at a point: damped least squares
//! on the tool point's position within the joint limits (less a margin),
//! and contacts simulated with it (a known robot, points and noise).

use super::group_means;
use crate::data::ContactFile;
use crate::error::Error;
use crate::identify::simulate::fill_standard_normal;
use crate::kinematics::{Evaluator, Motion};
use crate::measure::contact::ContactSensor;
use crate::model::{ParamTable, Robot};
use nalgebra::{Matrix3, Vector3};
use rand::Rng;

/// Most damped least-squares steps of a projection.
pub const PROJECT_STEPS: usize = 200;
/// Damping `λ` of a step (metres): steps near a singularity stay short.
pub const PROJECT_DAMPING: f64 = 1e-3;

/// Moves `q0` by damped least squares, `Δq = Jᵀ (J Jᵀ + λ² I)⁻¹ e`, until
/// the tool point `p + R o` of `robot` with `table` is within `tol` metres
/// of `target`, each step clamped into the joint limits shrunk by `margin`
/// (radians or metres). `None` when it does not get there in
/// [`PROJECT_STEPS`] steps.
#[must_use]
#[allow(clippy::too_many_arguments)]
pub fn project_to_point(
    robot: &Robot,
    table: &ParamTable,
    offset: &[f64; 3],
    target: &Vector3<f64>,
    q0: &[f64],
    margin: f64,
    tol: f64,
) -> Option<Vec<f64>> {
    let dof = robot.dof();
    let mut ev = Evaluator::new(robot, table);
    let mut joints = vec![Motion::default(); dof];
    let mut q = q0.to_vec();
    let clamp = |q: &mut Vec<f64>| {
        for (v, &[lo, hi]) in q.iter_mut().zip(&robot.limits) {
            *v = v.clamp(lo + margin, (hi - margin).max(lo + margin));
        }
    };
    clamp(&mut q);
    for _ in 0..PROJECT_STEPS {
        let end = ev.joint_motions(&q, &mut joints);
        let lever = end.rotation * Vector3::from_column_slice(offset);
        let e = target - ContactSensor::tool_point(&end, offset);
        if e.norm() <= tol {
            return Some(q);
        }
        let cols: Vec<Vector3<f64>> = joints.iter().map(|m| m.lin + m.ang.cross(&lever)).collect();
        let mut jjt = Matrix3::identity() * PROJECT_DAMPING * PROJECT_DAMPING;
        for c in &cols {
            jjt += c * c.transpose();
        }
        let y = jjt.lu().solve(&e)?;
        for (v, c) in q.iter_mut().zip(&cols) {
            *v += c.dot(&y);
        }
        clamp(&mut q);
    }
    None
}

/// Contacts simulated from `seeds`: each point is the mean of its rows'
/// tool points under `truth` (tool offset `offset`), and each row is moved
/// by [`project_to_point`] (from its own joint values, within the limits
/// less `margin`) to touch its point plus N(0, σ²) noise per coordinate
/// (σ = `sigma`, metres; the tool's seat is repeatable to σ). Errors name a
/// row that cannot be projected.
pub fn simulate_contacts<R: Rng + ?Sized>(
    robot: &Robot,
    truth: &ParamTable,
    offset: &[f64; 3],
    seeds: &ContactFile,
    sigma: f64,
    margin: f64,
    rng: &mut R,
) -> crate::error::Result<(ContactFile, Vec<Vector3<f64>>)> {
    let pts = super::tool_points(robot, truth, offset, &seeds.qs);
    let points = group_means(&pts, &seeds.groups, seeds.points.len());
    let mut out = seeds.clone();
    let mut noise = [0.0; 3];
    for (i, q) in out.qs.iter_mut().enumerate() {
        fill_standard_normal(rng, &mut noise);
        let target = points[seeds.groups[i]] + sigma * Vector3::from(noise);
        // 1e-9 m: four orders below any noise a test uses.
        *q = project_to_point(robot, truth, offset, &target, q, margin, 1e-9).ok_or_else(
            || {
                Error::Invalid(format!(
                    "{} line {}: the tool cannot reach point '{}' from this configuration within the limits",
                    seeds.origin, seeds.lines[i], seeds.points[seeds.groups[i]]
                ))
            },
        )?;
    }
    Ok((out, points))
}

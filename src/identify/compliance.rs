//! Joint compliance as unknowns: each revolute chain joint deflects under
//! its gravity torque, `Δq_i = c_i·τ_i(q)` ([`crate::model::gravity`],
//! [`crate::model::Symbol::C`]). Which joints get a compliance (those whose
//! torque varies over the data: a constant torque's deflection is a zero
//! offset, which the joint's γ already is), and what a fit says of them:
//! `c` with σ and t, the stiffness `k = −1/c` and the largest deflection.

use super::Identification;
use crate::data::Measurements;
use crate::kinematics::{Evaluator, Motion};
use crate::model::gravity::GravityModel;
use crate::model::{JointKind, ParamId, ParamTable, Robot, Symbol};
use serde::Serialize;
use std::sync::Arc;

/// A joint whose gravity torque varies over the data by less than this
/// fraction of the largest variation of any joint gets no compliance: its
/// deflection would be a zero offset (a constant torque), or need a
/// compliance a hundred times the others' to be seen at all — a column the
/// fit cannot tell from noise, along which Levenberg–Marquardt wanders
/// (a Panda's hand joint, 1e-3 N·m, sent its compliance to 1e13).
pub const CONSTANT_TORQUE: f64 = 1e-2;

/// A revolute joint that gets no compliance, and why.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct NoCompliance {
    /// The joint.
    pub joint: String,
    /// Why.
    pub reason: String,
}

/// The robot with a gravity model and a compliance unknown for every
/// revolute joint whose gravity torque varies over `meas`; the joints left
/// without one, with the reason.
#[must_use]
pub fn with_compliance(
    robot: &Robot,
    gravity: &Arc<GravityModel>,
    meas: &Measurements,
) -> (Robot, Vec<NoCompliance>) {
    with_compliance_at(robot, gravity, meas.qs())
}

/// [`with_compliance`] over joint configurations `qs` (a pool's: the
/// design Jacobian then has the compliance columns).
#[must_use]
pub fn with_compliance_at(
    robot: &Robot,
    gravity: &Arc<GravityModel>,
    qs: &[Vec<f64>],
) -> (Robot, Vec<NoCompliance>) {
    let mut r = robot.clone();
    r.gravity = Some(Arc::clone(gravity));
    let (lo, hi) = torque_ranges(gravity, qs);
    let scale = lo.iter().zip(&hi).fold(0.0f64, |m, (a, b)| m.max(b - a));
    let names = joint_names(robot);
    let mut skipped = Vec::new();
    for (f, frame) in robot.frames.iter().enumerate() {
        let Some(j) = frame.joint else { continue };
        if frame.joint_kind != JointKind::Revolute {
            continue;
        }
        let (a, b) = (lo[j], hi[j]);
        if b - a > CONSTANT_TORQUE * scale {
            r.unknowns.push(ParamId {
                frame: f,
                symbol: Symbol::C,
            });
            continue;
        }
        let reason = if a.abs().max(b.abs()) <= 1e-9 * scale.max(1.0) {
            "no gravity torque in these data (a vertical axis, or nothing carried)".to_string()
        } else {
            format!(
                "gravity torque nearly constant in these data ({a:.4} … {b:.4} N·m, a variation under {:.0} % of the largest joint's): a compliance would be a zero offset the data cannot tell apart",
                CONSTANT_TORQUE * 100.0
            )
        };
        skipped.push(NoCompliance {
            joint: names[j].clone(),
            reason,
        });
    }
    r.unknowns.sort();
    (r, skipped)
}

/// The robot with a gravity model and a compliance unknown for each joint
/// of `joints` (by name, as a design file stores them); a name that is not
/// a revolute joint of the chain is an error.
pub fn with_compliant_joints(
    robot: &Robot,
    gravity: &Arc<GravityModel>,
    joints: &[String],
) -> crate::Result<Robot> {
    let mut r = robot.clone();
    r.gravity = Some(Arc::clone(gravity));
    let names = joint_names(robot);
    for name in joints {
        let frame = names.iter().position(|n| n == name).and_then(|j| {
            r.frames
                .iter()
                .position(|f| f.joint == Some(j))
                .filter(|&f| r.is_compliant_frame(f))
        });
        let Some(frame) = frame else {
            return Err(crate::Error::Invalid(format!(
                "compliance of '{name}': not a revolute joint of the chain ({})",
                names.join(", ")
            )));
        };
        r.unknowns.push(ParamId {
            frame,
            symbol: Symbol::C,
        });
    }
    r.unknowns.sort();
    r.unknowns.dedup();
    r.validate()?;
    Ok(r)
}

/// Smallest and largest gravity torque of each joint over `qs`.
fn torque_ranges(g: &GravityModel, qs: &[Vec<f64>]) -> (Vec<f64>, Vec<f64>) {
    let n = g.dof();
    let (mut lo, mut hi) = (vec![f64::INFINITY; n], vec![f64::NEG_INFINITY; n]);
    let mut tau = vec![0.0; n];
    for q in qs {
        g.torques(q, &mut tau);
        for j in 0..n {
            lo[j] = lo[j].min(tau[j]);
            hi[j] = hi[j].max(tau[j]);
        }
    }
    if qs.is_empty() {
        return (vec![0.0; n], vec![0.0; n]);
    }
    (lo, hi)
}

/// The names of a robot's joints: the URDF's, or `q1`, `q2`, ….
fn joint_names(robot: &Robot) -> Vec<String> {
    match &robot.source {
        Some(s) => s.driven_names(),
        None => (1..=robot.dof()).map(|j| format!("q{j}")).collect(),
    }
}

/// One fitted compliance.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct ComplianceEstimate {
    /// The parameter's name (`c_<frame>`).
    pub name: String,
    /// The joint.
    pub joint: String,
    /// Compliance, rad per N·m.
    pub c: f64,
    /// Its standard deviation.
    pub std: Option<f64>,
    /// `c / σ`.
    pub t: Option<f64>,
    /// Implied stiffness `k = −1/c`, N·m/rad (`None` for c = 0).
    pub stiffness_nm_per_rad: Option<f64>,
    /// Smallest and largest gravity torque over the data, N·m.
    pub torque_range_nm: [f64; 2],
    /// Largest |c·τ| over the data, milliradians.
    pub max_deflection_mrad: f64,
    /// Largest displacement of the end point that deflection causes alone,
    /// mm.
    pub max_deflection_tool_mm: f64,
}

/// What a fit with compliances found.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct ComplianceReport {
    /// Each fitted compliance.
    pub estimates: Vec<ComplianceEstimate>,
    /// Revolute joints without one, and why.
    pub without: Vec<NoCompliance>,
    /// Largest displacement of the end point by all deflections together
    /// over the data, mm.
    pub max_tool_deflection_mm: f64,
}

/// The compliances of fit `id` of `robot` (with its gravity model) on
/// `meas`, with `without` the joints [`with_compliance`] left out.
#[must_use]
pub fn report(
    robot: &Robot,
    id: &Identification,
    meas: &Measurements,
    without: Vec<NoCompliance>,
) -> ComplianceReport {
    let names = joint_names(robot);
    let table = &id.table;
    let rigid = ParamTable {
        compliance: Vec::new(),
        ..table.clone()
    };
    let mut ev = Evaluator::new(robot, table);
    let mut ev_rigid = Evaluator::new(robot, &rigid);
    let mut joints = vec![Motion::default(); robot.dof()];
    let mut estimates = Vec::new();
    let mut worst_tool = 0.0f64;
    let ids: Vec<(usize, ParamId)> = robot
        .unknowns
        .iter()
        .enumerate()
        .filter(|(_, u)| u.symbol == Symbol::C)
        .map(|(k, &u)| (k, u))
        .collect();
    let mut per = vec![([f64::INFINITY, f64::NEG_INFINITY], 0.0f64, 0.0f64); ids.len()];
    for q in meas.qs() {
        let p = ev.joint_motions(q, &mut joints).position;
        let p0 = ev_rigid.end_frame(q).position;
        worst_tool = worst_tool.max((p - p0).norm());
        let tau = ev.torques();
        for (slot, (_, u)) in per.iter_mut().zip(&ids) {
            let j = robot.frames[u.frame].joint.unwrap_or(0);
            let d = (table.get(*u) * tau[j]).abs();
            slot.0[0] = slot.0[0].min(tau[j]);
            slot.0[1] = slot.0[1].max(tau[j]);
            slot.1 = slot.1.max(d);
            slot.2 = slot.2.max(d * joints[j].lin.norm());
        }
    }
    for ((k, u), (range, mrad, mm)) in ids.iter().zip(per) {
        let c = id.estimate[*k];
        let std = id.covariance.as_ref().map(|cv| cv.std[*k]);
        estimates.push(ComplianceEstimate {
            name: robot.param_name(*u),
            joint: names[robot.frames[u.frame].joint.unwrap_or(0)].clone(),
            c,
            std,
            t: std.filter(|s| *s > 0.0).map(|s| c / s),
            stiffness_nm_per_rad: (c != 0.0).then(|| -1.0 / c),
            torque_range_nm: range,
            max_deflection_mrad: mrad * 1e3,
            max_deflection_tool_mm: mm * 1e3,
        });
    }
    ComplianceReport {
        estimates,
        without,
        max_tool_deflection_mm: worst_tool * 1e3,
    }
}
/// Held-out errors of the geometric model and of the model with
/// compliances, fitted on the same splits.
#[derive(Clone, Debug, serde::Serialize)]
pub struct ComplianceComparison {
    /// Held-out position RMS (mm) per split, geometric model.
    pub geometric_position_rms_mm: Vec<f64>,
    /// Held-out position RMS (mm) per split, with compliances.
    pub compliant_position_rms_mm: Vec<f64>,
    /// Fitted (training) position RMS (mm) per split, geometric.
    pub geometric_fitted_rms_mm: Vec<f64>,
    /// Fitted (training) position RMS (mm) per split, with compliances.
    pub compliant_fitted_rms_mm: Vec<f64>,
    /// Held-out orientation RMS (degrees) per split, geometric (full poses).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub geometric_orientation_rms_deg: Option<Vec<f64>>,
    /// The same with compliances.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub compliant_orientation_rms_deg: Option<Vec<f64>>,
    /// Splits where the model with compliances predicts better.
    pub splits_better: usize,
    /// The verdict.
    pub verdict: String,
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len().max(1) as f64
}

/// The comparison of two held-out runs on the same splits.
#[must_use]
pub fn compare(
    geometric: &[super::SplitResult],
    compliant: &[super::SplitResult],
) -> ComplianceComparison {
    let pos = |s: &[super::SplitResult]| s.iter().map(|x| x.held_out.position_rms_mm).collect();
    let fit = |s: &[super::SplitResult]| s.iter().map(|x| x.fitted.position_rms_mm).collect();
    let ori = |s: &[super::SplitResult]| -> Option<Vec<f64>> {
        s.iter().map(|x| x.held_out.orientation_rms_deg).collect()
    };
    let (g, c): (Vec<f64>, Vec<f64>) = (pos(geometric), pos(compliant));
    let better = g.iter().zip(&c).filter(|(a, b)| b < a).count();
    let verdict = if mean(&c) < mean(&g) && 2 * better > g.len() {
        format!(
            "compliance helps: held-out {:.3} → {:.3} mm, better on {better} of {} splits",
            mean(&g),
            mean(&c),
            g.len()
        )
    } else {
        format!(
            "compliance does not help: held-out {:.3} mm geometric, {:.3} mm with compliance, better on {better} of {} splits",
            mean(&g),
            mean(&c),
            g.len()
        )
    };
    ComplianceComparison {
        geometric_fitted_rms_mm: fit(geometric),
        compliant_fitted_rms_mm: fit(compliant),
        geometric_orientation_rms_deg: ori(geometric),
        compliant_orientation_rms_deg: ori(compliant),
        geometric_position_rms_mm: g,
        compliant_position_rms_mm: c,
        splits_better: better,
        verdict,
    }
}

//! A robot described (`robots`): its chain, joints with kinds and limits,
//! parameter tables and unknowns.

use crate::model::{Frame, JointKind, MeasurementKind, Robot};
use serde::Serialize;

/// A robot as `robots --json` describes it.
#[derive(Clone, Debug, Serialize)]
pub struct RobotReport {
    /// Its name.
    pub name: String,
    /// Its links from base to tip.
    pub chain: Vec<String>,
    /// Its joints' names.
    pub joint_names: Vec<String>,
    /// Joints.
    pub dof: usize,
    /// Its frames (conventions, joints).
    pub frames: Vec<Frame>,
    /// The "real" parameter rows (a URDF's: made up, see the text).
    pub real: Vec<[f64; 5]>,
    /// The nominal parameter rows.
    pub nominal: Vec<[f64; 5]>,
    /// The unknowns' names.
    pub unknowns: Vec<String>,
    /// Revolute joints' limits in degrees; prismatic ones have none (null):
    /// see `limits`.
    pub limits_deg: Vec<Option<[f64; 2]>>,
    /// The limits in radians or metres.
    pub limits: Vec<[f64; 2]>,
    /// Each joint's kind.
    pub joint_kinds: Vec<JointKind>,
    /// What the sensor measures.
    pub measurement: MeasurementKind,
}

/// `robots --json`: the robots described.
#[derive(Clone, Debug, Serialize)]
pub struct RobotsReport {
    /// Each robot.
    pub robots: Vec<RobotReport>,
}

/// The kind of each joint, by joint number.
#[must_use]
pub fn joint_kinds(r: &Robot) -> Vec<JointKind> {
    let mut k = vec![JointKind::Revolute; r.dof()];
    for f in &r.frames {
        if let Some(j) = f.joint {
            k[j] = f.joint_kind;
        }
    }
    k
}

impl RobotReport {
    /// The description of `r`.
    #[must_use]
    pub fn of(r: &Robot) -> Self {
        let kinds = joint_kinds(r);
        Self {
            name: r.name.clone(),
            chain: super::chain(r),
            joint_names: crate::units::joint_names(r),
            dof: r.dof(),
            frames: r.frames.clone(),
            real: r.real.rows.clone(),
            nominal: r.nominal.rows.clone(),
            unknowns: r.parameter_names(),
            limits_deg: kinds
                .iter()
                .zip(&r.limits)
                .map(|(k, l)| match k {
                    JointKind::Revolute => Some([l[0].to_degrees(), l[1].to_degrees()]),
                    JointKind::Prismatic => None,
                })
                .collect(),
            limits: r.limits.clone(),
            joint_kinds: kinds,
            measurement: r.measurement,
        }
    }
}

/// `evaluate` on a contact file: a model's consistency (no fit).
#[derive(Clone, Debug, Serialize)]
pub struct ContactEvaluationReport {
    /// The robot's name.
    pub robot: String,
    /// Its links from base to tip.
    pub chain: Vec<String>,
    /// The contact file.
    pub measurements: String,
    /// Its rows.
    pub rows: usize,
    /// The evaluation.
    pub contacts: crate::identify::contact::evaluate::ContactEvaluation,
}

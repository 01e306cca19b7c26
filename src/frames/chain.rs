//! The two views of one chain at `q = 0`: the URDF's joint frames (from the
//! file's origins, [`UrdfSource`]) and the DH/Hayati model's joint frames
//! (from a parameter table, [`crate::kinematics::joint_chain`]), and the
//! constant map between them.

use super::FramesError;
use crate::kinematics::joint_chain;
use crate::model::source::UrdfSource;
use crate::model::{JointKind, ParamTable, Robot};
use nalgebra::{Isometry3, Vector3};

/// The URDF's frames at `q = 0`, in the measurement frame of the source's
/// mount.
#[derive(Clone, Debug)]
pub struct UrdfFrames {
    /// Each driven joint's frame (before its motion).
    pub joint: Vec<Isometry3<f64>>,
    /// Each driven joint's own `<origin>`.
    pub origin: Vec<Isometry3<f64>>,
    /// Each driven joint's unit axis, in its own frame.
    pub axis: Vec<Vector3<f64>>,
    /// Each driven joint's kind.
    pub kind: Vec<JointKind>,
    /// Each driven joint's name.
    pub name: Vec<String>,
    /// The fixed transform before each driven joint's origin: from the
    /// previous driven joint's frame (the base link for the first) through
    /// the fixed and locked joints between.
    pub before: Vec<Isometry3<f64>>,
    /// From the last driven joint's frame to the tip link.
    pub to_tip: Isometry3<f64>,
}

impl UrdfFrames {
    /// Walks the source's chain.
    #[must_use]
    pub fn of(src: &UrdfSource) -> UrdfFrames {
        let mut f = UrdfFrames {
            joint: Vec::new(),
            origin: Vec::new(),
            axis: Vec::new(),
            kind: Vec::new(),
            name: Vec::new(),
            before: Vec::new(),
            to_tip: Isometry3::identity(),
        };
        let mut at = src.mount;
        let mut since = Isometry3::identity();
        for j in &src.joints {
            match j.kind {
                Some(kind) if j.is_driven() => {
                    at *= j.origin;
                    f.before.push(since);
                    f.joint.push(at);
                    f.origin.push(j.origin);
                    f.axis.push(j.axis.normalize());
                    f.kind.push(kind);
                    f.name.push(j.name.clone());
                    since = Isometry3::identity();
                }
                _ => {
                    let t = j.fixed_part();
                    at *= t;
                    since *= t;
                }
            }
        }
        f.to_tip = since;
        // The first joint's `before` starts at the base link, not at the
        // measurement frame: the mount is the measurement frame itself.
        f
    }

    /// Driven joints.
    #[must_use]
    pub fn len(&self) -> usize {
        self.joint.len()
    }

    /// Whether there is no driven joint.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.joint.is_empty()
    }
}

/// The DH/Hayati model's frames at `q = 0` for a table, in the measurement
/// frame: each joint's frame (its z axis the joint axis) and the end frame.
#[derive(Clone, Debug)]
pub struct ModelFrames {
    /// Each joint's frame.
    pub joint: Vec<Isometry3<f64>>,
    /// The measured frame.
    pub end: Isometry3<f64>,
}

impl ModelFrames {
    /// The frames of `robot` at `table`.
    #[must_use]
    pub fn of(robot: &Robot, table: &ParamTable) -> ModelFrames {
        let ch = joint_chain(robot, table);
        let mut at = Isometry3::identity();
        let joint = ch
            .placements
            .iter()
            .map(|p| {
                at *= p;
                at
            })
            .collect();
        ModelFrames {
            joint,
            end: at * ch.tool,
        }
    }
}

/// For each joint, the constant `C_k = Z_k⁻¹ J_k` from the model's joint
/// frame `Z_k` to the URDF's `J_k` at the nominal table. `C_k` turns the
/// URDF axis into z and moves only along it, so `J_k R_a(q) = Z_k R_z(q)
/// C_k` for every `q`: the URDF frame of a calibrated model is `Z_k C_k`.
/// Errors when a joint's frames do not share the axis line (a model that
/// is not the source's import).
pub fn model_to_urdf(
    robot: &Robot,
    urdf: &UrdfFrames,
) -> std::result::Result<Vec<Isometry3<f64>>, FramesError> {
    let model = ModelFrames::of(robot, &robot.nominal);
    if model.joint.len() != urdf.len() {
        return Err(FramesError::NotTheSource(format!(
            "the model has {} joints, the URDF chain {}",
            model.joint.len(),
            urdf.len()
        )));
    }
    let scale = 1.0
        + urdf
            .joint
            .iter()
            .map(|j| j.translation.vector.norm())
            .fold(0.0, f64::max);
    let mut out = Vec::with_capacity(urdf.len());
    for k in 0..urdf.len() {
        let c = model.joint[k].inverse() * urdf.joint[k];
        let axis_err = (c.rotation * urdf.axis[k] - Vector3::z()).norm();
        let t = c.translation.vector;
        let off_axis = (t.x * t.x + t.y * t.y).sqrt();
        // Both are rounding of a chain of ~10 products of unit-size values:
        // 1e-9 (relative to the chain's size) is a million times that.
        if axis_err > 1e-9 || off_axis > 1e-9 * scale {
            return Err(FramesError::NotTheSource(format!(
                "joint '{}': the model's joint axis is not the URDF's ({axis_err:.1e} rad, {off_axis:.1e} m apart)",
                urdf.name[k]
            )));
        }
        out.push(c);
    }
    Ok(out)
}

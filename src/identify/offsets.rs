//! Offsets-only calibration: the unknowns that are the joints' zero
//! offsets, the measurement frame and the tool — what a driver's
//! joint-offset parameters (ros2_control `calibration_offset`-style) and a
//! frames file can hold — and nothing of the links between the joints.
//!
//! In a chain's frames (DH `Rz(θ) Tz(d) Tx(a) Rx(α)`, Hayati `Rz(θ) Tx(a)
//! Rx(α) Ry(β)`, with `θ = q + γ` for a revolute joint and `d = q + d₀` for
//! a prismatic one) the parameters split by where they sit:
//!
//! * a joint frame's `γ` (revolute) or `d` (prismatic) is **the joint's
//!   zero offset** (joint 1's is also the measurement frame's turn about
//!   its axis: the data see them together, and it is given to the joint);
//! * every frame before the first joint, and the first joint frame's other
//!   `γ` or `d` (a slide along, or a turn about, joint 1's axis), place the
//!   chain in the sensor's frame: **the measurement frame**;
//! * the last joint frame's parameters after its motion, and every frame
//!   after it, ride on the last link: **the tool**;
//! * everything else is link geometry: held at the model's value.

use crate::model::{JointKind, ParamId, Robot, Symbol};

/// What a parameter of the chain is, for an offsets-only calibration.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Role {
    /// Part of the measurement frame (the chain's placement in the sensor's frame).
    MeasurementFrame,
    /// A joint's zero offset.
    JointOffset,
    /// Part of the tool (the measured frame or point on the last link).
    Tool,
    /// Link geometry between two joints.
    Link,
}

/// The role of parameter `id` of `robot` (see the module documentation).
#[must_use]
pub fn role(robot: &Robot, id: ParamId) -> Role {
    let driven: Vec<usize> = (0..robot.frames.len())
        .filter(|&f| robot.frames[f].joint.is_some())
        .collect();
    let (Some(&first), Some(&last)) = (driven.first(), driven.last()) else {
        return Role::MeasurementFrame;
    };
    if id.symbol == Symbol::C {
        return Role::Link;
    }
    let offset = |f: usize| match robot.frames[f].joint_kind {
        JointKind::Revolute => id.symbol == Symbol::Gamma,
        JointKind::Prismatic => id.symbol == Symbol::D,
    };
    match id.frame {
        f if f < first => Role::MeasurementFrame,
        f if robot.frames[f].joint.is_some() && offset(f) => Role::JointOffset,
        // A turn about or slide along joint 1's axis: the placement's.
        f if f == first && matches!(id.symbol, Symbol::Gamma | Symbol::D) => Role::MeasurementFrame,
        f if f >= last => Role::Tool,
        _ => Role::Link,
    }
}

/// The names of `robot`'s unknowns that an offsets-only calibration holds
/// at the model's values: its link geometry.
#[must_use]
pub fn link_unknowns(robot: &Robot) -> Vec<String> {
    robot
        .unknowns
        .iter()
        .filter(|&&u| role(robot, u) == Role::Link)
        .map(|&u| robot.param_name(u))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ur5() -> Robot {
        crate::io::load_robot(concat!(env!("CARGO_MANIFEST_DIR"), "/fixtures/ur5.urdf")).unwrap()
    }

    #[test]
    fn a_ur5s_unknowns_split_into_frame_offsets_tool_and_links() {
        let r = ur5();
        let names = |want: Role| -> Vec<String> {
            r.unknowns
                .iter()
                .filter(|&&u| role(&r, u) == want)
                .map(|&u| r.param_name(u))
                .collect()
        };
        // Joint 1's offset is the measurement frame's turn about its axis:
        // the data cannot tell them apart, and the split gives it to the
        // joint (γ of the first joint frame).
        assert_eq!(
            names(Role::MeasurementFrame),
            [
                "gamma_base",
                "alpha_base",
                "a_base",
                "d_base",
                "d_shoulder_pan_joint"
            ]
        );
        assert_eq!(
            names(Role::JointOffset),
            [
                "gamma_shoulder_pan_joint",
                "gamma_shoulder_lift_joint",
                "gamma_elbow_joint",
                "gamma_wrist_1_joint",
                "gamma_wrist_2_joint",
                "gamma_wrist_3_joint"
            ]
        );
        assert_eq!(names(Role::Tool), ["alpha_wrist_3_joint", "d_tool"]);
        let links = link_unknowns(&r);
        assert_eq!(links.len(), r.unknowns.len() - 13, "{links:?}");
        assert!(links.iter().all(|n| !n.starts_with("gamma_")), "{links:?}");
    }
}

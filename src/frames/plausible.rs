//! Whether calibrated frames are a calibration of the robot
//! ([`crate::identify::plausible`] in the URDF's terms): each joint's
//! origin as the file gives it, moved by at most a fraction of its link.

use super::CalibratedFrames;
use crate::identify::plausible::{check_offsets, moved_too_far};
use crate::model::{JointKind, ParamTable, Robot};

/// Why the fit `table` of `robot` is not a calibration of it, or `None`:
/// with its URDF `frames`, a joint origin moved by more than
/// [`crate::identify::plausible::LINK_FRACTION`] of its link (at least a tenth of the reach; a
/// prismatic joint's slide along its axis is its zero, not a move), or the
/// tool or a marker beyond the reach; without them, the table's rows
/// ([`crate::identify::plausible::implausible`]).
#[must_use]
pub fn implausible(
    robot: &Robot,
    table: &ParamTable,
    frames: Option<&CalibratedFrames>,
) -> Option<String> {
    let Some(f) = frames else {
        return crate::identify::plausible::implausible(robot, table);
    };
    let reach = crate::units::reach(robot);
    for j in &f.joints {
        let mut d = j.calibrated.translation.vector - j.nominal.translation.vector;
        if j.kind == JointKind::Prismatic {
            let axis = j.nominal.rotation * j.axis;
            d -= axis * d.dot(&axis);
        }
        let link = j.nominal.translation.vector.norm();
        if let Some(why) = moved_too_far(&format!("joint '{}'", j.name), d.norm(), link, reach) {
            return Some(why);
        }
    }
    let tool = [f.tool.translation.vector.into()];
    let markers: Vec<[f64; 3]> = f.markers.iter().map(|m| (*m).into()).collect();
    check_offsets("the tool", &tool, reach).or_else(|| check_offsets("marker", &markers, reach))
}

//! Whether a fitted model is a calibration of the robot or a different
//! robot: a converged fit that moves a joint's origin by more than a
//! fraction of its link ([`LINK_FRACTION`]), or puts the tool or a marker
//! beyond the robot's reach, fitted the wrong data (another unit, another
//! robot) and is refused like a fit that did not converge.

use crate::model::{ParamTable, Robot};

/// How far (a fraction of the link's nominal length, or of a tenth of the
/// reach for a short link) a fit may move a joint's origin: calibration
/// corrects millimetres on links of decimetres.
pub const LINK_FRACTION: f64 = 0.1;

/// The length of a frame row's translation (its `a` and `d`).
fn length(row: &[f64; 5]) -> f64 {
    row[2].hypot(row[3])
}

/// Why a move of `moved` metres of `what`'s origin, on a link `link`
/// metres long, is too far ([`LINK_FRACTION`] of the link, at least a tenth
/// of `reach`), or `None`.
#[must_use]
pub fn moved_too_far(what: &str, moved: f64, link: f64, reach: f64) -> Option<String> {
    let limit = LINK_FRACTION * link.max(0.1 * reach);
    (moved > limit).then(|| {
        format!(
            "the fit moved the origin of {what} by {:.1} mm, more than {} % of its link ({:.1} mm): not a calibration of this robot (the data's unit or robot?)",
            moved * 1e3,
            LINK_FRACTION * 100.0,
            link * 1e3
        )
    })
}

/// Why `fitted` is not a calibration of `robot` (whose nominal table is the
/// start), or `None`: a joint frame's origin moved by more than
/// [`LINK_FRACTION`] of its link (at least a tenth of the reach), or the
/// tool (the frames after the last joint) or a marker beyond the reach.
/// The frames before the first joint (where the sensor sees the base) may
/// be anywhere.
#[must_use]
pub fn implausible(robot: &Robot, fitted: &ParamTable) -> Option<String> {
    let reach = crate::units::reach(robot);
    let nominal = &robot.nominal;
    let first = robot.frames.iter().position(|f| f.joint.is_some())?;
    let last = robot.frames.iter().rposition(|f| f.joint.is_some())?;
    for k in first..=last {
        let (Some(n), Some(f)) = (nominal.rows.get(k), fitted.rows.get(k)) else {
            continue;
        };
        let prismatic = robot.frames[k].joint.is_some()
            && robot.frames[k].joint_kind == crate::model::JointKind::Prismatic;
        // A prismatic joint's d is its travel's zero: only a moves the origin.
        let moved = if prismatic {
            (f[2] - n[2]).abs()
        } else {
            (f[2] - n[2]).hypot(f[3] - n[3])
        };
        let label = format!("frame '{}'", robot.frames[k].label);
        if let Some(why) = moved_too_far(&label, moved, length(n), reach) {
            return Some(why);
        }
    }
    let tool: f64 = fitted.rows[last + 1..].iter().map(length).sum();
    if tool > reach {
        return Some(format!(
            "the fit put the tool {:.3} m from the last joint, beyond the robot's reach of {reach:.3} m: not a calibration of this robot (the data's unit or robot?)",
            tool
        ));
    }
    check_offsets("marker", &fitted.markers, reach)
}

/// Why a fitted offset (a marker's, the tool's) is beyond `reach`, or
/// `None`.
#[must_use]
pub fn check_offsets(what: &str, offsets: &[[f64; 3]], reach: f64) -> Option<String> {
    offsets.iter().enumerate().find_map(|(k, o)| {
        let norm = (o[0] * o[0] + o[1] * o[1] + o[2] * o[2]).sqrt();
        let which = if offsets.len() > 1 {
            format!("{what} {}", k + 1)
        } else {
            what.to_string()
        };
        (norm > reach).then(|| {
            format!(
                "the fit put {which} {norm:.3} m from the tip link, beyond the robot's reach of {reach:.3} m: not a calibration of this robot (the data's unit or robot?)"
            )
        })
    })
}

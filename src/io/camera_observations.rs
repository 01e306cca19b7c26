//! A camera's observations: a CSV with one row per detected target point,
//!
//! ```text
//! pose,shoulder_pan_joint,…,wrist_3_joint,feature,u,v
//! 0,0.1,-1.2,…,0.3,0,412.31,288.02
//! 0,0.1,-1.2,…,0.3,1,447.90,287.45
//! ```
//!
//! `pose` an integer naming the configuration (rows of one pose need not
//! be adjacent; poses keep the order they first appear in), one column per
//! joint named as in the URDF (radians and metres unless the units say
//! otherwise, checked against the joints' limits by
//! [`crate::units::joint_values_to_model_units`], which says when a column
//! looks like degrees), `feature` a target point's id, `u, v` its pixel
//! (OpenCV's convention, `(0, 0)` the centre of the top-left pixel). A
//! point not detected at a pose simply has no row.
//!
//! Refused, naming the file, line and column: a missing column, a feature
//! id the target does not have, a feature given twice at one pose, a pixel
//! outside the image, joint values that differ between the rows of one
//! pose, and a pose with fewer than 4 points (a camera cannot place the
//! target from fewer).

use super::camera_target::Target;
use super::table::{Table, parse_csv};
use crate::error::{Error, Result};
use crate::measure::pinhole::Intrinsics;
use crate::model::Robot;
use crate::units::{JointSource, Units, joint_names, joint_values_to_model_units};
use std::path::Path;

use crate::data::CameraObservations;
pub use crate::measure::camera::MIN_POINTS_PER_POSE;

/// Reads an observation file for `robot`, `target` and the camera
/// `intrinsics`, joint values in `units`.
pub fn read_observations(
    path: &Path,
    robot: &Robot,
    target: &Target,
    intrinsics: &Intrinsics,
    units: Units,
) -> Result<CameraObservations> {
    let text = super::read::read_text(path)?;
    parse_observations(
        &text,
        &path.display().to_string(),
        robot,
        target,
        intrinsics,
        units,
    )
}

/// The columns of an observation file: pose, joints, feature, u, v.
struct Columns {
    pose: usize,
    joints: Vec<usize>,
    feature: usize,
    u: usize,
    v: usize,
}

fn columns(t: &Table, robot: &Robot) -> std::result::Result<Columns, String> {
    let find = |name: &str, what: &str| {
        t.column(name).ok_or_else(|| {
            format!(
                "line 1: no '{name}' column ({what}); the header needs pose, the joints ({}), feature, u, v",
                joint_names(robot).join(", ")
            )
        })
    };
    let joints = joint_names(robot)
        .iter()
        .map(|j| find(j, "a joint of the robot, named as in the URDF"))
        .collect::<std::result::Result<Vec<_>, _>>()?;
    Ok(Columns {
        pose: find("pose", "the configuration's id")?,
        joints,
        feature: find("feature", "the target point's id")?,
        u: find("u", "pixel column")?,
        v: find("v", "pixel row")?,
    })
}

/// Parses an observation file's `text` (from `origin`, for messages).
pub fn parse_observations(
    text: &str,
    origin: &str,
    robot: &Robot,
    target: &Target,
    intrinsics: &Intrinsics,
    units: Units,
) -> Result<CameraObservations> {
    let err = |message: String| Error::Parse {
        path: origin.to_string(),
        message,
    };
    let t = parse_csv(text, origin)?;
    let c = columns(&t, robot).map_err(err)?;
    check_locked(&t, robot, units).map_err(err)?;
    let mut obs = CameraObservations {
        origin: origin.to_string(),
        pose_ids: Vec::new(),
        qs: Vec::new(),
        seen: Vec::new(),
    };
    // The line of each pose's first row, for the joint-unit check.
    let mut first_lines = Vec::new();
    let mut lines_of: Vec<Vec<usize>> = Vec::new();
    for (row, &line) in t.rows.iter().zip(&t.lines) {
        let cell = |k: usize, what: &str| -> Result<f64> {
            let v = row[k];
            if v.is_finite() {
                Ok(v)
            } else {
                Err(err(format!(
                    "line {line}, column {} ('{}'): {v} is not a finite number ({what})",
                    k + 1,
                    t.columns[k]
                )))
            }
        };
        let id = integer(cell(c.pose, "a pose id")?, line, c.pose, &t).map_err(err)?;
        let q: Vec<f64> = c
            .joints
            .iter()
            .map(|&k| cell(k, "a joint value"))
            .collect::<Result<_>>()?;
        let p = match obs.pose_ids.iter().position(|&i| i == id) {
            Some(p) => p,
            None => {
                obs.pose_ids.push(id);
                obs.qs.push(q.clone());
                obs.seen.push(vec![None; target.points.len()]);
                first_lines.push(line);
                lines_of.push(Vec::new());
                obs.pose_ids.len() - 1
            }
        };
        lines_of[p].push(line);
        if let Some(j) = (0..q.len()).find(|&j| q[j] != obs.qs[p][j]) {
            return Err(err(format!(
                "line {line}, column {} ('{}'): pose {id} has joint value {} here but {} on line {}; the rows of one pose share its joint values",
                c.joints[j] + 1,
                t.columns[c.joints[j]],
                q[j],
                obs.qs[p][j],
                first_lines[p]
            )));
        }
        let fid = integer(cell(c.feature, "a feature id")?, line, c.feature, &t).map_err(err)?;
        let k = target.index_of(fid).ok_or_else(|| {
            err(format!(
                "line {line}, column {} ('feature'): the target has no point {fid} (its ids: {})",
                c.feature + 1,
                id_range(target)
            ))
        })?;
        let px = [cell(c.u, "a pixel")?, cell(c.v, "a pixel")?];
        if !intrinsics.inside(px, 0.0) {
            let col = if px[0] < -0.5 || px[0] > f64::from(intrinsics.width) - 0.5 {
                c.u
            } else {
                c.v
            };
            return Err(err(format!(
                "line {line}, column {} ('{}'): pixel ({}, {}) lies outside the {}×{} image",
                col + 1,
                t.columns[col],
                px[0],
                px[1],
                intrinsics.width,
                intrinsics.height
            )));
        }
        if obs.seen[p][k].replace(px).is_some() {
            return Err(err(format!(
                "line {line}, column {} ('feature'): point {fid} given twice for pose {id}",
                c.feature + 1
            )));
        }
    }
    check_poses(&obs, &lines_of).map_err(err)?;
    let rows: Vec<String> = first_lines.iter().map(|l| format!("line {l}")).collect();
    let cols: Vec<String> = c.joints.iter().map(|&k| t.columns[k].clone()).collect();
    let source = JointSource {
        file: origin,
        rows: &rows,
        columns: &cols,
    };
    joint_values_to_model_units(robot, units, &source, &mut obs.qs)?;
    Ok(obs)
}

/// A locked joint moves less than this between the value it is locked at
/// and the file's (radians or metres): a value printed with six decimals
/// is within 5e-7 of what was meant, a joint that moved by a tenth of a
/// degree is 1.7e-3 off.
const LOCKED_TOL: f64 = 1e-3;

/// Refuses a column of a joint `robot` holds locked whose values the file
/// says moved: the camera saw the robot in another configuration than the
/// model would place it in (issue 49: a UR5 fitted so misplaced its
/// pixels by 145 px). Names the line, the column and both values.
fn check_locked(t: &Table, robot: &Robot, units: Units) -> std::result::Result<(), String> {
    let Some(src) = robot.source.as_ref() else {
        return Ok(());
    };
    for j in &src.joints {
        let (Some(at), Some(k)) = (j.locked, t.column(&j.name)) else {
            continue;
        };
        let scale = match j.kind {
            Some(crate::model::JointKind::Prismatic) => units.length.to_m(),
            _ => units.angle.to_rad(),
        };
        for (row, line) in t.rows.iter().zip(&t.lines) {
            let v = row[k] * scale;
            if v.is_finite() && (v - at).abs() > LOCKED_TOL {
                return Err(format!(
                    "line {line}, column {} ('{}'): the joint is locked at {at} but this row has it at {v}: the data say it moved; unlock it (or give its column the locked value)",
                    k + 1,
                    j.name
                ));
            }
        }
    }
    Ok(())
}

/// Refuses a file without rows and a pose that sees fewer than
/// [`MIN_POINTS_PER_POSE`] points (`lines_of`: each pose's lines).
fn check_poses(
    obs: &CameraObservations,
    lines_of: &[Vec<usize>],
) -> std::result::Result<(), String> {
    if obs.pose_ids.is_empty() {
        return Err("no observations: the file has a header but no rows".into());
    }
    for (p, s) in obs.seen.iter().enumerate() {
        let n = s.iter().filter(|x| x.is_some()).count();
        if n < MIN_POINTS_PER_POSE {
            return Err(format!(
                "pose {} (line {}): {n} point(s) seen; a pose needs at least {MIN_POINTS_PER_POSE} (remove it or add its detections)",
                obs.pose_ids[p],
                lines_of[p]
                    .iter()
                    .map(usize::to_string)
                    .collect::<Vec<_>>()
                    .join(", ")
            ));
        }
    }
    Ok(())
}

/// The value of an id column, which must be an integer.
fn integer(v: f64, line: usize, k: usize, t: &Table) -> std::result::Result<i64, String> {
    if v.fract() == 0.0 && v.abs() < 9e15 {
        Ok(v as i64)
    } else {
        Err(format!(
            "line {line}, column {} ('{}'): {v} is not an integer id",
            k + 1,
            t.columns[k]
        ))
    }
}

/// The target's ids, for messages: `0–53` for consecutive ids, else a list.
fn id_range(t: &Target) -> String {
    let (lo, hi) = (t.ids.iter().min(), t.ids.iter().max());
    match (lo, hi) {
        (Some(&lo), Some(&hi)) if (hi - lo) as usize + 1 == t.ids.len() => format!("{lo}–{hi}"),
        _ => t
            .ids
            .iter()
            .map(i64::to_string)
            .collect::<Vec<_>>()
            .join(", "),
    }
}

/// The CSV text of `obs` (see the module documentation), joint values in
/// radians and metres, pixels with 6 decimals (a micro-pixel: far below any
/// detector's noise).
#[must_use]
pub fn observations_csv(obs: &CameraObservations, robot: &Robot, target: &Target) -> String {
    use std::fmt::Write as _;
    let mut s = format!("pose,{},feature,u,v\n", joint_names(robot).join(","));
    for ((id, q), seen) in obs.pose_ids.iter().zip(&obs.qs).zip(&obs.seen) {
        let joints: Vec<String> = q.iter().map(|v| format!("{v:.17}")).collect();
        for (k, px) in seen.iter().enumerate() {
            if let Some([u, v]) = px {
                let _ = writeln!(
                    s,
                    "{id},{},{},{u:.6},{v:.6}",
                    joints.join(","),
                    target.ids[k]
                );
            }
        }
    }
    s
}

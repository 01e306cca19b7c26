//! Whether a calibration from measurements may be written, decided once in
//! the library so that every front end refuses the same fits with the same
//! message: a fit that did not converge, or that converged to another robot
//! ([`crate::frames::plausible::implausible`]: a joint origin moved by more
//! than a fraction of its link, a tool beyond the reach), or that had fewer
//! measurement rows than the robot has unknowns (it converged only by
//! holding most of them at nominal), is refused, with too few rows named
//! first as the cause.

use crate::frames::CalibratedFrames;
use crate::identify::Identification;
use crate::model::Robot;
use serde::Serialize;

/// The exit status of a calibration that ran but must not be written.
pub const EXIT_REFUSED: i32 = 3;

/// What may be done with a calibration's result.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Verdict {
    /// Converged and plausible: the calibrated robot may be written.
    Calibrated,
    /// Not to be written (exit status [`EXIT_REFUSED`]), and why.
    Refused {
        /// The reason, with its cause first when there is one.
        reason: String,
    },
}

impl Verdict {
    /// 0, or [`EXIT_REFUSED`].
    #[must_use]
    pub fn exit_status(&self) -> i32 {
        match self {
            Verdict::Calibrated => 0,
            Verdict::Refused { .. } => EXIT_REFUSED,
        }
    }

    /// The reason of a refusal.
    #[must_use]
    pub fn refusal(&self) -> Option<&str> {
        match self {
            Verdict::Calibrated => None,
            Verdict::Refused { reason } => Some(reason),
        }
    }
}

/// The verdict on the fit `id` of `robot` (its calibrated `frames` for a
/// URDF robot) from `poses` poses with `unknowns` unknowns (estimated and
/// fixed as undetermined).
#[must_use]
pub fn verdict(
    robot: &Robot,
    id: &Identification,
    frames: Option<&CalibratedFrames>,
    poses: usize,
    unknowns: usize,
) -> Verdict {
    let few = too_few_rows(robot, poses, unknowns);
    let why = if !id.converged() {
        Some(unconverged(id))
    } else if few.is_some() {
        // Converged on the few unknowns the rows determine (the others held
        // at nominal): a fit of the data, not a calibration of the robot.
        Some(format!(
            "the fit converged on {} of the {unknowns} unknowns, the rest held at nominal: not a calibration of the robot",
            id.names.len()
        ))
    } else {
        crate::frames::plausible::implausible(robot, &id.table, frames)
    };
    match why {
        None => Verdict::Calibrated,
        Some(why) => Verdict::Refused {
            reason: match few {
                Some(cause) => format!("{cause}\n  {why}"),
                None => why,
            },
        },
    }
}

/// Why a fit that did not converge is refused.
#[must_use]
pub fn unconverged(id: &Identification) -> String {
    let mut why = format!(
        "identification ended {:?} ({:?}) after {} iterations",
        id.status, id.stop, id.iterations
    );
    if !id.unidentifiable.is_empty() {
        why += &format!(
            "; not determined by the data: {}",
            id.unidentifiable.join(", ")
        );
    }
    why
}

/// `N poses give R measurement rows for U unknowns: too few …` when the
/// data have fewer rows than the fit had unknowns.
#[must_use]
pub fn too_few_rows(robot: &Robot, poses: usize, unknowns: usize) -> Option<String> {
    let per_pose = robot.rows_per_pose().max(1);
    let rows = poses * per_pose;
    (rows < unknowns).then(|| {
        format!(
            "{poses} poses give {rows} measurement rows for {unknowns} unknowns: too few to determine the model (at least {} poses)",
            unknowns.div_ceil(per_pose)
        )
    })
}

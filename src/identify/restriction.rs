//! Which of the robot's unknowns a fit estimates: all of them, only what a
//! driver's joint offsets and a frames file hold
//! ([`super::offsets`]), or only what keeps the nominal axis relations
//! closed-form inverse kinematics rely on ([`super::axis_relations`]).

use crate::model::Robot;
use serde::Serialize;

/// The unknowns a fit estimates.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Restriction {
    /// The chain's complete, minimal set.
    #[default]
    All,
    /// Joint zero offsets, the measurement frame and the tool.
    Offsets,
    /// Every unknown except those that would change a nominal parallel,
    /// perpendicular or intersecting relation of consecutive joint axes.
    KeepAxisRelations,
}

impl Restriction {
    /// The names of `robot`'s unknowns held at their nominal values.
    ///
    /// # Errors
    /// Keeping the axis relations of a nominal model that has none (no
    /// consecutive axes exactly parallel, perpendicular or intersecting:
    /// a model whose origins a factory calibration already moved) is
    /// refused: it would hold nothing and keep nothing.
    pub fn held(self, robot: &Robot) -> crate::Result<Vec<String>> {
        Ok(match self {
            Restriction::All => Vec::new(),
            Restriction::Offsets => super::offsets::link_unknowns(robot),
            Restriction::KeepAxisRelations => {
                if super::axis_relations::held_relations(robot).is_empty() {
                    return Err(crate::Error::Invalid(format!(
                        "keeping the axis relations of '{}': its nominal model has no consecutive joint axes exactly parallel, perpendicular or intersecting (to 1e-9 rad and 1e-9 of its reach), so there is nothing to keep; a kinematics file from a factory calibration moves every origin: start from the design description",
                        robot.name
                    )));
                }
                super::axis_relations::held_unknowns(robot)
            }
        })
    }

    /// What the restricted model is, for a report's line ("offsets only").
    #[must_use]
    pub fn describe(self) -> &'static str {
        match self {
            Restriction::All => "every unknown",
            Restriction::Offsets => "offsets only",
            Restriction::KeepAxisRelations => "axis relations kept",
        }
    }

    /// `robot` with the held unknowns removed from its unknowns: the model a
    /// design for the restricted fit is chosen for.
    ///
    /// # Errors
    /// As [`Restriction::held`].
    pub fn apply(self, robot: &Robot) -> crate::Result<Robot> {
        let held = self.held(robot)?;
        let mut r = robot.clone();
        r.unknowns.retain(|&u| !held.contains(&robot.param_name(u)));
        Ok(r)
    }
}

/// `fix` with the unknowns `restriction` holds added (each once, the
/// user's first, in order).
///
/// # Errors
/// As [`Restriction::held`].
pub fn with_held(
    fix: &[String],
    restriction: Restriction,
    robot: &Robot,
) -> crate::Result<Vec<String>> {
    let mut out = fix.to_vec();
    for n in restriction.held(robot)? {
        if !out.contains(&n) {
            out.push(n);
        }
    }
    Ok(out)
}

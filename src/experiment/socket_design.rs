//! The configurations to record for sockets at given positions
//! (`select --point`, calibration from contacts) as one pipeline: the
//! question asked of the robot's sensor (contacts replace a sensor that
//! measures the chain's tip as one point and nothing else), the known
//! distances between sockets resolved by name and checked against the
//! robot's reach, and the design
//! ([`crate::select::contact::socket_design`]).
//!
//! Errors name the offending value (a distance by its position among those
//! given, a point by name); the front end adds its flag names.

use crate::data::NamedDistance;
use crate::identify::contact::lengths::distance_beyond_reach;
use crate::measure::contact::KnownDistance;
use crate::measure::{Sensor, ToolRecord, sensor_for};
use crate::model::{ParamTable, Robot};

pub use crate::identify::contact::select::Socket;
pub use crate::select::contact::ContactSearch;
pub use crate::select::contact::socket_design::{SocketDesign, SocketDesignSettings};

/// Joint-space samples projected onto each socket when none are asked for.
pub const DEFAULT_SAMPLES: usize = 1000;

/// An input of a socket design that cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum SocketDesignError {
    /// The robot's sensor measures more than the chain's tip as one point
    /// (a pose, markers with their own offsets): contacts touch with the
    /// tip itself.
    #[error("the tool point of {robot} is a measured point")]
    ToolNotAPoint {
        /// The robot's name.
        robot: String,
    },
    /// A known distance names a point that is no socket.
    #[error("no point is named '{name}' (the points: {})", points.join(", "))]
    UnknownPoint {
        /// The distance's position among those given.
        distance: usize,
        /// The name given.
        name: String,
        /// The sockets' names.
        points: Vec<String>,
    },
    /// A known distance between a socket and itself, or not a finite
    /// length > 0.
    #[error("a distance needs two different points and a finite length > 0 (metres)")]
    BadDistance {
        /// The distance's position among those given.
        distance: usize,
    },
    /// A known distance beyond twice the robot's reach
    /// ([`distance_beyond_reach`]).
    #[error("{why}")]
    BeyondReach {
        /// The distance's position among those given.
        distance: usize,
        /// Why, naming the points and lengths.
        why: String,
    },
    /// The design refused its inputs (no socket reached, too few
    /// configurations, …).
    #[error(transparent)]
    Design(#[from] crate::identify::IdentifyError),
}

/// Whether contacts can stand in for `robot`'s sensor: it measures the
/// chain's tip as one point, with no orientation and no unknowns of its
/// own (asked of the sensor, [`Sensor::tool_record`]).
#[must_use]
pub fn measures_the_tip(robot: &Robot) -> bool {
    let s: Box<dyn Sensor> = sensor_for(robot);
    s.tool_record() == ToolRecord::Point && s.points_per_pose() == 1 && s.n_own_params() == 0
}

/// The `given` distances between `sockets`, as indices into them, each
/// checked (two different sockets, a finite length > 0, within twice the
/// robot's reach).
pub fn known_distances(
    robot: &Robot,
    sockets: &[Socket],
    given: &[NamedDistance],
) -> Result<Vec<KnownDistance>, SocketDesignError> {
    let names: Vec<String> = sockets.iter().map(|s| s.name.clone()).collect();
    given
        .iter()
        .enumerate()
        .map(|(k, d)| {
            let index = |n: &str| {
                names
                    .iter()
                    .position(|m| m == n)
                    .ok_or_else(|| SocketDesignError::UnknownPoint {
                        distance: k,
                        name: n.to_string(),
                        points: names.clone(),
                    })
            };
            let (a, b) = (index(&d.a)?, index(&d.b)?);
            if a == b || !(d.metres.is_finite() && d.metres > 0.0) {
                return Err(SocketDesignError::BadDistance { distance: k });
            }
            if let Some(why) = distance_beyond_reach(robot, &d.a, &d.b, d.metres) {
                return Err(SocketDesignError::BeyondReach { distance: k, why });
            }
            Ok(KnownDistance {
                a,
                b,
                metres: d.metres,
            })
        })
        .collect()
}

/// Chooses and judges `settings.n` configurations touching `sockets` with
/// the `given` distances between them (any `settings.distances` are
/// replaced by them) for `robot` at `table`.
pub fn design(
    robot: &Robot,
    table: &ParamTable,
    sockets: &[Socket],
    given: &[NamedDistance],
    settings: SocketDesignSettings,
) -> Result<SocketDesign, SocketDesignError> {
    if !measures_the_tip(robot) {
        return Err(SocketDesignError::ToolNotAPoint {
            robot: robot.name.clone(),
        });
    }
    let settings = SocketDesignSettings {
        distances: known_distances(robot, sockets, given)?,
        ..settings
    };
    Ok(crate::select::contact::socket_design::design_for_sockets(
        robot, table, sockets, &settings,
    )?)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The sensor question agrees with the robot's measurement: a point
    /// robot's tip is touched, a pose robot's and a marker robot's are not.
    #[test]
    fn only_a_point_sensor_measures_the_tip() {
        use crate::model::MeasurementKind;
        let point = Robot::ur5();
        assert!(measures_the_tip(&point));
        for kind in [MeasurementKind::Pose, MeasurementKind::Markers(2)] {
            let mut r = point.clone();
            r.measurement = kind;
            assert!(!measures_the_tip(&r), "{kind:?}");
        }
    }
}

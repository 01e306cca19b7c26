//! Known lengths checked against the robot before a contact fit: a known
//! distance or a plane's offset far beyond the robot's reach (a length in
//! millimetres given as metres) is refused, and so is a distance far
//! shorter than the one the nominal model puts between the two points.

use super::{group_means, tool_points};
use crate::data::ContactFile;
use crate::error::{Compact, Error, Result};
use crate::measure::contact::{KnownDistance, PlaneKind};
use crate::model::Robot;

/// How many times the robot's reach ([`crate::units::reach`]) a known
/// distance or a plane's distance from the base may be: two points the
/// tool touches are at most twice the reach (and the tool) apart.
pub const LENGTH_REACH_FACTOR: f64 = 2.0;

/// How many times shorter than the nominal model's distance between the
/// two points' contacts a known distance may be (the nominal model errs by
/// millimetres, not a hundredfold).
pub const SHORT_FACTOR: f64 = 100.0;

/// ` (in millimetres: X m)` when `metres` read as millimetres is within
/// `limit`.
fn as_mm(metres: f64, limit: f64) -> String {
    if metres.abs() * 1e-3 <= limit {
        format!(
            "; it looks like millimetres (= {} m)",
            Compact(metres * 1e-3)
        )
    } else {
        String::new()
    }
}

/// How a known distance is named in messages: `distance A,B=METRES`.
fn distance_label(a: &str, b: &str, metres: f64) -> String {
    format!("distance {a},{b}={}", Compact(metres))
}

/// Why a known distance `metres` between points `a` and `b` cannot be,
/// or `None`: beyond [`LENGTH_REACH_FACTOR`] × the robot's reach
/// ([`crate::units::reach`]), no two points the tool touches are so far
/// apart (a length in millimetres given as metres is named as such). The
/// check of a contact fit's distances ([`check_distances`]) and of a
/// socket design's (`select --point-distance`) alike.
#[must_use]
pub fn distance_beyond_reach(robot: &Robot, a: &str, b: &str, metres: f64) -> Option<String> {
    let reach = crate::units::reach(robot);
    let limit = LENGTH_REACH_FACTOR * reach;
    (metres > limit).then(|| {
        format!(
            "{}: {} m is more than {LENGTH_REACH_FACTOR} × the robot's reach ({reach:.3} m){}",
            distance_label(a, b, metres),
            Compact(metres),
            as_mm(metres, limit)
        )
    })
}

/// Refuses a known distance beyond [`LENGTH_REACH_FACTOR`] × the reach, or
/// [`SHORT_FACTOR`] times shorter than the nominal model's distance between
/// the two points' mean contacts (with no tool offset), naming it.
pub fn check_distances(robot: &Robot, file: &ContactFile, known: &[KnownDistance]) -> Result<()> {
    let means = group_means(
        &tool_points(robot, &robot.nominal, &[0.0; 3], &file.qs),
        &file.groups,
        file.points.len() + file.planes.len(),
    );
    for d in known {
        let label = distance_label(&file.points[d.a], &file.points[d.b], d.metres);
        if let Some(why) =
            distance_beyond_reach(robot, &file.points[d.a], &file.points[d.b], d.metres)
        {
            return Err(Error::Invalid(why));
        }
        let nominal = (means[d.a] - means[d.b]).norm();
        if d.metres * SHORT_FACTOR < nominal {
            return Err(Error::Invalid(format!(
                "{label}: {} m is more than {SHORT_FACTOR} times shorter than the nominal model's {nominal:.3} m between the two points' contacts",
                Compact(d.metres)
            )));
        }
    }
    Ok(())
}

/// Refuses a known plane farther from the base than
/// [`LENGTH_REACH_FACTOR`] × the reach (the robot cannot touch it), naming
/// it.
pub fn check_planes(robot: &Robot, file: &ContactFile) -> Result<()> {
    let reach = crate::units::reach(robot);
    let limit = LENGTH_REACH_FACTOR * reach;
    for p in &file.planes {
        let PlaneKind::Known { normal, offset } = &p.kind else {
            continue;
        };
        let n = normal.iter().map(|x| x * x).sum::<f64>().sqrt();
        let distance = offset / n;
        if distance.abs() > limit {
            return Err(Error::Invalid(format!(
                "plane {}: offset d = {} m puts it {} m from the base, more than {LENGTH_REACH_FACTOR} × the reach ({reach:.3} m): the robot cannot touch it{}",
                p.name,
                Compact(*offset),
                Compact(distance.abs()),
                as_mm(distance, limit)
            )));
        }
    }
    Ok(())
}

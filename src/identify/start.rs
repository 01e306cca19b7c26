//! The sensor a measurement set calls for, and where identification starts.
//!
//! Measurement files say what they measured: `K` markers per pose, or a
//! point with an orientation. [`for_measurements`] gives the robot measured
//! that way (never flattening several markers into one point) and a start
//! table:
//!
//! * the robot's own sensor when it already fits the data: start at the
//!   nominal table;
//! * orientations for a point robot: its full-pose variant
//!   ([`Robot::with_measurement`]);
//! * `K > 1` markers for a point robot: a `K`-marker robot
//!   ([`Robot::with_markers`]). The offsets are unknown, so the start is
//!   found in two steps: the point robot is fitted to marker 1 alone (its
//!   end point becomes marker 1), then each offset is the mean of `Rᵢᵀ (y_ik −
//!   pᵢ)` over the poses at that fit, the least-squares offset for the
//!   fitted chain. The `K`-marker robot's nominal table is the robot's with
//!   these offsets; identification starts from the fit with these offsets.

use super::{IdentifyError, LmSettings, Result, identify};
use crate::data::Measurements;
use crate::kinematics::Evaluator;
use crate::model::{MeasurementKind, ParamTable, Robot};
use nalgebra::Vector3;

/// A robot fitted to a measurement set's sensor, with where to start.
#[derive(Clone, Debug)]
pub struct Start {
    /// The robot, measured as the data were.
    pub robot: Robot,
    /// The table identification starts from.
    pub table: ParamTable,
    /// What was changed, for the report (empty when nothing was).
    pub notes: Vec<String>,
}

/// The robot measured as `meas` were, and the start of identification (see
/// the module documentation). Errors when the data cannot be of this robot
/// (several markers for a full-pose robot, a joint count that differs).
pub fn for_measurements(robot: &Robot, meas: &Measurements, lm: &LmSettings) -> Result<Start> {
    if let Some(name) = meas.robot().filter(|n| *n != robot.name) {
        return Err(IdentifyError::Model(crate::Error::Invalid(format!(
            "the measurements are of robot '{name}', not '{}'",
            robot.name
        ))));
    }
    let k = meas.markers();
    let has_orientation = !meas.orientations().is_empty();
    if let Some(e) = has_orientation
        .then(|| constant_orientation(robot, meas))
        .flatten()
    {
        return Err(e);
    }
    let have = crate::measure::sensor_for(robot);
    let markers = have.tool_record() == crate::measure::ToolRecord::Markers;
    if k == have.points_per_pose() && has_orientation == have.measures_orientation() && k == 1
        || (k > 1 && markers && have.points_per_pose() == k)
    {
        return Ok(Start {
            robot: robot.clone(),
            table: robot.nominal.clone(),
            notes: Vec::new(),
        });
    }
    // A robot measured by its whole tool point adapts to the data's shape.
    match (have.follows_tool_point(), k, has_orientation) {
        (true, 1, true) => {
            // Builds the full-pose kind the data hold, decided above.
            let r = robot.with_measurement(MeasurementKind::Pose)?;
            Ok(Start {
                table: r.nominal.clone(),
                notes: vec![format!(
                    "the measurements hold orientations: robot '{}' calibrated from full poses ({} unknowns)",
                    robot.name,
                    r.n_params()
                )],
                robot: r,
            })
        }
        (true, k, false) if k > 1 => markers_start(robot, meas, lm),
        _ => {
            // Not a combination we adapt: the check names what differs.
            meas.check(robot)?;
            Err(crate::data::DataError::MarkerCount {
                robot: robot.name.clone(),
                given: k,
                expected: have.points_per_pose(),
            }
            .into())
        }
    }
}

/// The largest turn, degrees, of the nominal model's orientation (a
/// point robot's end frame) between the first pose of `meas` and another.
fn nominal_turn_deg(robot: &Robot, meas: &Measurements) -> f64 {
    let mut ev = Evaluator::new(robot, &robot.nominal);
    let mut qs = meas.qs().iter();
    let Some(first) = qs.next() else {
        return 0.0;
    };
    let r0 = ev.end_frame(first).rotation;
    qs.map(|q| {
        let c = ((r0.transpose() * ev.end_frame(q).rotation).trace() - 1.0) / 2.0;
        c.clamp(-1.0, 1.0).acos().to_degrees()
    })
    .fold(0.0, f64::max)
}

/// The error of orientations that are one rotation (within 1e-9) at every
/// pose while the nominal model's orientation turns by more than a degree
/// over the poses ([`IdentifyError::ConstantOrientation`]): fitted, they
/// would make the robot's orientation still, with an orientation σ of tens
/// of degrees. `None` for orientations that change, or a robot whose
/// orientation does not turn (a gantry).
fn constant_orientation(robot: &Robot, meas: &Measurements) -> Option<IdentifyError> {
    let o = meas.orientations();
    let same = |a: &[[f64; 3]; 3], b: &[[f64; 3]; 3]| {
        (0..3).all(|i| (0..3).all(|j| (a[i][j] - b[i][j]).abs() <= 1e-9))
    };
    if o.len() < 2 || !o.iter().all(|r| same(r, &o[0])) {
        return None;
    }
    let turn_deg = nominal_turn_deg(robot, meas);
    if turn_deg <= 1.0 {
        return None;
    }
    let identity = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    Some(IdentifyError::ConstantOrientation {
        what: if same(&o[0], &identity) {
            "the identity"
        } else {
            "one rotation"
        },
        poses: o.len(),
        turn_deg,
    })
}

/// Each marker's least-squares offset for a chain: the mean over poses of
/// `Rᵢᵀ (y_ik − pᵢ)`.
fn mean_offsets(robot: &Robot, table: &ParamTable, meas: &Measurements) -> Vec<[f64; 3]> {
    let k = meas.markers();
    let mut ev = Evaluator::new(robot, table);
    let mut sum = vec![Vector3::zeros(); k];
    for (i, q) in meas.qs().iter().enumerate() {
        let e = ev.end_frame(q);
        for (j, s) in sum.iter_mut().enumerate() {
            let y = Vector3::from(meas.points()[k * i + j]);
            *s += e.rotation.transpose() * (y - e.position);
        }
    }
    sum.iter().map(|s| (s / meas.len() as f64).into()).collect()
}

/// The two-step start of a `K`-marker fit from a point robot.
fn markers_start(point: &Robot, meas: &Measurements, lm: &LmSettings) -> Result<Start> {
    let k = meas.markers();
    let n = meas.len();
    let first: Vec<[f64; 3]> = (0..n).map(|i| meas.points()[k * i]).collect();
    let m1 = Measurements::unchecked(meas.qs().to_vec(), 1, first, Vec::new());
    let fit = identify(point, &point.nominal, &m1, lm)?;
    let offsets = mean_offsets(point, &fit.table, meas);
    let mut robot = point.with_markers(&offsets)?;
    // The nominal model's own best offsets: what "nominal" means for
    // markers whose offsets were never known.
    robot.nominal.markers = mean_offsets(point, &point.nominal, meas);
    let mut table = fit.table.clone();
    table.markers.clone_from(&offsets);
    Ok(Start {
        notes: vec![format!(
            "{k} markers per pose: a {k}-marker sensor with 3 offset unknowns per marker ({} unknowns in all); started from a fit of marker 1 alone ({:?}, RMS {:.3} mm per point) and the offsets it implies",
            robot.n_params(),
            fit.status,
            1e3 * (fit.rss / n as f64).sqrt()
        )],
        robot,
        table,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The PUMA's joints at pose `i` of twelve, every joint turning.
    fn q(i: usize) -> Vec<f64> {
        (0..6).map(|j| 0.1 * (i * (j + 1)) as f64).collect()
    }

    /// Twelve PUMA poses, their end points measured and each orientation
    /// given by `rotation(i)` (row-major).
    fn measured(rotation: impl FnMut(usize) -> [[f64; 3]; 3]) -> (Robot, Measurements) {
        let robot = Robot::puma560();
        let qs: Vec<Vec<f64>> = (0..12).map(q).collect();
        let mut ev = Evaluator::new(&robot, &robot.nominal);
        let points = qs.iter().map(|q| ev.end_frame(q).position.into()).collect();
        let orientations = (0..qs.len()).map(rotation).collect();
        (robot, Measurements::unchecked(qs, 1, points, orientations))
    }

    #[test]
    fn orientations_that_never_change_while_the_robot_turns_are_refused() {
        let lm = LmSettings::default();
        let identity = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let (robot, meas) = measured(|_| identity);
        match for_measurements(&robot, &meas, &lm) {
            Err(IdentifyError::ConstantOrientation {
                what,
                poses,
                turn_deg,
            }) => {
                assert_eq!((what, poses), ("the identity", 12));
                assert!(turn_deg > 30.0, "{turn_deg}");
            }
            other => panic!("{:?}", other.map(|s| s.notes)),
        }
        let turned = [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]];
        let (robot, meas) = measured(|_| turned);
        let e = for_measurements(&robot, &meas, &lm).err().unwrap();
        assert!(
            e.to_string()
                .contains("is one rotation at every one of the 12 poses"),
            "{e}"
        );
        // The orientations the robot has: fitted as full poses.
        let puma = Robot::puma560();
        let mut ev = Evaluator::new(&puma, &puma.nominal);
        let (robot, meas) = measured(|i| ev.end_frame(&q(i)).rotation.transpose().into());
        let start = for_measurements(&robot, &meas, &lm).unwrap();
        assert_eq!(start.robot.measurement, MeasurementKind::Pose);
    }
}

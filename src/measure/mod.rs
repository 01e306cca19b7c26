//! What a sensor measures at a pose: the measurement seam ([`Sensor`], with
//! [`point`], [`pose`], [`markers`], [`contact`] and [`camera`] sensors; a
//! camera's projection in [`pinhole`]), the region it sees ([`visibility`])
//! and the rotation maps of full-pose measurements ([`so3`]).
//!
//! [`JacobianEvaluator`] joins the kinematics' per-unknown motions and a
//! sensor's rows into the identification Jacobian of one pose.

pub mod camera;
pub mod contact;
pub mod fisheye;
pub mod markers;
pub mod pinhole;
pub mod point;
pub mod pose;
pub mod sensor;
pub mod so3;
pub mod visibility;

pub use sensor::{Observation, ObservationBuf, RowKind, Sensor, ToolRecord};
pub use visibility::Visibility;

use crate::kinematics::{Evaluator, Motion};
use crate::model::{ParamTable, Robot};
use nalgebra::{Matrix3, Vector3};

/// The identification Jacobian of one robot, parameter table and its sensor
/// ([`sensor_for`]), pose by pose, with reusable scratch.
#[derive(Debug)]
pub struct JacobianEvaluator<'r> {
    ev: Evaluator<'r>,
    sensor: Box<dyn Sensor>,
    /// The same kind of sensor with unit weights (joint Jacobians).
    unweighted: Box<dyn Sensor>,
    motions: Vec<Motion>,
    joints: Vec<Motion>,
    /// The sensor's own parameters (marker offsets) in `table`.
    own: Vec<f64>,
}

impl<'r> JacobianEvaluator<'r> {
    /// An evaluator for `robot` with parameters `table`.
    #[must_use]
    pub fn new(robot: &'r Robot, table: &'r ParamTable) -> Self {
        Self {
            ev: Evaluator::new(robot, table),
            sensor: sensor_for(robot),
            unweighted: sensor_of(robot.measurement, 1.0),
            motions: vec![Motion::default(); robot.n_unknowns()],
            joints: vec![Motion::default(); robot.dof()],
            own: table.marker_values(),
        }
    }

    /// The sensor.
    #[must_use]
    pub fn sensor(&self) -> &dyn Sensor {
        self.sensor.as_ref()
    }

    /// End point at `q`, and the identification Jacobian `∂y/∂θ` (t × p,
    /// row-major, `t` = the sensor's rows, `p` = [`Robot::n_params`]: the
    /// unknowns in [`Robot::unknowns`] order, then the sensor's own) at zero
    /// residual written into `jac` (see
    /// [`Sensor::motion_rows`]: rows 0–2 the position, for a full pose rows
    /// 3–5 the angular velocity times [`Robot::orientation_scale`]).
    pub fn eval(&mut self, q: &[f64], jac: &mut [f64]) -> Vector3<f64> {
        self.eval_pose(q, jac).1
    }

    /// As [`JacobianEvaluator::eval`], also returning the end frame's
    /// orientation.
    pub fn eval_pose(&mut self, q: &[f64], jac: &mut [f64]) -> (Matrix3<f64>, Vector3<f64>) {
        let n = self.motions.len();
        let p = n + self.own.len();
        debug_assert_eq!(jac.len(), self.sensor.rows() * p);
        let end = self.ev.motions(q, &mut self.motions);
        self.sensor
            .motion_rows(&end, &self.own, &self.motions, jac, p);
        self.sensor.own_rows(&end, &self.own, &mut jac[n..], p);
        (end.rotation, end.position)
    }

    /// Geometric Jacobian with respect to the joint values (t × dof,
    /// row-major): the sensor's rows of the joints' motions
    /// ([`Evaluator::joint_motions`]) with unit weights: for a full pose,
    /// rows 3–5 are the angular velocity itself (rad per joint unit), not
    /// scaled by [`Robot::orientation_scale`]. Returns the end point.
    pub fn joint_jacobian(&mut self, q: &[f64], jac: &mut [f64]) -> Vector3<f64> {
        let dof = self.joints.len();
        debug_assert_eq!(jac.len(), self.sensor.rows() * dof);
        let end = self.ev.joint_motions(q, &mut self.joints);
        self.unweighted
            .motion_rows(&end, &self.own, &self.joints, jac, dof);
        end.position
    }
}

// The dispatcher lives beside the implementations' module declarations,
// not beside the trait: each sensor file imports the trait, and the trait's
// file imports none of them.
/// The sensor of a measurement kind, with the robot's weights.
#[must_use]
pub fn sensor_of(kind: crate::model::MeasurementKind, orientation_scale: f64) -> Box<dyn Sensor> {
    match kind {
        crate::model::MeasurementKind::Point => Box::new(point::PointSensor::new()),
        crate::model::MeasurementKind::Pose => Box::new(pose::PoseSensor::new(orientation_scale)),
        crate::model::MeasurementKind::Markers(k) => Box::new(markers::MarkerSensor::new(k)),
    }
}

/// The sensor a robot is measured with ([`Robot::measurement`], weighted by
/// [`Robot::orientation_scale`]).
#[must_use]
pub fn sensor_for(robot: &Robot) -> Box<dyn Sensor> {
    sensor_of(robot.measurement, robot.orientation_scale)
}

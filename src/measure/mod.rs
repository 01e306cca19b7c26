//! What a sensor measures at a pose: the measurement seam ([`Sensor`], with
//! [`point`], [`pose`], [`markers`], [`contact`] and [`camera`] sensors; a
//! camera's projection in [`pinhole`]), the region it sees ([`visibility`])
//! and the rotation maps of full-pose measurements ([`so3`]).
//!
//! A sensor beside these is one folder `measure/<name>/` (its [`Sensor`],
//! its [`crate::model::SensorKey`] and its [`Registration`]) plus one line
//! in `registered_sensors!` below: a robot measured by it
//! ([`crate::model::MeasurementKind::Registered`]) is selected, bounded and
//! fitted by the library's pipelines through the trait alone.
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
///
/// # Panics
/// For a [`crate::model::MeasurementKind::Registered`] key that no sensor
/// registers, or whose rows differ from its sensor's: keys come from the
/// sensors' folders, so either is a programming error, not input.
#[must_use]
pub fn sensor_of(kind: crate::model::MeasurementKind, orientation_scale: f64) -> Box<dyn Sensor> {
    match kind {
        crate::model::MeasurementKind::Point => Box::new(point::PointSensor::new()),
        crate::model::MeasurementKind::Pose => Box::new(pose::PoseSensor::new(orientation_scale)),
        crate::model::MeasurementKind::Markers(k) => Box::new(markers::MarkerSensor::new(k)),
        crate::model::MeasurementKind::Registered(key) => {
            let r = registered()
                .into_iter()
                .find(|r| r.key == key)
                .unwrap_or_else(|| panic!("sensor '{}' is not registered", key.name));
            let sensor = (r.make)(orientation_scale);
            assert_eq!(sensor.rows(), key.rows, "sensor '{}': rows", key.name);
            sensor
        }
    }
}

/// A sensor registered beside the built-in ones
/// ([`crate::model::MeasurementKind::Registered`]): the key it is named by
/// and how it is built.
#[derive(Clone, Copy, Debug)]
pub struct Registration {
    /// Its key.
    pub key: crate::model::SensorKey,
    /// Builds the sensor, given the robot's orientation scale.
    pub make: fn(f64) -> Box<dyn Sensor>,
}

/// Declares each registered sensor's module (`measure/<name>/`, which
/// defines its `REGISTRATION`) and lists them in [`registered`].
macro_rules! registered_sensors {
    ($($name:ident),* $(,)?) => {
        $(pub mod $name;)*

        /// Every sensor registered beside the built-in ones.
        #[must_use]
        pub fn registered() -> Vec<Registration> {
            vec![$($name::REGISTRATION),*]
        }
    };
}

// Sensors beside the built-in ones: each is its folder `measure/<name>/`
// (the sensor, its key and its `REGISTRATION`) and one line here.
registered_sensors! {
    height,
}

/// The measurement kind of the registered sensor named `name` (its
/// [`crate::model::SensorKey::name`]), as robot files and robot names
/// (`ur5:NAME`) choose it; `None` when no sensor registers that name.
#[must_use]
pub fn registered_kind(name: &str) -> Option<crate::model::MeasurementKind> {
    registered()
        .into_iter()
        .find(|r| r.key.name == name)
        .map(|r| crate::model::MeasurementKind::Registered(r.key))
}

/// The names of the registered sensors, in registration order, for
/// messages listing the measurements a file or a name may choose.
#[must_use]
pub fn registered_names() -> Vec<&'static str> {
    registered().into_iter().map(|r| r.key.name).collect()
}

/// The sensor a robot is measured with ([`Robot::measurement`], weighted by
/// [`Robot::orientation_scale`]).
#[must_use]
pub fn sensor_for(robot: &Robot) -> Box<dyn Sensor> {
    sensor_of(robot.measurement, robot.orientation_scale)
}

//! `fk`'s report: forward kinematics (and the identification Jacobian) at
//! one joint vector, with the end frame's orientation in every form.

use super::chain;
use crate::model::{ParamSet, Robot};
use serde::Serialize;

/// `fk`: forward kinematics (and the identification Jacobian) at one joint
/// vector.
#[derive(Clone, Debug, Serialize)]
pub struct FkReport {
    /// Robot name or description path.
    pub robot: String,
    /// Driven frames.
    pub chain: Vec<String>,
    /// Parameter set.
    pub params: ParamSet,
    /// Joint values, radians (or metres).
    pub q: Vec<f64>,
    /// End point.
    pub position: [f64; 3],
    /// The end frame's orientation, for robots whose sensor measures or
    /// observes it (full poses, several markers).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub orientation: Option<Orientation>,
    /// Predicted marker positions (a marker robot).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub markers: Option<Vec<[f64; 3]>>,
    /// Identification Jacobian, `t` rows of `p` (when asked for).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub jacobian: Option<Vec<Vec<f64>>>,
    /// Names of its columns (when the Jacobian is asked for).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub parameter_names: Option<Vec<String>>,
    /// The end frame's rotation matrix (base frame), rows; not in the
    /// report's JSON (`orientation` gives it in the files' forms).
    #[serde(skip)]
    pub rotation: [[f64; 3]; 3],
}

impl FkReport {
    /// [`Self::new`] at joint values `q` given in `units` (named `label`
    /// in messages: their count, the joints' names, limits and units
    /// checked as every reader of joint values does,
    /// [`crate::units::joint_values_to_model_units`]).
    pub fn in_units(
        robot: &Robot,
        params: ParamSet,
        q: Vec<f64>,
        units: crate::units::Units,
        label: &str,
        jacobian: bool,
    ) -> crate::Result<Self> {
        let names = crate::units::joint_names(robot);
        if q.len() != robot.dof() {
            return Err(crate::Error::Invalid(format!(
                "{label}: expected {} joint angles, got {}: the joints of {} are, in order, {}",
                robot.dof(),
                q.len(),
                robot.name,
                names.join(", ")
            )));
        }
        robot.check_q(&q)?;
        let mut qs = vec![q];
        let rows = ["the joint vector".to_string()];
        let source = crate::units::JointSource {
            file: label,
            rows: &rows,
            columns: &names,
        };
        crate::units::joint_values_to_model_units(robot, units, &source, &mut qs)?;
        let q = qs.pop().expect("one joint vector");
        Self::new(robot, params, q, jacobian)
    }

    /// Forward kinematics of `robot` at `q` with table `params`, and the
    /// Jacobian when `jacobian` is set.
    pub fn new(
        robot: &Robot,
        params: ParamSet,
        q: Vec<f64>,
        jacobian: bool,
    ) -> crate::Result<Self> {
        let table = robot.params(params);
        let p = crate::kinematics::position_checked(robot, table, &q)?;
        let sensor = crate::measure::sensor_for(robot);
        let (rot, _) = crate::kinematics::pose(robot, table, &q);
        let orientation = sensor.observes_orientation().then(|| Orientation::of(&rot));
        let markers = (robot.measurement.markers() > 0).then(|| {
            table
                .markers
                .iter()
                .map(|o| (p + rot * nalgebra::Vector3::from(*o)).into())
                .collect()
        });
        let jac = jacobian.then(|| {
            let n = robot.n_params();
            let mut jac = vec![0.0; robot.rows_per_pose() * n];
            crate::measure::JacobianEvaluator::new(robot, table).eval(&q, &mut jac);
            jac.chunks(n.max(1)).map(<[f64]>::to_vec).collect()
        });
        Ok(Self {
            robot: robot.name.clone(),
            chain: chain(robot),
            params,
            q,
            position: [p.x, p.y, p.z],
            orientation,
            markers,
            parameter_names: jac.as_ref().map(|_| robot.parameter_names()),
            jacobian: jac,
            rotation: std::array::from_fn(|i| std::array::from_fn(|j| rot[(i, j)])),
        })
    }
}

/// An orientation in the forms measurement files use.
#[derive(Clone, Debug, Serialize)]
pub struct Orientation {
    /// Rotation matrix, row-major (columns: the end frame's axes).
    pub matrix: [[f64; 3]; 3],
    /// Roll, pitch, yaw (radians): `R = Rz(yaw) · Ry(pitch) · Rx(roll)`, the
    /// `phix, phiy, phiz` of a measurement CSV.
    pub rpy: [f64; 3],
    /// Unit quaternion `[w, x, y, z]` with `w ≥ 0`.
    pub quaternion: [f64; 4],
}

impl Orientation {
    /// The forms of a rotation matrix.
    #[must_use]
    pub fn of(r: &nalgebra::Matrix3<f64>) -> Self {
        let rot = nalgebra::Rotation3::from_matrix_unchecked(*r);
        let (roll, pitch, yaw) = rot.euler_angles();
        let mut q = nalgebra::UnitQuaternion::from_rotation_matrix(&rot);
        if q.w < 0.0 {
            q = nalgebra::UnitQuaternion::new_unchecked(-q.into_inner());
        }
        Self {
            matrix: std::array::from_fn(|i| std::array::from_fn(|j| r[(i, j)])),
            rpy: [roll, pitch, yaw],
            quaternion: [q.w, q.i, q.j, q.k],
        }
    }
}

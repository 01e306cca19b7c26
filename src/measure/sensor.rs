//! The measurement seam: what a sensor observes of the end frame, how a
//! measured value differs from a predicted one, and the rows it contributes
//! to the identification Jacobian.
//!
//! The kinematics ([`crate::kinematics::Evaluator`]) know nothing of
//! sensors: at a joint vector they give the end frame `(R, p)` and, for every
//! unknown, the [`Motion`] it induces, i.e. the linear velocity of the end
//! point and the angular velocity of the end frame under that parameter's
//! elementary motion. A [`Sensor`] turns these into its measurement
//! (prediction), its residual and its Jacobian rows, with its row weights.
//!
//! # Values
//! A measured or predicted value of one pose is a flat slice of
//! [`Sensor::value_len`] numbers in the sensor's own layout (a point: `x y
//! z`; a pose: `x y z` then the unit quaternion `w x y z`). Residuals have
//! [`Sensor::rows`] entries (any number: K markers give 3K) and are already
//! weighted, so that every row carries the same noise σ.
//!
//! # Unknowns of a sensor's own
//! A sensor may carry unknowns of its own, e.g. one marker offset `o_k`
//! (a 3-vector in the end frame) per marker. They are
//! [`Sensor::n_own_params`] columns appended after the robot's unknowns in
//! the parameter vector and in every Jacobian: `θ = [θ_robot, θ_sensor]`.
//! Their current values are passed as `own` to [`Sensor::predict`],
//! [`Sensor::motion_rows`] and [`Sensor::own_rows`]; the latter writes their
//! columns (for a marker `p_k = p + R o_k`: `∂p_k/∂o_k = R`). The robot's
//! columns of a marker are `lin + ang × (R o_k)`, from the same [`Motion`]s.
//! Point and pose sensors have no unknowns of their own (`own` is empty).
//!
//! # Poses that share unknowns, and constraints between them
//! A contact sensor ([`super::contact`]) has no measured value at all: a
//! pose's value is the group it touches (its [`Observation::tag`]), and its
//! residual is the tool point minus that group's point, an own unknown. Such
//! a sensor overrides [`Sensor::residual_own`] and [`Sensor::own_rows_of`],
//! which see the own unknowns and the measured value (the defaults fall back
//! to [`Sensor::residual`] and [`Sensor::own_rows`]), and may add rows tied
//! to no pose ([`Sensor::constraint_rows`], [`Sensor::constraints`]: a known
//! distance between two contact points), appended after the poses' rows.

use crate::kinematics::{EndFrame, Motion};
use nalgebra::Vector3;
use std::fmt;

/// What a calibrated robot's description records of what its sensor
/// measured on the last link, for frames tables and URDF tool frames.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ToolRecord {
    /// The tool frame, position and orientation (a full pose).
    Frame,
    /// One tool point in the last link (its orientation unobserved).
    Point,
    /// Each marker's offset in the last link.
    Markers,
}

/// What a row of a residual measures, for reports that split errors into
/// distances and angles.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RowKind {
    /// A position coordinate, metres.
    Position,
    /// An orientation coordinate (a rotation-vector component), radians
    /// before weighting.
    Orientation,
    /// An image coordinate (`u` or `v`), pixels ([`super::camera`]).
    Pixel,
}

/// One pose's observation as measurement files hold it: measured points
/// (base frame, metres) and, for sensors that see orientation, a rotation
/// matrix (row-major, base frame).
#[derive(Clone, Copy, Debug)]
pub struct Observation<'a> {
    /// Measured points, [`Sensor::points_per_pose`] of them.
    pub points: &'a [[f64; 3]],
    /// Measured orientation, present exactly when
    /// [`Sensor::observes_orientation`].
    pub orientation: Option<&'a [[f64; 3]; 3]>,
    /// The pose's group among the sensor's own unknowns, for sensors whose
    /// poses share unknowns by group (a contact sensor's point or plane,
    /// [`super::contact`]); `None` for the others.
    pub tag: Option<usize>,
}

/// An owned [`Observation`], as a simulation produces it.
#[derive(Clone, Debug, PartialEq)]
pub struct ObservationBuf {
    /// Measured points.
    pub points: Vec<[f64; 3]>,
    /// Measured orientation, row-major.
    pub orientation: Option<[[f64; 3]; 3]>,
    /// The pose's group (see [`Observation::tag`]).
    pub tag: Option<usize>,
}

/// A sensor: rows per pose, prediction, residual, Jacobian rows and weights.
///
/// Implementations: [`super::point::PointSensor`] (3 rows, the end point;
/// or the coordinates of it a sensor reads, [`Sensor::point_coordinates`]),
/// [`super::pose::PoseSensor`] (6 rows, the end point and the end frame's orientation)
/// and [`super::markers::MarkerSensor`] (`3K` rows, `K` markers with their own offsets).
/// [`super::sensor_for`] picks one from [`crate::model::Robot::measurement`].
/// Sensors that are not a robot's own are built by their fits:
/// [`super::contact::ContactSensor`] (contacts with fixed points) and
/// [`super::camera::CameraSensor`] (`2N` pixel rows of `N` target points).
///
/// The hot path, the pool Jacobian of up to 10⁶ poses, calls
/// [`Sensor::motion_rows`] once per pose; every other method is per pose or
/// per identification.
pub trait Sensor: fmt::Debug + Send + Sync {
    /// What a pose's measurement is, for messages (`points`, `full poses
    /// (position and orientation)`).
    fn describe(&self) -> &'static str;

    /// Rows of the residual and of the identification Jacobian per pose (`t`).
    fn rows(&self) -> usize;

    /// Kind of each of the [`Sensor::rows`] rows.
    fn row_kinds(&self) -> &[RowKind];

    /// Weight of each row: residual and Jacobian rows are multiplied by it so
    /// that every row carries the same noise σ (1 for positions,
    /// [`crate::model::Robot::orientation_scale`] for orientations).
    fn weights(&self) -> &[f64];

    /// Degrees of freedom of the end frame the sensor observes (3 for a
    /// point, 6 for a pose or three markers off a line): with the robot's
    /// joints they give the number of independent kinematic parameters.
    fn observed_dof(&self) -> usize;

    /// Whether the measurement includes the end frame's orientation (so
    /// that an orientation error of the model is observable).
    fn observes_orientation(&self) -> bool;

    /// Whether a measured value holds an orientation (a rotation per pose
    /// in measurement files). Default: [`Sensor::observes_orientation`];
    /// several markers observe the orientation through their positions
    /// without measuring one.
    fn measures_orientation(&self) -> bool {
        self.observes_orientation()
    }

    /// Points measured per pose.
    fn points_per_pose(&self) -> usize;

    /// What a calibrated description records of the measured tool (frames
    /// tables, URDF tool frames, the 3D page's tracker). Default: the tool
    /// frame when a value holds an orientation, else the tool point.
    fn tool_record(&self) -> ToolRecord {
        if self.measures_orientation() {
            ToolRecord::Frame
        } else {
            ToolRecord::Point
        }
    }

    /// Whether a value is the whole tool point and nothing more (its `x y
    /// z`, no orientation, no unknowns of the sensor's own): a robot so
    /// measured turns into its full-pose variant when data hold
    /// orientations (or `:pose` asks for it), into a `K`-marker one when
    /// data hold `K` points a pose, and is started from the tool point the
    /// data imply. Default: from [`Sensor::tool_record`],
    /// [`Sensor::point_coordinates`], [`Sensor::measures_orientation`] and
    /// [`Sensor::n_own_params`], so a sensor reading less (a height) is not.
    fn follows_tool_point(&self) -> bool {
        self.tool_record() == ToolRecord::Point
            && self.points_per_pose() == 1
            && self.point_coordinates().len() == 3
            && !self.measures_orientation()
            && self.n_own_params() == 0
    }

    /// The points of the last link the sensor follows, in the measurement
    /// frame (metres), for end frame `end` and own unknowns `own`: the end
    /// point by default; each marker for a marker sensor.
    fn measured_points(&self, end: &EndFrame, own: &[f64]) -> Vec<Vector3<f64>> {
        let _ = own;
        vec![end.position]
    }

    /// The coordinates of each measured point that a value reads (indices
    /// into `x y z`, increasing), for measurement files: a CSV holds the
    /// columns `x1 y1 z1`… of these alone, and the others of a point read
    /// as 0. A calibration's validation and predicted errors count these
    /// coordinates of the tool point alone (a height gauge's: the height
    /// error), and a measured point has this many position rows. Default
    /// all three.
    fn point_coordinates(&self) -> &'static [usize] {
        &[0, 1, 2]
    }

    /// Length of one pose's measured or predicted value.
    fn value_len(&self) -> usize;

    /// Number of unknowns of the sensor's own, appended after the robot's
    /// (see the module documentation). Default 0.
    fn n_own_params(&self) -> usize {
        0
    }

    /// Names of the sensor's own unknowns (`n_own_params` of them). Default none.
    fn own_param_names(&self) -> Vec<String> {
        Vec::new()
    }

    /// Writes an observation in the sensor's value layout into `out`
    /// (`value_len` entries), projecting it onto the measurement manifold
    /// where needed (a measured rotation onto the nearest rotation). The
    /// observation has the shape the sensor expects (checked by the caller).
    fn encode(&self, obs: &Observation<'_>, out: &mut [f64]);

    /// The observation a value stands for (the inverse of
    /// [`Sensor::encode`] up to rounding).
    fn decode(&self, value: &[f64]) -> ObservationBuf;

    /// The predicted value (`value_len` entries) for end frame `end` and the
    /// sensor's own unknowns `own`.
    fn predict(&self, end: &EndFrame, own: &[f64], out: &mut [f64]);

    /// Moves a value by `delta` (`rows` entries, unweighted: metres and
    /// radians) along the measurement manifold: simulated noise.
    fn retract(&self, value: &mut [f64], delta: &[f64]);

    /// The weighted residual `predicted ⊖ measured` (`rows` entries).
    fn residual(&self, predicted: &[f64], measured: &[f64], out: &mut [f64]);

    /// The identification-Jacobian rows of the kinematic columns at zero
    /// residual (the design Jacobian `X` that pose selection uses): column
    /// `c` of the `rows × motions.len()` block is the weighted derivative of
    /// the measurement under `motions[c]`. Written row-major into `out` with
    /// row stride `ld ≥ motions.len()` (so that own columns can follow).
    fn motion_rows(
        &self,
        end: &EndFrame,
        own: &[f64],
        motions: &[Motion],
        out: &mut [f64],
        ld: usize,
    );

    /// The exact derivative of [`Sensor::residual`] against `measured` with
    /// respect to the motions (for Levenberg–Marquardt), same layout as
    /// [`Sensor::motion_rows`]. Default: [`Sensor::motion_rows`], exact for
    /// residuals linear in the prediction (points).
    fn residual_rows(
        &self,
        end: &EndFrame,
        own: &[f64],
        motions: &[Motion],
        measured: &[f64],
        out: &mut [f64],
        ld: usize,
    ) {
        let _ = measured;
        self.motion_rows(end, own, motions, out, ld);
    }

    /// The columns of the sensor's own unknowns (`rows × n_own_params`),
    /// row-major with row stride `ld` into `out`. Default: nothing (no own
    /// unknowns).
    fn own_rows(&self, end: &EndFrame, own: &[f64], out: &mut [f64], ld: usize) {
        let _ = (end, own, out, ld);
    }

    /// The weighted residual of a pose knowing the sensor's own unknowns
    /// (see the module documentation). Default: [`Sensor::residual`].
    fn residual_own(&self, predicted: &[f64], measured: &[f64], own: &[f64], out: &mut [f64]) {
        let _ = own;
        self.residual(predicted, measured, out);
    }

    /// The own columns of a pose's residual knowing its measured value.
    /// Default: [`Sensor::own_rows`].
    fn own_rows_of(
        &self,
        end: &EndFrame,
        own: &[f64],
        measured: &[f64],
        out: &mut [f64],
        ld: usize,
    ) {
        let _ = measured;
        self.own_rows(end, own, out, ld);
    }

    /// Rows of constraints between the sensor's own unknowns, tied to no
    /// pose (appended after every pose's rows). Default 0.
    fn constraint_rows(&self) -> usize {
        0
    }

    /// Writes the weighted constraint residuals ([`Sensor::constraint_rows`]
    /// entries) into `r` and, when `jac` is given, their own columns
    /// (`constraint_rows × n_own_params`, row-major, row stride `ld`).
    /// Default: nothing.
    fn constraints(&self, own: &[f64], r: &mut [f64], jac: Option<&mut [f64]>, ld: usize) {
        let _ = (own, r, jac, ld);
    }
}

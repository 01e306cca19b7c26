//! Points (and orientations) measured at known joint angles
//! ([`Measurements`]), validated against a robot, and the [`DataError`]
//! their checks give.

use crate::error::Error;
use crate::measure::Observation;
use crate::model::Robot;
use serde::{Deserialize, Serialize};
use thiserror::Error;

/// Bad measured data: what was wrong and where (pose numbers 0-based).
#[derive(Debug, Error)]
pub enum DataError {
    /// No poses at all.
    #[error("no measurements: identification needs at least one measured pose")]
    Empty,
    /// Joint vectors and measured points of different counts.
    #[error(
        "{poses} poses but {measurements} measured points: every pose needs exactly {per_pose} (missing measurements?)"
    )]
    MeasurementCount {
        /// Number of joint vectors.
        poses: usize,
        /// Number of measured points.
        measurements: usize,
        /// Points per pose (markers).
        per_pose: usize,
    },
    /// Several markers per pose given for a robot whose sensor sees another
    /// number: never flattened into one point.
    #[error(
        "the measurements hold {given} marker(s) per pose but robot '{robot}' measures {expected}: several markers are never merged into one point; calibrate with a {given}-marker sensor (a measurement file with {given} markers does that by itself in `calibrate` and `evaluate`)"
    )]
    MarkerCount {
        /// The robot's name.
        robot: String,
        /// Markers per pose in the measurements.
        given: usize,
        /// Points per pose of the robot's sensor.
        expected: usize,
    },
    /// A measured coordinate that is NaN or infinite.
    #[error(
        "measurement {pose}, coordinate {coordinate}: not a finite number ({value}); missing or corrupt"
    )]
    NonFiniteMeasurement {
        /// 0-based pose number.
        pose: usize,
        /// `x`, `y` or `z`.
        coordinate: char,
        /// The value given.
        value: f64,
    },
    /// A joint vector that does not fit the robot.
    #[error("pose {pose}: {source}")]
    Pose {
        /// 0-based pose number.
        pose: usize,
        /// What is wrong with it.
        source: Error,
    },
    /// Orientations missing for a full-pose robot, or given for a point robot.
    #[error(
        "robot '{robot}' measures {expected} per pose, but {given} orientations were given for {poses} poses"
    )]
    OrientationCount {
        /// The robot's name.
        robot: String,
        /// `points` or `full poses (position and orientation)`.
        expected: &'static str,
        /// Orientations given.
        given: usize,
        /// Poses given.
        poses: usize,
    },
    /// A measured orientation that is not a rotation matrix.
    #[error("measurement {pose}: the orientation is not a rotation matrix: {reason}")]
    NotARotation {
        /// 0-based pose number.
        pose: usize,
        /// What is wrong with it.
        reason: String,
    },
    /// Invalid robot (a file naming another robot, say).
    #[error(transparent)]
    Model(#[from] Error),
}

/// Result with a [`DataError`].
pub type Result<T> = std::result::Result<T, DataError>;

/// Largest `max |RᵀR − I|` accepted for a measured orientation: a rotation
/// matrix written with 7 significant digits (a sensor's export) is
/// orthonormal to about 1e-7; a matrix off by more than 1e-6 is not a
/// rotation but a typing or unit error. Accepted matrices are projected to
/// the nearest rotation before use.
pub const ROTATION_TOLERANCE: f64 = 1e-6;

/// Points (and, for a full-pose robot, orientations) measured at known joint
/// angles, validated against a robot: as many points as joint vectors, every
/// joint vector of the robot's length and finite, every coordinate finite,
/// and one rotation matrix per pose exactly when the robot measures full
/// poses.
///
/// In JSON: `{"robot": "name", "qs": [[q1, …], …], "points": [[x, y, z],
/// …], "orientations": [[[r00, r01, r02], [r10, …], [r20, …]], …]}`
/// (metres, radians; orientations row-major, base frame, omitted for
/// points; `robot` optional, checked against the robot when present). With
/// `K` markers per pose (`"markers": K`, default 1) `points` holds `K` points
/// per pose, pose-major (pose 1's markers 1…K, then pose 2's).
/// Instead of `orientations` a file may give `"quaternions": [[w, x, y, z],
/// …]` (unit to [`ROTATION_TOLERANCE`], scalar first, as most trackers
/// export them); they are read into rotation matrices.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields, try_from = "MeasurementsFile")]
pub struct Measurements {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    robot: Option<String>,
    qs: Vec<Vec<f64>>,
    #[serde(default = "one", skip_serializing_if = "is_one")]
    markers: usize,
    points: Vec<[f64; 3]>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    orientations: Vec<[[f64; 3]; 3]>,
}

fn one() -> usize {
    1
}

fn is_one(k: &usize) -> bool {
    *k == 1
}

impl Measurements {
    /// Validates and wraps joint vectors and the points measured at them.
    ///
    /// ```
    /// use activecal::data::Measurements;
    /// use activecal::model::Robot;
    /// let robot = Robot::puma560();
    /// let bad = Measurements::new(&robot, vec![vec![0.0; 6]], vec![[0.0, f64::NAN, 0.0]]);
    /// assert!(bad.unwrap_err().to_string().contains("coordinate y"));
    /// ```
    pub fn new(robot: &Robot, qs: Vec<Vec<f64>>, points: Vec<[f64; 3]>) -> Result<Self> {
        Self::with_orientations(robot, qs, points, Vec::new())
    }

    /// Validates and wraps full-pose measurements: joint vectors, the
    /// positions and the orientations (rotation matrices, row-major) measured
    /// at them. For a point robot `orientations` must be empty.
    ///
    /// ```
    /// use activecal::data::Measurements;
    /// use activecal::model::Robot;
    /// let robot = Robot::builtin("ur5:pose").unwrap();
    /// let eye = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    /// let ok = Measurements::with_orientations(&robot, vec![vec![0.0; 6]], vec![[0.0; 3]], vec![eye]);
    /// assert!(ok.is_ok());
    /// let missing = Measurements::new(&robot, vec![vec![0.0; 6]], vec![[0.0; 3]]);
    /// assert!(missing.unwrap_err().to_string().contains("0 orientations"));
    /// ```
    pub fn with_orientations(
        robot: &Robot,
        qs: Vec<Vec<f64>>,
        points: Vec<[f64; 3]>,
        orientations: Vec<[[f64; 3]; 3]>,
    ) -> Result<Self> {
        let markers = robot.measurement.markers().max(1);
        let m = Self {
            robot: None,
            qs,
            markers,
            points,
            orientations,
        };
        m.check(robot)?;
        Ok(m)
    }

    /// Wraps measurements without a robot to check them against: joint
    /// vectors, `markers` points per pose (pose-major) and orientations, as a
    /// file reader has them. [`Measurements::check`] validates them against
    /// the robot they are used with (as [`identify`] does).
    #[must_use]
    pub fn unchecked(
        qs: Vec<Vec<f64>>,
        markers: usize,
        points: Vec<[f64; 3]>,
        orientations: Vec<[[f64; 3]; 3]>,
    ) -> Self {
        Self {
            robot: None,
            qs,
            markers,
            points,
            orientations,
        }
    }

    /// The markers that repeat an earlier marker in every pose (the same
    /// coordinates to 1e-12 relative: an exporter's copy, not a second
    /// marker), as `(duplicate, original)` pairs of 0-based marker numbers,
    /// and the measurements with each counted once. Two copies of one
    /// marker are one measurement: fitted as two, they would halve its
    /// noise and give the copy an offset of its own.
    #[must_use]
    pub fn without_repeated_markers(&self) -> (Self, Vec<(usize, usize)>) {
        let k = self.markers;
        let same = |a: &[f64; 3], b: &[f64; 3]| {
            a.iter()
                .zip(b)
                .all(|(x, y)| (x - y).abs() <= 1e-12 * (1.0 + x.abs().max(y.abs())))
        };
        let mut repeats = Vec::new();
        for b in 1..k {
            if let Some(a) = (0..b).find(|&a| {
                !repeats.iter().any(|&(d, _)| d == a)
                    && self
                        .points
                        .chunks_exact(k)
                        .all(|pose| same(&pose[a], &pose[b]))
            }) {
                repeats.push((b, a));
            }
        }
        if repeats.is_empty() || self.points.is_empty() {
            return (self.clone(), Vec::new());
        }
        let keep: Vec<usize> = (0..k)
            .filter(|m| !repeats.iter().any(|&(d, _)| d == *m))
            .collect();
        let points = self
            .points
            .chunks_exact(k)
            .flat_map(|pose| keep.iter().map(|&m| pose[m]).collect::<Vec<_>>())
            .collect();
        let mut out = self.clone();
        out.markers = keep.len();
        out.points = points;
        (out, repeats)
    }

    /// Replaces the joint vectors (as converted by a reader, one per pose)
    /// and scales every measured point by `length_to_m`: a file read in
    /// other units, brought to radians and metres.
    pub fn set_units(&mut self, qs: Vec<Vec<f64>>, length_to_m: f64) {
        debug_assert_eq!(qs.len(), self.qs.len());
        self.qs = qs;
        if length_to_m != 1.0 {
            for p in &mut self.points {
                p.iter_mut().for_each(|c| *c *= length_to_m);
            }
        }
    }

    /// Markers (points) per pose.
    #[must_use]
    pub fn markers(&self) -> usize {
        self.markers
    }

    /// The measurements of the given poses (in that order), e.g. a
    /// training or held-out split. Panics on an index out of range.
    #[must_use]
    pub fn subset(&self, poses: &[usize]) -> Self {
        let k = self.markers;
        Self {
            robot: self.robot.clone(),
            qs: poses.iter().map(|&i| self.qs[i].clone()).collect(),
            markers: k,
            points: poses
                .iter()
                .flat_map(|&i| self.points[k * i..k * (i + 1)].iter().copied())
                .collect(),
            orientations: if self.orientations.is_empty() {
                Vec::new()
            } else {
                poses.iter().map(|&i| self.orientations[i]).collect()
            },
        }
    }

    /// Re-checks the measurements against a robot (done by [`identify`]).
    pub fn check(&self, robot: &Robot) -> Result<()> {
        if let Some(name) = self.robot.as_ref().filter(|n| **n != robot.name) {
            return Err(DataError::Model(Error::Invalid(format!(
                "the measurements are of robot '{name}', not '{}'",
                robot.name
            ))));
        }
        let sensor = crate::measure::sensor_for(robot);
        if sensor.points_per_pose() != self.markers {
            return Err(DataError::MarkerCount {
                robot: robot.name.clone(),
                given: self.markers,
                expected: sensor.points_per_pose(),
            });
        }
        if self.qs.len().checked_mul(self.markers) != Some(self.points.len()) {
            return Err(DataError::MeasurementCount {
                poses: self.qs.len(),
                measurements: self.points.len(),
                per_pose: self.markers,
            });
        }
        if self.qs.is_empty() {
            return Err(DataError::Empty);
        }
        for (i, q) in self.qs.iter().enumerate() {
            robot
                .check_q(q)
                .map_err(|source| DataError::Pose { pose: i, source })?;
        }
        for (i, p) in self.points.iter().enumerate() {
            if let Some(c) = (0..3).find(|&c| !p[c].is_finite()) {
                return Err(DataError::NonFiniteMeasurement {
                    pose: i / self.markers,
                    coordinate: ['x', 'y', 'z'][c],
                    value: p[c],
                });
            }
        }
        let want = if sensor.measures_orientation() {
            self.qs.len()
        } else {
            0
        };
        if self.orientations.len() != want {
            return Err(DataError::OrientationCount {
                robot: robot.name.clone(),
                expected: sensor.describe(),
                given: self.orientations.len(),
                poses: self.qs.len(),
            });
        }
        for (i, r) in self.orientations.iter().enumerate() {
            crate::measure::so3::check_rotation(&matrix(r), ROTATION_TOLERANCE)
                .map_err(|reason| DataError::NotARotation { pose: i, reason })?;
        }
        Ok(())
    }

    /// Records the robot's name, so that [`Measurements::check`] refuses the
    /// measurements for another robot (as [`simulate()`] does).
    #[must_use]
    pub fn of_robot(mut self, name: &str) -> Self {
        self.robot = Some(name.to_string());
        self
    }

    /// The robot's name, if recorded.
    #[must_use]
    pub fn robot(&self) -> Option<&str> {
        self.robot.as_deref()
    }

    /// Number of measured poses.
    #[must_use]
    pub fn len(&self) -> usize {
        self.qs.len()
    }

    /// Whether there are no poses (never true for a validated value).
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.qs.is_empty()
    }

    /// Joint vectors.
    #[must_use]
    pub fn qs(&self) -> &[Vec<f64>] {
        &self.qs
    }

    /// Measured points, [`Measurements::markers`] per joint vector
    /// (pose-major).
    #[must_use]
    pub fn points(&self) -> &[[f64; 3]] {
        &self.points
    }

    /// Pose `i`'s observation, as a sensor reads it
    /// ([`crate::measure::Sensor::encode`]). Panics if `i ≥ len()`.
    #[must_use]
    pub fn observation(&self, i: usize) -> Observation<'_> {
        let k = self.markers;
        Observation {
            points: &self.points[k * i..k * (i + 1)],
            orientation: self.orientations.get(i),
            tag: None,
        }
    }

    /// Measured orientations (row-major rotation matrices), one per joint
    /// vector for a full-pose robot, empty for a point robot.
    #[must_use]
    pub fn orientations(&self) -> &[[[f64; 3]; 3]] {
        &self.orientations
    }
}

/// The JSON form of [`Measurements`]: orientations as matrices or as
/// quaternions.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MeasurementsFile {
    #[serde(default)]
    robot: Option<String>,
    qs: Vec<Vec<f64>>,
    #[serde(default = "one")]
    markers: usize,
    points: Vec<Vec<f64>>,
    #[serde(default)]
    orientations: Vec<[[f64; 3]; 3]>,
    #[serde(default)]
    quaternions: Vec<[f64; 4]>,
}

impl TryFrom<MeasurementsFile> for Measurements {
    type Error = String;

    fn try_from(f: MeasurementsFile) -> std::result::Result<Self, String> {
        if !f.quaternions.is_empty() && !f.orientations.is_empty() {
            return Err("give `orientations` or `quaternions`, not both".into());
        }
        let mut orientations = f.orientations;
        for (i, q) in f.quaternions.iter().enumerate() {
            let norm = q.iter().map(|v| v * v).sum::<f64>().sqrt();
            if !norm.is_finite() || (norm - 1.0).abs() > ROTATION_TOLERANCE {
                return Err(format!(
                    "quaternion {i}: norm {norm} is not 1 (to {ROTATION_TOLERANCE:e}); expected [w, x, y, z] of a rotation"
                ));
            }
            let uq = nalgebra::UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(
                q[0], q[1], q[2], q[3],
            ));
            orientations.push(rows(uq.to_rotation_matrix().matrix()));
        }
        if f.markers == 0 {
            return Err("`markers` must be at least 1 (points per pose)".into());
        }
        let mut points = Vec::with_capacity(f.points.len());
        for (i, p) in f.points.iter().enumerate() {
            let &[x, y, z] = p.as_slice() else {
                return Err(format!(
                    "point {i}: expected 3 coordinates [x, y, z], got {}",
                    p.len()
                ));
            };
            points.push([x, y, z]);
        }
        Ok(Self {
            robot: f.robot,
            qs: f.qs,
            markers: f.markers,
            points,
            orientations,
        })
    }
}

/// A row-major `[[f64; 3]; 3]` as a matrix.
pub(crate) fn matrix(r: &[[f64; 3]; 3]) -> nalgebra::Matrix3<f64> {
    nalgebra::Matrix3::from_fn(|i, j| r[i][j])
}

/// A matrix as row-major `[[f64; 3]; 3]`.
pub(crate) fn rows(m: &nalgebra::Matrix3<f64>) -> [[f64; 3]; 3] {
    std::array::from_fn(|i| std::array::from_fn(|j| m[(i, j)]))
}

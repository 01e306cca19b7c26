//! Held-out validation poses: drawn from a pool outside the designs, and the
//! real robot's errors there before and after calibration (measured, and as
//! the predicted covariance implies).
//!
//! Errors are in the sensor's own terms: the tool point's error over the
//! coordinates the sensor reads ([`crate::measure::Sensor::point_coordinates`]:
//! all three for a point, a pose or markers; `z` alone for a height gauge,
//! whose `x` and `y` no calibration can observe), and the orientation error
//! for sensors that observe it.

use super::VALIDATION_STREAM;
use crate::blocks::jacobian_of;
use crate::identify::{IdentifyError, Result};
use crate::kinematics::{pose, position};
use crate::linalg::gram::product;
use crate::measure::so3;
use crate::measure::{RowKind, sensor_for};
use crate::model::{ParamTable, Robot};
use crate::pool::Pool;
use faer::Mat;
use nalgebra::{UnitQuaternion, Vector3};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::Serialize;

/// Held-out poses and the real robot's end points (and, for a full-pose
/// robot, end orientations) there, with the coordinates of the end point
/// the robot's sensor reads.
#[derive(Clone, Debug, Serialize)]
pub struct ValidationSet {
    /// Lattice indices of the poses, when they come from a pool.
    pub lattice_indices: Vec<usize>,
    /// Joint vectors.
    pub qs: Vec<Vec<f64>>,
    #[serde(skip)]
    truth: Vec<Vector3<f64>>,
    /// True orientations; empty for a point robot.
    #[serde(skip)]
    truth_rot: Vec<UnitQuaternion<f64>>,
    /// The coordinates of the end point the sensor reads (indices into
    /// `x y z`); the others' errors are not counted.
    #[serde(skip)]
    coordinates: &'static [usize],
}

impl ValidationSet {
    /// `n` distinct pool poses drawn uniformly (seeded) from those whose pool
    /// positions are not in `exclude`. Errors when fewer than `n` remain.
    pub fn sample(
        robot: &Robot,
        pool: &Pool,
        exclude: &[usize],
        n: usize,
        seed: u64,
    ) -> Result<ValidationSet> {
        let mut taken = vec![false; pool.len()];
        for &k in exclude {
            if k >= pool.len() {
                return Err(IdentifyError::Design {
                    name: "validation".into(),
                    reason: format!("pool position {k} is outside the pool of {}", pool.len()),
                });
            }
            taken[k] = true;
        }
        let mut free: Vec<usize> = (0..pool.len()).filter(|&k| !taken[k]).collect();
        if free.len() < n {
            return Err(IdentifyError::Setting {
                name: "validation_poses",
                value: n.to_string(),
                reason: "more validation poses than pool poses outside the designs",
            });
        }
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        rng.set_stream(VALIDATION_STREAM);
        // Partial Fisher–Yates: the first n entries are a uniform sample.
        for i in 0..n {
            let j = rng.random_range(i..free.len());
            free.swap(i, j);
        }
        free.truncate(n);
        free.sort_unstable();
        let qs = free.iter().map(|&k| pool.q(k)).collect();
        let mut v = Self::from_qs(robot, qs)?;
        v.lattice_indices = free.iter().map(|&k| pool.ids[k]).collect();
        Ok(v)
    }

    /// Validation at given joint vectors.
    pub fn from_qs(robot: &Robot, qs: Vec<Vec<f64>>) -> Result<ValidationSet> {
        for (i, q) in qs.iter().enumerate() {
            robot
                .check_q(q)
                .map_err(|source| crate::data::DataError::Pose { pose: i, source })?;
        }
        let poses: Vec<_> = qs.iter().map(|q| pose(robot, &robot.real, q)).collect();
        let truth = poses.iter().map(|(_, p)| *p).collect();
        let sensor = sensor_for(robot);
        let truth_rot = if sensor.observes_orientation() {
            poses.iter().map(|(r, _)| so3::to_quaternion(r)).collect()
        } else {
            Vec::new()
        };
        Ok(ValidationSet {
            lattice_indices: Vec::new(),
            qs,
            truth,
            truth_rot,
            coordinates: sensor.point_coordinates(),
        })
    }

    /// Number of poses.
    #[must_use]
    pub fn len(&self) -> usize {
        self.qs.len()
    }

    /// Whether there are no poses.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.qs.is_empty()
    }

    /// The end point's error `p(table, q) − p(real, q)` at a pose whose
    /// true end point is `truth`, over the coordinates the sensor reads (the
    /// others 0).
    fn error(
        &self,
        robot: &Robot,
        table: &ParamTable,
        q: &[f64],
        truth: &Vector3<f64>,
    ) -> Vector3<f64> {
        let mut e = position(robot, table, q) - truth;
        if self.coordinates.len() < 3 {
            for k in 0..3 {
                if !self.coordinates.contains(&k) {
                    e[k] = 0.0;
                }
            }
        }
        e
    }

    /// RMS distance `√(mean ‖p(table, q) − p(real, q)‖²)` over the poses,
    /// over the coordinates the sensor reads (for a height gauge the RMS
    /// height error; 0 for an empty set).
    #[must_use]
    pub fn rms(&self, robot: &Robot, table: &ParamTable) -> f64 {
        if self.qs.is_empty() {
            return 0.0;
        }
        let s: f64 = self
            .qs
            .iter()
            .zip(&self.truth)
            .map(|(q, t)| self.error(robot, table, q, t).norm_squared())
            .sum();
        (s / self.qs.len() as f64).sqrt()
    }

    /// The position error `‖p(table, q) − p(real, q)‖` at every pose, over
    /// the coordinates the sensor reads, metres.
    #[must_use]
    pub fn position_errors(&self, robot: &Robot, table: &ParamTable) -> Vec<f64> {
        self.qs
            .iter()
            .zip(&self.truth)
            .map(|(q, t)| self.error(robot, table, q, t).norm())
            .collect()
    }

    /// The orientation error angle `∠(R(table, q) R(real, q)ᵀ)` at every
    /// pose, radians; empty for a point robot.
    #[must_use]
    pub fn orientation_errors(&self, robot: &Robot, table: &ParamTable) -> Vec<f64> {
        self.qs
            .iter()
            .zip(&self.truth_rot)
            .map(|(q, t)| {
                let (r, _) = pose(robot, table, q);
                so3::difference(&so3::to_quaternion(&r), t).norm()
            })
            .collect()
    }

    /// RMS orientation error `√(mean ∠(R(table, q) R(real, q)ᵀ)²)`, radians,
    /// over the poses; `None` for a point robot (or an empty set).
    #[must_use]
    pub fn orientation_rms(&self, robot: &Robot, table: &ParamTable) -> Option<f64> {
        if self.truth_rot.is_empty() {
            return None;
        }
        let s: f64 = self
            .qs
            .iter()
            .zip(&self.truth_rot)
            .map(|(q, t)| {
                let (r, _) = pose(robot, table, q);
                so3::difference(&so3::to_quaternion(&r), t).norm_squared()
            })
            .sum();
        Some((s / self.qs.len() as f64).sqrt())
    }

    /// The RMS errors the linearised model predicts after calibration with
    /// estimate covariance `c`, from one Jacobian `X_v` of the validation
    /// poses at the real parameters: the position distance `√(tr_pos / n)`
    /// (per measured point; a point's rows are the coordinates the sensor
    /// reads, so a height gauge's is the height error) and, for a full-pose
    /// robot, the orientation angle in radians
    /// `√(tr_ori / n)`, where `tr_pos` and `tr_ori` are the traces of
    /// `X_v C X_vᵀ` over the position rows and over the orientation rows
    /// (divided by [`Robot::orientation_scale`]).
    #[must_use]
    pub fn predicted_rms(&self, robot: &Robot, c: &Mat<f64>) -> (f64, Option<f64>) {
        let sensor = sensor_for(robot);
        let pose = sensor.observes_orientation();
        if self.qs.is_empty() {
            return (0.0, pose.then_some(0.0));
        }
        let x = jacobian_of(robot, &robot.real, self.qs.len(), |k, q| {
            q.copy_from_slice(&self.qs[k])
        });
        let t = x.t();
        let xc = product(x.mat(), c.as_ref());
        let m = x.mat();
        // Traces over the position rows and over the orientation rows (the
        // latter carry the orientation weight w, divided out below).
        let kinds = sensor.row_kinds();
        let weights = sensor.weights();
        let mut tr = [0.0, 0.0];
        for j in 0..m.ncols() {
            for i in 0..m.nrows() {
                tr[usize::from(kinds[i % t] == RowKind::Orientation)] += xc[(i, j)] * m[(i, j)];
            }
        }
        let n = self.qs.len() as f64;
        // Measured points per pose: position rows over the coordinates a
        // point has (several markers per pose share the distance mean over
        // points; a height gauge's one row is its one point).
        let per_pose = kinds.iter().filter(|&&k| k == RowKind::Position).count() as f64
            / sensor.point_coordinates().len() as f64;
        let w = weights
            .iter()
            .zip(kinds)
            .find(|&(_, &k)| k == RowKind::Orientation)
            .map_or(1.0, |(w, _)| *w);
        (
            (tr[0].max(0.0) / (n * per_pose)).sqrt(),
            pose.then(|| (tr[1].max(0.0) / n).sqrt() / w),
        )
    }
}

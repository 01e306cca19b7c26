//! The camera filter of a pool: keep the configurations in which a camera
//! sees its target well ([`crate::measure::camera`]):
//!
//! * at least `min_fraction` of the target's points in front of the camera,
//!   inside its model's field (a fisheye's too: a point behind the camera
//!   or past the angle where the distortion folds back is not seen,
//!   [`crate::measure::pinhole::Intrinsics::sees`]) and inside the image,
//!   `margin_px` pixels or more from its border;
//! * the target facing the camera: the viewing angle (between the target's
//!   z axis and the line of sight, [`crate::measure::camera::View`]) at most
//!   `max_view_angle` (radians; 60° by default: past it corner detectors
//!   lose accuracy fast);
//! * the target's centroid `distance` metres from the camera, within a
//!   range (focus, resolution).
//!
//! Evaluated with the placements the filter is given (the start of a
//! calibration, or a design's assumption) and the build's parameter table.
//! The line of sight against the robot's own collision geometry is a
//! separate check, [`crate::pool::line_of_sight`].

use crate::kinematics::Evaluator;
use crate::measure::camera::{CameraSensor, Mounting, View};
use crate::measure::pinhole::Intrinsics;
use crate::model::{ParamTable, Robot};
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use serde::{Deserialize, Serialize};

/// The default largest viewing angle, degrees.
pub const DEFAULT_MAX_VIEW_ANGLE_DEG: f64 = 60.0;

/// Keeps the configurations in which a camera sees its target well (see
/// the module documentation).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CameraView {
    /// The camera's intrinsics.
    pub intrinsics: Intrinsics,
    /// Where the camera and the target are.
    pub mounting: Mounting,
    /// The target's points, its frame, metres.
    pub points: Vec<[f64; 3]>,
    /// The direction in the target's frame from its seen face into it
    /// (`[0, 0, 1]` for OpenCV's boards, `[0, 0, −1]` for Kalibr's
    /// aprilgrid: [`crate::io::camera_target::Target::face`]); the viewing
    /// angle is measured from it.
    #[serde(default = "into_the_board")]
    pub face: [f64; 3],
    /// The camera's placement in its parent: x, y, z (m), roll, pitch, yaw
    /// (rad, as in URDF).
    pub camera: [f64; 6],
    /// The target's placement in its parent, likewise.
    pub target: [f64; 6],
    /// The fraction of the points that must be seen, in (0, 1].
    pub min_fraction: f64,
    /// How far inside the image a seen point must be, pixels.
    pub margin_px: f64,
    /// The largest viewing angle, radians.
    pub max_view_angle: f64,
    /// The range of the target's distance from the camera, metres.
    pub distance: [f64; 2],
}

/// `+z`: OpenCV's boards are seen from the side their z points away from.
fn into_the_board() -> [f64; 3] {
    [0.0, 0.0, 1.0]
}

/// The placement `X,Y,Z,ROLL,PITCH,YAW` stands for (metres, radians; rpy
/// as in URDF).
#[must_use]
pub fn placement(v: &[f64; 6]) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::new(v[0], v[1], v[2]),
        UnitQuaternion::from_euler_angles(v[3], v[4], v[5]),
    )
}

impl CameraView {
    /// Checks the settings: the intrinsics, at least 4 points, a fraction
    /// in (0, 1], a margin ≥ 0, an angle in (0, π/2], a distance range
    /// `0 ≤ lo < hi`, finite placements. Returns what is wrong.
    pub fn validate(&self) -> Result<(), String> {
        self.intrinsics.check()?;
        if self.points.len() < crate::measure::camera::MIN_POINTS_PER_POSE {
            return Err(format!("{} target points; at least 4", self.points.len()));
        }
        if !(self.min_fraction > 0.0 && self.min_fraction <= 1.0) {
            return Err(format!(
                "fraction of points seen {}: must be in (0, 1]",
                self.min_fraction
            ));
        }
        if !(self.margin_px >= 0.0 && self.margin_px.is_finite()) {
            return Err(format!(
                "margin {} px: must be finite and ≥ 0",
                self.margin_px
            ));
        }
        if !(self.max_view_angle > 0.0 && self.max_view_angle <= std::f64::consts::FRAC_PI_2) {
            return Err(format!(
                "largest viewing angle {}°: must be in (0°, 90°]",
                self.max_view_angle.to_degrees()
            ));
        }
        let [lo, hi] = self.distance;
        if !(lo >= 0.0 && lo < hi) {
            return Err(format!("distance range [{lo}, {hi}] m: need 0 ≤ lo < hi"));
        }
        let finite = |v: &[f64]| v.iter().all(|x| x.is_finite());
        if !(finite(&self.camera) && finite(&self.target) && self.points.iter().all(|p| finite(p)))
        {
            return Err("a placement or a target point is not finite".into());
        }
        if !(finite(&self.face) && Vector3::from(self.face).norm() > 0.0) {
            return Err(format!(
                "the target's face direction {:?} is not a finite non-zero vector",
                self.face
            ));
        }
        Ok(())
    }

    /// The camera sensor and own unknowns of the filter's placements.
    #[must_use]
    pub fn sensor(&self) -> (CameraSensor, Vec<f64>) {
        let (c, t) = (placement(&self.camera), placement(&self.target));
        let pts = self.points.iter().map(|p| Vector3::from(*p)).collect();
        (
            CameraSensor::new(self.intrinsics.clone(), self.mounting, pts, &c, &t)
                .with_margin(self.margin_px)
                .with_face(Vector3::from(self.face)),
            CameraSensor::start_own(&c, &t),
        )
    }

    /// How the camera sees the target at `q` (evaluated at `table`).
    #[must_use]
    pub fn view(&self, robot: &Robot, table: &ParamTable, q: &[f64]) -> View {
        let (s, own) = self.sensor();
        s.view(
            &Evaluator::new(robot, table).end_frame(q),
            &own,
            self.margin_px,
        )
    }

    /// Whether the camera sees the target well at `q`.
    #[must_use]
    pub fn keeps(&self, robot: &Robot, table: &ParamTable, q: &[f64]) -> bool {
        let v = self.view(robot, table, q);
        v.seen as f64 >= self.min_fraction * self.points.len() as f64
            && v.angle <= self.max_view_angle
            && v.distance >= self.distance[0]
            && v.distance <= self.distance[1]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A camera 0.8 m out along the flange's axis at a configuration `q0`,
    /// looking back at a board on the flange: `q0` passes, most random
    /// configurations do not, and every one that passes sees all points
    /// inside the margin, facing the camera within the angle, in the
    /// distance range (checked from the sensor's own predicted pixels).
    #[test]
    fn kept_configurations_see_the_target() {
        use nalgebra::Rotation3;
        let robot = Robot::ur5();
        let q0 = [0.3, -1.2, 1.0, -0.5, 0.8, 0.2];
        let e = Evaluator::new(&robot, &robot.nominal).end_frame(&q0);
        let axis = e.rotation.column(2).into_owned();
        // Camera z against the flange's z; the board's z (into it) away from
        // the camera, along the flange's −z.
        let rc = Rotation3::from_matrix_unchecked(e.rotation)
            * Rotation3::from_euler_angles(std::f64::consts::PI, 0.0, 0.0);
        let (r, p, y) = rc.euler_angles();
        let eye = e.position + 0.8 * axis;
        let board: Vec<[f64; 3]> = (0..20)
            .map(|k| [0.02 * (k % 5) as f64, 0.02 * (k / 5) as f64, 0.0])
            .collect();
        let f = CameraView {
            intrinsics: Intrinsics {
                width: 1280,
                height: 960,
                fx: 900.0,
                fy: 900.0,
                cx: 640.0,
                cy: 480.0,
                distortion: crate::measure::pinhole::Distortion::PlumbBob([0.0; 5]),
            },
            mounting: Mounting::EyeToHand,
            points: board,
            face: into_the_board(),
            camera: [eye.x, eye.y, eye.z, r, p, y],
            target: [-0.04, -0.03, 0.01, std::f64::consts::PI, 0.0, 0.0],
            min_fraction: 1.0,
            margin_px: 10.0,
            max_view_angle: DEFAULT_MAX_VIEW_ANGLE_DEG.to_radians(),
            distance: [0.3, 1.5],
        };
        f.validate().unwrap();
        assert!(
            f.keeps(&robot, &robot.nominal, &q0),
            "{:?}",
            f.view(&robot, &robot.nominal, &q0)
        );
        let qs = crate::observability::generic_configurations(&robot, 5000, 3);
        let kept: Vec<&Vec<f64>> = qs
            .iter()
            .filter(|q| f.keeps(&robot, &robot.nominal, q))
            .collect();
        assert!(kept.len() < qs.len() / 2, "{} of {}", kept.len(), qs.len());
        let (s, own) = f.sensor();
        let mut ev = Evaluator::new(&robot, &robot.nominal);
        for q in kept {
            let e = ev.end_frame(q);
            let v = s.view(&e, &own, 10.0);
            assert!(v.angle <= 60f64.to_radians() && (0.3..=1.5).contains(&v.distance));
            let mut pred = vec![0.0; 60];
            crate::measure::Sensor::predict(&s, &e, &own, &mut pred);
            for p in pred.chunks_exact(3) {
                assert!(
                    p[2] == 1.0 && (10.0 - 0.5..=1280.0 - 10.5).contains(&p[0]),
                    "{p:?}"
                );
            }
        }
        let mut bad = f.clone();
        bad.max_view_angle = 2.0;
        assert!(bad.validate().unwrap_err().contains("viewing angle"));
    }
}

//! The line of sight of a camera pool ([`super::camera_view`]): a
//! configuration is kept when enough of the target's points are both inside
//! the image (with the view's margin) and in sight, the straight segment
//! from the camera's centre to the point crossing none of the robot's
//! collision geometry ([`crate::collision`]'s model, loaded from the URDF's
//! `<collision>` elements as the self-collision filter loads it) nor an
//! obstacle of its spec.
//!
//! Each segment stops [`DEFAULT_STOP`] (1 mm) short of its point, so that a
//! ray ending on the target's own surface is not blocked by it; the link
//! the target (eye-to-hand) or the camera (eye-in-hand) is mounted on — the
//! chain's tip and every link fixed to it — is not checked: the board or
//! camera is fixed to it, and a flange behind the board is already excluded
//! by the viewing angle. Moving links past the tip (gripper fingers) are
//! checked.

use crate::collision::{CollisionFilter, CollisionModel, CollisionSpec};
use crate::kinematics::Evaluator;
use crate::measure::camera::Mounting;
use crate::model::{ParamTable, Robot};
use crate::pool::camera_view::{CameraView, placement};
use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion};
use std::sync::Arc;

/// How far short of a target point a ray stops, metres.
pub const DEFAULT_STOP: f64 = 1e-3;

/// The line-of-sight check of a camera pool (see the module documentation).
#[derive(Clone, Debug)]
pub struct LineOfSight {
    /// The collision model's spec (its URDF, chain, package directories,
    /// obstacles); its pairs and clearance are not used.
    pub collision: CollisionFilter,
    /// How far short of each point a ray stops, metres (≥ 0).
    pub stop: f64,
    /// A camera on the robot's own link (a head camera,
    /// [`crate::io::urdf_branch`]): the link, whose frame is the camera
    /// chain's base (the rays are cast from it, and its rigid body is not
    /// checked). `None`: the rays are in the collision model's base link.
    pub camera_link: Option<String>,
}

/// The lines of sight a [`LineOfSight`] checked at one configuration.
#[derive(Clone, Debug)]
pub struct SightLines {
    /// The camera's centre (base frame).
    pub eye: Point3<f64>,
    /// The target's points (base frame).
    pub points: Vec<Point3<f64>>,
    /// Per point: inside the image (with the view's margin).
    pub inside: Vec<bool>,
    /// Per point: the ray from the camera is blocked.
    pub blocked: Vec<bool>,
}

impl SightLines {
    /// Per point: seen inside the image and in sight.
    #[must_use]
    pub fn seen(&self) -> Vec<bool> {
        self.inside
            .iter()
            .zip(&self.blocked)
            .map(|(i, b)| *i && !*b)
            .collect()
    }
}

/// The points of the target and the camera's centre in the base frame at
/// `q`, and which points the camera sees (in front, inside its model's
/// field and the image with the margin).
#[must_use]
pub fn rays(
    view: &CameraView,
    robot: &Robot,
    table: &ParamTable,
    q: &[f64],
) -> (Point3<f64>, Vec<Point3<f64>>, Vec<bool>) {
    let e = Evaluator::new(robot, table).end_frame(q);
    let end = Isometry3::from_parts(
        Translation3::from(e.position),
        UnitQuaternion::from_matrix(&e.rotation),
    );
    let (cam, tgt) = (placement(&view.camera), placement(&view.target));
    let (cam, tgt) = match view.mounting {
        Mounting::EyeToHand => (cam, end * tgt),
        Mounting::EyeInHand => (end * cam, tgt),
    };
    let pts: Vec<Point3<f64>> = view
        .points
        .iter()
        .map(|p| tgt * Point3::new(p[0], p[1], p[2]))
        .collect();
    let field = view.intrinsics.field_angle();
    let inside = pts
        .iter()
        .map(|p| {
            let x = cam.inverse_transform_point(p).coords;
            view.intrinsics.sees(&x, field, view.margin_px).is_some()
        })
        .collect();
    (Point3::from(cam.translation.vector), pts, inside)
}

impl LineOfSight {
    /// The check against the model of `spec` (loaded on first use), rays
    /// stopping [`DEFAULT_STOP`] short.
    #[must_use]
    pub fn new(spec: CollisionSpec) -> Self {
        Self {
            collision: CollisionFilter::new(spec),
            stop: DEFAULT_STOP,
            camera_link: None,
        }
    }

    /// The check for a camera on the robot's own link `link`, the base of
    /// the camera chain whose configurations it is given (see
    /// [`LineOfSight::camera_link`]); `spec` drives the same joints, by
    /// name, in the whole tree.
    #[must_use]
    pub fn from_link(spec: CollisionSpec, link: &str) -> Self {
        Self {
            camera_link: Some(link.to_string()),
            ..Self::new(spec)
        }
    }

    /// The loaded model, or why it cannot be loaded (or lacks the camera's
    /// link).
    pub fn load(&self) -> Result<Arc<CollisionModel>, String> {
        let m = self.collision.load()?;
        match &self.camera_link {
            Some(l) if !m.has_link(l) => Err(format!(
                "{}: no link '{l}' for the camera",
                self.collision.spec.urdf
            )),
            _ => Ok(m),
        }
    }

    /// The lines of sight at `q`: the camera's centre, the target's
    /// points, which of them are inside the image and which rays the
    /// robot or an obstacle blocks (base frame of `robot`). `None` when the
    /// model cannot be loaded ([`LineOfSight::load`] says why).
    #[must_use]
    pub fn sight_lines(
        &self,
        view: &CameraView,
        robot: &Robot,
        table: &ParamTable,
        q: &[f64],
    ) -> Option<SightLines> {
        let model = self.load().ok()?;
        let (eye, points, inside) = rays(view, robot, table, q);
        let blocked = match &self.camera_link {
            Some(l) => model
                .blocked_rays_from_link(q, l, &eye, &points, self.stop)
                .unwrap_or_else(|| vec![true; points.len()]),
            None => model.blocked_rays(q, &eye, &points, self.stop, true),
        };
        Some(SightLines {
            eye,
            points,
            inside,
            blocked,
        })
    }

    /// For each target point at `q`: seen inside the image and in sight.
    /// Empty when the model cannot be loaded ([`LineOfSight::load`] says why).
    #[must_use]
    pub fn seen_in_sight(
        &self,
        view: &CameraView,
        robot: &Robot,
        table: &ParamTable,
        q: &[f64],
    ) -> Vec<bool> {
        self.sight_lines(view, robot, table, q)
            .map(|s| s.seen())
            .unwrap_or_default()
    }

    /// Whether at least the view's fraction of the target's points are seen
    /// and in sight at `q` (the view's other tests are
    /// [`CameraView::keeps`]'s).
    #[must_use]
    pub fn keeps(&self, view: &CameraView, robot: &Robot, table: &ParamTable, q: &[f64]) -> bool {
        let n = self
            .seen_in_sight(view, robot, table, q)
            .iter()
            .filter(|s| **s)
            .count();
        n > 0 && n as f64 >= view.min_fraction * view.points.len() as f64
    }
}

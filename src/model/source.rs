//! Where a robot model came from, kept beside it: the URDF file a chain was
//! imported from, its text, and the chain as the file gives it (each joint's
//! own origin and axis), with the measurement frame and tool the model was
//! mounted with. Pure data: [`crate::io::urdf`] fills it, the calibrated
//! frames ([`crate::frames`]) read it, and the URDF writer edits its text.

use super::JointKind;
use nalgebra::{Isometry3, Rotation3, Translation3, Unit, UnitQuaternion, Vector3};

/// One joint of the chain as the URDF file gives it, fixed and locked
/// joints included.
#[derive(Clone, Debug, PartialEq)]
pub struct SourceJoint {
    /// The URDF joint's name.
    pub name: String,
    /// Revolute (continuous included) or prismatic; `None` for a fixed joint.
    pub kind: Option<JointKind>,
    /// The `<origin>` of the joint: parent link → joint frame.
    pub origin: Isometry3<f64>,
    /// Unit axis in the joint frame (ignored for a fixed joint).
    pub axis: Vector3<f64>,
    /// The value a moving joint is held at (`--lock`), if it is.
    pub locked: Option<f64>,
}

impl SourceJoint {
    /// Whether the joint moves in the model (a moving joint not locked).
    #[must_use]
    pub fn is_driven(&self) -> bool {
        self.kind.is_some() && self.locked.is_none()
    }

    /// The joint's motion at value `q`: a rotation about its axis, or a
    /// translation along it; identity for a fixed joint.
    #[must_use]
    pub fn motion(&self, q: f64) -> Isometry3<f64> {
        match self.kind {
            None => Isometry3::identity(),
            Some(JointKind::Revolute) => Isometry3::from_parts(
                Translation3::identity(),
                UnitQuaternion::from_axis_angle(&Unit::new_normalize(self.axis), q),
            ),
            Some(JointKind::Prismatic) => Isometry3::from_parts(
                Translation3::from(self.axis.normalize() * q),
                UnitQuaternion::identity(),
            ),
        }
    }

    /// The joint's fixed transform in a chain: its origin, and for a locked
    /// joint its motion at the held value.
    #[must_use]
    pub fn fixed_part(&self) -> Isometry3<f64> {
        match self.locked {
            Some(v) => self.origin * self.motion(v),
            None => self.origin,
        }
    }
}

/// The URDF a robot's chain was imported from.
#[derive(Clone, Debug, PartialEq)]
pub struct UrdfSource {
    /// The file, as named on import.
    pub path: String,
    /// The file's text, as read (a calibrated URDF is this text with only
    /// the chain's origins changed).
    pub text: String,
    /// The chain's base link.
    pub base: String,
    /// The chain's tip link.
    pub tip: String,
    /// The joints from the base link to the tip link, in order.
    pub joints: Vec<SourceJoint>,
    /// The measurement frame the model was mounted in: measurement frame →
    /// base link (identity unless a frames file gave one).
    pub mount: Isometry3<f64>,
    /// The tool: tip link → measured frame (identity unless a frames file
    /// gave one).
    pub tool: Isometry3<f64>,
    /// The chain's driven joints that the file's tree walks the other way
    /// (a chain from a camera's link down to a branch point and up to an
    /// arm's tip, [`crate::io::urdf_branch`]); empty for a chain from the
    /// root.
    pub reversed: Vec<Reversed>,
}

/// A driven joint of a chain walked against the file's tree, from child
/// link to parent link. Its motion is the file's joint's inverse (the
/// chain's axis is the file's negated, its value the file's), and its
/// origin in the chain is the inverse of the `<origin>` of the file's
/// joint on its other side (`neighbour`): a calibrated chain writes that
/// joint's origin.
#[derive(Clone, Debug, PartialEq)]
pub struct Reversed {
    /// The joint's name (the chain's and the file's).
    pub joint: String,
    /// The driven joint of the file whose child link is this joint's
    /// parent link (the previous joint of the chain), as the file gives
    /// it; `None` for the chain's first joint, whose origin the split
    /// keeps as it is ([`crate::frames::gauge`]) and nothing writes.
    pub neighbour: Option<SourceJoint>,
}

impl UrdfSource {
    /// The names of the driven joints, in configuration order.
    #[must_use]
    pub fn driven_names(&self) -> Vec<String> {
        self.joints
            .iter()
            .filter(|j| j.is_driven())
            .map(|j| j.name.clone())
            .collect()
    }
}

/// URDF `rpy` (fixed-axis roll, pitch, yaw: `R = Rz(yaw) Ry(pitch) Rx(roll)`)
/// of a rotation. Yaw comes first from `atan2(R10, R00)` (any value will do
/// at gimbal lock, where it is ill-determined), then pitch and roll from
/// `Rz(−yaw) R = Ry(pitch) Rx(roll)`, whose entries are all of order 1, so
/// the angles rebuild the rotation to rounding everywhere, gimbal lock
/// included.
#[must_use]
pub fn rpy(r: &Rotation3<f64>) -> [f64; 3] {
    let m = r.matrix();
    let yaw = m[(1, 0)].atan2(m[(0, 0)]);
    let (sy, cy) = yaw.sin_cos();
    let pitch = (-m[(2, 0)]).atan2(cy * m[(0, 0)] + sy * m[(1, 0)]);
    let roll = (sy * m[(0, 2)] - cy * m[(1, 2)]).atan2(cy * m[(1, 1)] - sy * m[(0, 1)]);
    [roll, pitch, yaw]
}

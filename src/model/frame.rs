//! The frame law, once: a frame's transform is the product of elementary
//! motions `Rz(q + γ) · Tz(d) · Tx(a) · Rx(α) · Ry(β)` (β only for Hayati
//! frames; a prismatic joint moves `Tz(q + d)` instead and leaves `Rz(γ)`; a
//! fixed frame has no `q`). The kinematics walk, the joint-chain split used
//! by the outside cross-checks, and the URDF importer all take the motions
//! from [`Frame::motion`].

use super::{Convention, Frame, JointKind};
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};

/// The elementary motions of one frame at given joint values, in the order
/// they act.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameMotion {
    /// Rotation about the base z axis: `q + γ` (revolute or fixed), `γ`
    /// (prismatic).
    pub theta: f64,
    /// Translation along the base z axis: `d` (revolute or fixed), `q + d`
    /// (prismatic).
    pub d: f64,
    /// Translation along the rotated x axis.
    pub a: f64,
    /// Rotation about that x axis.
    pub alpha: f64,
    /// Rotation about the new y axis (Hayati frames only).
    pub beta: Option<f64>,
}

impl Frame {
    /// The frame's motions for the parameter row `[γ, α, a, d, β]` and joint
    /// vector `q` (only `q[joint]` is read; a fixed frame reads none).
    #[inline]
    #[must_use]
    pub fn motion(&self, row: &[f64; 5], q: &[f64]) -> FrameMotion {
        let [gamma, alpha, a, d, beta] = *row;
        let (theta, d) = match (self.joint, self.joint_kind) {
            (Some(j), JointKind::Prismatic) => (gamma, q[j] + d),
            (Some(j), JointKind::Revolute) => (q[j] + gamma, d),
            (None, _) => (gamma, d),
        };
        FrameMotion {
            theta,
            d,
            a,
            alpha,
            beta: (self.convention == Convention::Hayati).then_some(beta),
        }
    }

    /// The frame's motions with its joint at zero.
    #[must_use]
    pub fn motion_at_zero(&self, row: &[f64; 5]) -> FrameMotion {
        let [gamma, alpha, a, d, beta] = *row;
        FrameMotion {
            theta: gamma,
            d,
            a,
            alpha,
            beta: (self.convention == Convention::Hayati).then_some(beta),
        }
    }
}

impl FrameMotion {
    /// `Rz(θ)`: the part before the joint's own motion.
    #[must_use]
    pub fn rotation_z(&self) -> Isometry3<f64> {
        rotation(Vector3::z_axis(), self.theta)
    }

    /// Multiplies `acc` on the right by `Tz(d) Tx(a) Rx(α) Ry(β)`, the part
    /// after `Rz(θ)`, one factor at a time. A revolute joint's `Rz(q)` and a
    /// prismatic joint's `Tz(q)` both commute with `Rz(γ)` and `Tz(d)`, so a
    /// joint acts between [`FrameMotion::rotation_z`] and this.
    pub fn apply_after_rotation_z(&self, acc: &mut Isometry3<f64>) {
        *acc *= Isometry3::from_parts(
            Translation3::new(self.a, 0.0, self.d),
            UnitQuaternion::from_axis_angle(&Vector3::x_axis(), self.alpha),
        );
        if let Some(beta) = self.beta {
            *acc *= rotation(Vector3::y_axis(), beta);
        }
    }

    /// The whole transform `Rz(θ) Tz(d) Tx(a) Rx(α) Ry(β)`.
    #[must_use]
    pub fn isometry(&self) -> Isometry3<f64> {
        let mut t = self.rotation_z();
        self.apply_after_rotation_z(&mut t);
        t
    }
}

fn rotation(axis: nalgebra::Unit<Vector3<f64>>, angle: f64) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::identity(),
        UnitQuaternion::from_axis_angle(&axis, angle),
    )
}

/// The transform of a frame of `convention` with parameter row `row` and its
/// joint (if any) at zero.
#[must_use]
pub fn frame_transform(convention: Convention, row: &[f64; 5]) -> Isometry3<f64> {
    Frame::fixed("_", convention).motion_at_zero(row).isometry()
}

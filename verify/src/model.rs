//! Pinocchio and MuJoCo models of any [`Robot`]: fixed placements before
//! joints along z, and an end-effector frame at the measured point,
//! `T(q) = P_0 M_0(q_0) P_1 M_1(q_1) … P_{n−1} M_{n−1}(q_{n−1}) · tool`, where
//! `M_k(q) = Rz(q)` for a revolute joint and `Tz(q)` for a prismatic one.
//!
//! The placements are built here from the robot's DH / Hayati parameters,
//! **independently of `activecal::kinematics`** (textbook homogeneous
//! matrices instead of its rotation kernels and `joint_chain`): if the
//! libraries were fed activecal's own chain, a wrong kinematic detail would
//! be copied into the references and the cross-check could not see it.
//!
//! Frame transform (see `activecal::robot`): DH `Rz(q+γ) Tz(d) Tx(a) Rx(α)`,
//! Hayati the same followed by `Ry(β)`; a prismatic frame `Rz(γ) Tz(q+d) …`;
//! a fixed frame has `q = 0`.

use activecal::model::{Convention, JointKind, ParamTable, Robot};
use anyhow::{Result, bail};
use nalgebra::{Matrix3, Matrix4, Rotation3, UnitQuaternion, Vector3};
use serde::Serialize;
use std::fmt::Write;

/// A rigid transform: `x ↦ rotation · x + translation`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Placement {
    /// Rotation matrix, row-major (`rotation[r][c]`).
    pub rotation: [[f64; 3]; 3],
    /// Translation (metres).
    pub translation: [f64; 3],
}

impl Placement {
    /// The placement of a homogeneous 4 × 4 matrix.
    #[must_use]
    pub fn from_homogeneous(m: &Matrix4<f64>) -> Self {
        let mut rotation = [[0.0; 3]; 3];
        for (r, row) in rotation.iter_mut().enumerate() {
            for (c, v) in row.iter_mut().enumerate() {
                *v = m[(r, c)];
            }
        }
        Placement {
            rotation,
            translation: [m[(0, 3)], m[(1, 3)], m[(2, 3)]],
        }
    }

    /// The homogeneous 4 × 4 matrix of this placement.
    #[must_use]
    pub fn homogeneous(&self) -> Matrix4<f64> {
        let mut m = Matrix4::identity();
        for r in 0..3 {
            for c in 0..3 {
                m[(r, c)] = self.rotation[r][c];
            }
            m[(r, 3)] = self.translation[r];
        }
        m
    }

    /// The rotation as a unit quaternion `(w, x, y, z)` (MJCF's `quat` order;
    /// nalgebra stores `i j k w`).
    #[must_use]
    pub fn quat_wxyz(&self) -> [f64; 4] {
        let m = Matrix3::from_fn(|r, c| self.rotation[r][c]);
        let q = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(m));
        [q.w, q.i, q.j, q.k]
    }
}

/// A robot as fixed placements and joints along z: what Pinocchio's
/// `addJoint(parent, JointModelRZ() or JointModelPZ(), placement)` and
/// MuJoCo's nested bodies with hinge or slide joints are built from.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ModelSpec {
    /// Robot name.
    pub robot: String,
    /// `placements[k]`: from joint k−1's moving frame (the measurement frame
    /// for k = 0) to joint k's frame before its motion `M_k(q_k)`.
    pub placements: Vec<Placement>,
    /// `kinds[k]`: joint k rotates about (revolute) or slides along
    /// (prismatic) the z axis of its placement frame.
    pub kinds: Vec<JointKind>,
    /// From the last joint's moving frame to the end-effector frame, whose
    /// origin is the measured point.
    pub tool: Placement,
}

impl ModelSpec {
    /// Number of joints.
    #[must_use]
    pub fn dof(&self) -> usize {
        self.placements.len()
    }

    /// End-effector transform `T(q)` as a homogeneous matrix (a plain-Rust
    /// evaluation of the spec, to test the spec itself without Python).
    #[must_use]
    pub fn transform(&self, q: &[f64]) -> Matrix4<f64> {
        assert_eq!(q.len(), self.dof(), "joint vector length");
        let mut t = Matrix4::<f64>::identity();
        for ((p, &kind), &qk) in self.placements.iter().zip(&self.kinds).zip(q) {
            t = t * p.homogeneous() * joint_motion(kind, qk);
        }
        t * self.tool.homogeneous()
    }
}

/// Textbook DH matrix `Rz(θ) Tz(d) Tx(a) Rx(α)`.
#[must_use]
fn dh(theta: f64, d: f64, a: f64, alpha: f64) -> Matrix4<f64> {
    let (st, ct) = theta.sin_cos();
    let (sa, ca) = alpha.sin_cos();
    #[rustfmt::skip]
    let m = Matrix4::new(
        ct, -st * ca,  st * sa, a * ct,
        st,  ct * ca, -ct * sa, a * st,
        0.0,      sa,       ca,      d,
        0.0,     0.0,      0.0,    1.0,
    );
    m
}

/// `Rz(θ)` as a homogeneous matrix.
#[must_use]
fn rz(theta: f64) -> Matrix4<f64> {
    dh(theta, 0.0, 0.0, 0.0)
}

/// `Tz(s)` as a homogeneous matrix.
#[must_use]
fn tz(s: f64) -> Matrix4<f64> {
    dh(0.0, s, 0.0, 0.0)
}

/// The motion of a joint at value `q`: `Rz(q)` or `Tz(q)`.
#[must_use]
pub fn joint_motion(kind: JointKind, q: f64) -> Matrix4<f64> {
    match kind {
        JointKind::Revolute => rz(q),
        JointKind::Prismatic => tz(q),
    }
}

/// `Ry(β)` as a homogeneous matrix.
#[must_use]
fn ry(beta: f64) -> Matrix4<f64> {
    let (s, c) = beta.sin_cos();
    #[rustfmt::skip]
    let m = Matrix4::new(
          c, 0.0,   s, 0.0,
        0.0, 1.0, 0.0, 0.0,
         -s, 0.0,   c, 0.0,
        0.0, 0.0, 0.0, 1.0,
    );
    m
}

/// The Pinocchio (and MuJoCo) model of `robot` with parameters `table`: one
/// placement before each joint, in joint order, and the tool placement.
///
/// Fixed frames are folded into the neighbouring placements; a revolute
/// frame `Rz(q+γ) B` contributes `Rz(γ)` to the placement before its joint
/// and `B = Tz(d) Tx(a) Rx(α) [Ry(β)]` after it, and so does a prismatic
/// frame `Rz(γ) Tz(q) B`. Fails if joints do not drive frames in increasing
/// joint order (0, 1, …, dof−1), the only layout a serial chain of nested
/// bodies can express without renumbering.
pub fn pinocchio_model_spec(robot: &Robot, table: &ParamTable) -> Result<ModelSpec> {
    if table.rows.len() != robot.frames.len() {
        bail!(
            "parameter table has {} rows for {} frames",
            table.rows.len(),
            robot.frames.len()
        );
    }
    let mut placements = Vec::with_capacity(robot.dof());
    let mut kinds = Vec::with_capacity(robot.dof());
    let mut acc = Matrix4::identity();
    for (frame, row) in robot.frames.iter().zip(&table.rows) {
        let [gamma, alpha, a, d, beta] = *row;
        let twist = match frame.convention {
            Convention::Dh => Matrix4::identity(),
            Convention::Hayati => ry(beta),
        };
        match frame.joint {
            None => acc = acc * dh(gamma, d, a, alpha) * twist,
            Some(j) => {
                if j != placements.len() {
                    bail!(
                        "frame {} is driven by joint {} but joint {} comes next",
                        frame.label,
                        j + 1,
                        placements.len() + 1
                    );
                }
                placements.push(Placement::from_homogeneous(&(acc * rz(gamma))));
                kinds.push(frame.joint_kind);
                acc = dh(0.0, d, a, alpha) * twist;
            }
        }
    }
    if placements.len() != robot.dof() {
        bail!(
            "{} frames are driven but the robot has {} joints",
            placements.len(),
            robot.dof()
        );
    }
    Ok(ModelSpec {
        robot: robot.name.clone(),
        placements,
        kinds,
        tool: Placement::from_homogeneous(&acc),
    })
}

/// Shortest decimal that parses back to the same `f64` (Rust's `{:?}`).
fn num(x: f64) -> String {
    // -0.0 prints as "-0.0"; MuJoCo reads it, but plain 0 is tidier.
    if x == 0.0 {
        "0".into()
    } else {
        format!("{x:?}")
    }
}

fn nums(xs: &[f64]) -> String {
    xs.iter().map(|&x| num(x)).collect::<Vec<_>>().join(" ")
}

/// An MJCF document for MuJoCo: nested bodies `link1 … linkN` with `pos` /
/// `quat` from [`pinocchio_model_spec`], a joint `q1 … qN` along the body's
/// z axis in each (`hinge` if revolute, `slide` if prismatic), a unit
/// inertial (MuJoCo refuses moving bodies without mass), and a site `ee` at
/// the end effector. Numbers are printed
/// as the shortest decimal that round-trips, so the model is exact up to
/// MuJoCo's quaternion normalization.
pub fn mjcf(robot: &Robot, table: &ParamTable) -> Result<String> {
    Ok(mjcf_of_spec(&pinocchio_model_spec(robot, table)?))
}

/// The MJCF of a model spec (see [`mjcf`]).
#[must_use]
pub fn mjcf_of_spec(spec: &ModelSpec) -> String {
    let mut s = String::new();
    let name = spec.robot.replace(['"', '<', '>', '&'], "_");
    writeln!(s, "<mujoco model=\"{name}\">").unwrap();
    writeln!(s, "  <compiler angle=\"radian\"/>").unwrap();
    writeln!(s, "  <option gravity=\"0 0 0\"/>").unwrap();
    writeln!(s, "  <worldbody>").unwrap();
    let mut indent = String::from("    ");
    for (k, (p, kind)) in spec.placements.iter().zip(&spec.kinds).enumerate() {
        writeln!(
            s,
            "{indent}<body name=\"link{}\" pos=\"{}\" quat=\"{}\">",
            k + 1,
            nums(&p.translation),
            nums(&p.quat_wxyz())
        )
        .unwrap();
        indent.push_str("  ");
        let kind = match kind {
            JointKind::Revolute => "hinge",
            JointKind::Prismatic => "slide",
        };
        writeln!(
            s,
            "{indent}<joint name=\"q{}\" type=\"{kind}\" pos=\"0 0 0\" axis=\"0 0 1\"/>",
            k + 1
        )
        .unwrap();
        writeln!(
            s,
            "{indent}<inertial pos=\"0 0 0\" mass=\"1\" diaginertia=\"0.01 0.01 0.01\"/>"
        )
        .unwrap();
    }
    writeln!(
        s,
        "{indent}<site name=\"ee\" pos=\"{}\" quat=\"{}\"/>",
        nums(&spec.tool.translation),
        nums(&spec.tool.quat_wxyz())
    )
    .unwrap();
    for _ in &spec.placements {
        indent.truncate(indent.len() - 2);
        writeln!(s, "{indent}</body>").unwrap();
    }
    writeln!(s, "  </worldbody>").unwrap();
    writeln!(s, "</mujoco>").unwrap();
    s
}

/// Position of the end point of a spec at `q` (the translation of
/// [`ModelSpec::transform`]).
#[must_use]
pub fn spec_position(spec: &ModelSpec, q: &[f64]) -> Vector3<f64> {
    let t = spec.transform(q);
    Vector3::new(t[(0, 3)], t[(1, 3)], t[(2, 3)])
}

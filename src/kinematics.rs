//! Forward kinematics and the analytic identification Jacobian of a [`Robot`].
//!
//! A frame's transform is the product of elementary motions
//! `Rz(q+γ) · Tz(d) · Tx(a) · Rx(α) · Ry(β)` (β only for Hayati frames). The
//! derivative of the end point `p` with respect to each parameter is the
//! velocity of `p` under the corresponding elementary motion, expressed in the
//! measurement frame: for a rotation about a unit axis `u` through a point `o`
//! it is `u × (p − o)`, for a translation along `u` it is `u`.

use crate::error::Result;
use crate::robot::{Convention, ParamTable, Robot, Symbol};
use nalgebra::{Isometry3, Matrix3, Translation3, UnitQuaternion, Vector3};

/// Axes and origins along one frame, in the measurement frame, needed by the
/// Jacobian columns of its parameters.
#[derive(Clone, Copy, Debug, Default)]
struct FrameAxes {
    /// Origin of the frame's base (where `Rz(q+γ)` acts).
    o_base: Vector3<f64>,
    /// z axis of the base (`γ` rotation axis, `d` translation direction).
    z: Vector3<f64>,
    /// x axis after `Rz` (`a` translation direction, `α` rotation axis).
    x: Vector3<f64>,
    /// Origin after `Tz(d) Tx(a)` (where `α` and `β` act).
    o_twist: Vector3<f64>,
    /// y axis after `Rx(α)` (`β` rotation axis).
    y: Vector3<f64>,
}

#[inline]
fn rot_z(r: &Matrix3<f64>, th: f64) -> Matrix3<f64> {
    let (s, c) = th.sin_cos();
    let mut out = *r;
    for i in 0..3 {
        let (x, y) = (r[(i, 0)], r[(i, 1)]);
        out[(i, 0)] = c * x + s * y;
        out[(i, 1)] = -s * x + c * y;
    }
    out
}

#[inline]
fn rot_x(r: &Matrix3<f64>, th: f64) -> Matrix3<f64> {
    let (s, c) = th.sin_cos();
    let mut out = *r;
    for i in 0..3 {
        let (y, z) = (r[(i, 1)], r[(i, 2)]);
        out[(i, 1)] = c * y + s * z;
        out[(i, 2)] = -s * y + c * z;
    }
    out
}

#[inline]
fn rot_y(r: &Matrix3<f64>, th: f64) -> Matrix3<f64> {
    let (s, c) = th.sin_cos();
    let mut out = *r;
    for i in 0..3 {
        let (x, z) = (r[(i, 0)], r[(i, 2)]);
        out[(i, 0)] = c * x - s * z;
        out[(i, 2)] = s * x + c * z;
    }
    out
}

/// Joint value of a frame: `q[j]` for a driven frame, 0 for a fixed one.
#[inline]
fn frame_q(joint: Option<usize>, q: &[f64]) -> f64 {
    joint.map_or(0.0, |j| q[j])
}

/// Walks the chain, filling `axes` (one entry per frame) and returning the
/// end-point transform `(R, p)`.
fn walk(
    robot: &Robot,
    table: &ParamTable,
    q: &[f64],
    axes: &mut [FrameAxes],
) -> (Matrix3<f64>, Vector3<f64>) {
    let mut r = Matrix3::identity();
    let mut o = Vector3::zeros();
    for ((frame, row), ax) in robot.frames.iter().zip(&table.rows).zip(axes.iter_mut()) {
        let [gamma, alpha, a, d, beta] = *row;
        ax.o_base = o;
        ax.z = r.column(2).into_owned();
        r = rot_z(&r, frame_q(frame.joint, q) + gamma);
        ax.x = r.column(0).into_owned();
        o += ax.z * d + ax.x * a;
        ax.o_twist = o;
        r = rot_x(&r, alpha);
        ax.y = r.column(1).into_owned();
        if frame.convention == Convention::Hayati {
            r = rot_y(&r, beta);
        }
    }
    (r, o)
}

/// Position of the end point in the measurement frame (no input checks; see
/// [`Robot::check_q`]).
#[must_use]
pub fn position(robot: &Robot, table: &ParamTable, q: &[f64]) -> Vector3<f64> {
    let mut axes = vec![FrameAxes::default(); robot.frames.len()];
    walk(robot, table, q, &mut axes).1
}

/// Position of the end point, with the joint vector validated.
pub fn position_checked(robot: &Robot, table: &ParamTable, q: &[f64]) -> Result<Vector3<f64>> {
    robot.check_q(q)?;
    Ok(position(robot, table, q))
}

/// Reusable scratch for [`Evaluator::eval`]: avoids an allocation per pose.
#[derive(Clone, Debug)]
pub struct Evaluator<'r> {
    robot: &'r Robot,
    table: &'r ParamTable,
    axes: Vec<FrameAxes>,
}

impl<'r> Evaluator<'r> {
    /// An evaluator for one robot and parameter table.
    #[must_use]
    pub fn new(robot: &'r Robot, table: &'r ParamTable) -> Self {
        Self {
            robot,
            table,
            axes: vec![FrameAxes::default(); robot.frames.len()],
        }
    }

    /// End point at `q`, and the identification Jacobian `∂p/∂θ` (3 × p,
    /// row-major, unknowns in [`Robot::unknowns`] order) written into `jac`.
    pub fn eval(&mut self, q: &[f64], jac: &mut [f64]) -> Vector3<f64> {
        let p_len = self.robot.unknowns.len();
        debug_assert_eq!(jac.len(), 3 * p_len);
        let (_, p) = walk(self.robot, self.table, q, &mut self.axes);
        for (c, u) in self.robot.unknowns.iter().enumerate() {
            let ax = &self.axes[u.frame];
            let col = match u.symbol {
                Symbol::Gamma => ax.z.cross(&(p - ax.o_base)),
                Symbol::D => ax.z,
                Symbol::A => ax.x,
                Symbol::Alpha => ax.x.cross(&(p - ax.o_twist)),
                Symbol::Beta => ax.y.cross(&(p - ax.o_twist)),
            };
            for r in 0..3 {
                jac[r * p_len + c] = col[r];
            }
        }
        p
    }

    /// Geometric position Jacobian with respect to the joint angles (3 × dof,
    /// row-major): column `j` is `z_j × (p − o_j)` for the frame driven by
    /// joint `j`. It equals the identification-Jacobian column of that frame's γ.
    pub fn joint_jacobian(&mut self, q: &[f64], jac: &mut [f64]) -> Vector3<f64> {
        let dof = self.robot.dof();
        debug_assert_eq!(jac.len(), 3 * dof);
        let (_, p) = walk(self.robot, self.table, q, &mut self.axes);
        for (f, frame) in self.robot.frames.iter().enumerate() {
            if let Some(j) = frame.joint {
                let ax = &self.axes[f];
                let col = ax.z.cross(&(p - ax.o_base));
                for r in 0..3 {
                    jac[r * dof + j] = col[r];
                }
            }
        }
        p
    }
}

/// The chain as fixed placements and revolute joints about z, the form
/// Pinocchio and MuJoCo models are built from: `T(q) = P_0 Rz(q_0) P_1 Rz(q_1)
/// … P_{n−1} Rz(q_{n−1}) · tool`.
#[derive(Clone, Debug)]
pub struct JointChain {
    /// `placements[k]`: transform from joint k−1's moving frame (or the
    /// measurement frame for k = 0) to joint k's frame before its rotation.
    /// Indexed by joint number.
    pub placements: Vec<Isometry3<f64>>,
    /// Transform from the last joint's moving frame to the end point frame.
    pub tool: Isometry3<f64>,
}

fn iso_rz(th: f64) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::identity(),
        UnitQuaternion::from_axis_angle(&Vector3::z_axis(), th),
    )
}

fn iso_rx(th: f64) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::identity(),
        UnitQuaternion::from_axis_angle(&Vector3::x_axis(), th),
    )
}

fn iso_ry(th: f64) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::identity(),
        UnitQuaternion::from_axis_angle(&Vector3::y_axis(), th),
    )
}

/// Splits the chain into fixed placements and joints (for the Pinocchio and
/// MuJoCo cross-checks). Joints must drive frames in increasing joint order.
#[must_use]
pub fn joint_chain(robot: &Robot, table: &ParamTable) -> JointChain {
    let mut acc = Isometry3::identity();
    let mut placements = vec![Isometry3::identity(); robot.dof()];
    for (frame, row) in robot.frames.iter().zip(&table.rows) {
        let [gamma, alpha, a, d, beta] = *row;
        acc *= iso_rz(gamma);
        if let Some(j) = frame.joint {
            placements[j] = acc;
            acc = Isometry3::identity();
        }
        acc *= Translation3::new(a, 0.0, d) * iso_rx(alpha);
        if frame.convention == Convention::Hayati {
            acc *= iso_ry(beta);
        }
    }
    JointChain {
        placements,
        tool: acc,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::robot::Robot;

    fn q_sample(i: usize) -> [f64; 6] {
        let mut q = [0.0; 6];
        for (j, v) in q.iter_mut().enumerate() {
            *v = ((i * 7 + j * 13) as f64 * 0.37).sin() * 2.5;
        }
        q
    }

    #[test]
    fn joint_chain_reproduces_position() {
        let r = Robot::puma560();
        for table in [&r.nominal, &r.real] {
            let ch = joint_chain(&r, table);
            for i in 0..50 {
                let q = q_sample(i);
                let mut t = Isometry3::identity();
                for (j, p) in ch.placements.iter().enumerate() {
                    t = t * p * iso_rz(q[j]);
                }
                t *= ch.tool;
                let p = position(&r, table, &q);
                // Both are ~10 flops per step on values of size ≤ 20 m: 1e-12 m is rounding.
                assert!((t.translation.vector - p).norm() < 1e-12);
            }
        }
    }

    #[test]
    fn gamma_columns_equal_joint_jacobian() {
        let r = Robot::puma560();
        let mut ev = Evaluator::new(&r, &r.nominal);
        let p = r.n_unknowns();
        let mut jac = vec![0.0; 3 * p];
        let mut jj = vec![0.0; 18];
        let q = q_sample(3);
        ev.eval(&q, &mut jac);
        ev.joint_jacobian(&q, &mut jj);
        // gamma_0 is unknown index 4 and drives joint 0.
        for row in 0..3 {
            assert_eq!(jac[row * p + 4], jj[row * 6]);
        }
    }
}

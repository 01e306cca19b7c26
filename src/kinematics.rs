//! Forward kinematics and the analytic identification Jacobian of a [`Robot`].
//!
//! A frame's transform is the product of elementary motions
//! `Rz(q+γ) · Tz(d) · Tx(a) · Rx(α) · Ry(β)` (β only for Hayati frames; a
//! prismatic joint moves `Tz(q+d)` instead and leaves `Rz(γ)`). The
//! derivative of the end point `p` with respect to each parameter is the
//! velocity of `p` under the corresponding elementary motion, expressed in the
//! measurement frame: for a rotation about a unit axis `u` through a point `o`
//! it is `u × (p − o)`, for a translation along `u` it is `u`; the angular
//! velocity of the end frame is `u` for a rotation about `u`, 0 for a
//! translation. [`Evaluator::motions`] gives both per unknown ([`Motion`]);
//! which rows a measurement makes of them is the sensor's business
//! ([`crate::measure::Sensor`]): this module knows no sensor.

use crate::error::Result;
use crate::model::{JointKind, ParamTable, Robot, Symbol};
use nalgebra::{Isometry3, Matrix3, Vector3};

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
        let m = frame.motion(row, q);
        ax.o_base = o;
        ax.z = r.column(2).into_owned();
        r = rot_z(&r, m.theta);
        ax.x = r.column(0).into_owned();
        o += ax.z * m.d + ax.x * m.a;
        ax.o_twist = o;
        r = rot_x(&r, m.alpha);
        ax.y = r.column(1).into_owned();
        if let Some(beta) = m.beta {
            r = rot_y(&r, beta);
        }
    }
    (r, o)
}

/// Position of the end point in the measurement frame (no input checks; see
/// [`Robot::check_q`]).
#[must_use]
pub fn position(robot: &Robot, table: &ParamTable, q: &[f64]) -> Vector3<f64> {
    Evaluator::new(robot, table).end_frame(q).position
}

/// Position of the end point, with the joint vector validated.
pub fn position_checked(robot: &Robot, table: &ParamTable, q: &[f64]) -> Result<Vector3<f64>> {
    robot.check_q(q)?;
    Ok(position(robot, table, q))
}

/// Orientation `R` (columns: the end frame's axes) and position `p` of the
/// end frame in the measurement frame (no input checks; see
/// [`Robot::check_q`]).
#[must_use]
pub fn pose(robot: &Robot, table: &ParamTable, q: &[f64]) -> (Matrix3<f64>, Vector3<f64>) {
    let e = Evaluator::new(robot, table).end_frame(q);
    (e.rotation, e.position)
}

/// The end frame of the chain: orientation `R` (columns: the end frame's
/// axes) and position `p` of the end point, in the measurement frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EndFrame {
    /// Orientation `R`.
    pub rotation: Matrix3<f64>,
    /// Position `p`.
    pub position: Vector3<f64>,
}

/// The first-order motion of the end frame under one parameter's (or one
/// joint's) elementary motion, in the measurement frame: for a rotation about
/// a unit axis `u` through `o`, `lin = u × (p − o)` and `ang = u`; for a
/// translation along `u`, `lin = u` and `ang = 0`. A sensor turns these into
/// its Jacobian rows ([`crate::measure::Sensor::motion_rows`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Motion {
    /// Linear velocity of the end point.
    pub lin: Vector3<f64>,
    /// Angular velocity of the end frame.
    pub ang: Vector3<f64>,
}

/// Reusable scratch for walking one robot's chain many times: avoids an
/// allocation per pose.
///
/// A robot with a gravity model ([`Robot::gravity`]) whose table has joint
/// compliances, or whose unknowns include one ([`Symbol::C`]), is walked at
/// the deflected configuration `q + c∘τ(q)`, `τ` the gravity torques at
/// the commanded `q` (which no kinematic parameter changes): every sensor
/// sees the sag. A compliance's motion is its joint's motion at the
/// deflected configuration times `τ_j(q)`, exactly.
#[derive(Clone, Debug)]
pub struct Evaluator<'r> {
    robot: &'r Robot,
    table: &'r ParamTable,
    axes: Vec<FrameAxes>,
    /// Whether the chain deflects (or a compliance is unknown).
    deflects: bool,
    /// Gravity torques at the last commanded configuration.
    tau: Vec<f64>,
    /// The last deflected configuration.
    q_eff: Vec<f64>,
}

impl<'r> Evaluator<'r> {
    /// An evaluator for one robot and parameter table.
    #[must_use]
    pub fn new(robot: &'r Robot, table: &'r ParamTable) -> Self {
        let deflects = robot.gravity.is_some()
            && (table.has_compliance() || robot.unknowns.iter().any(|u| u.symbol == Symbol::C));
        Self {
            robot,
            table,
            axes: vec![FrameAxes::default(); robot.frames.len()],
            deflects,
            tau: vec![0.0; robot.dof()],
            q_eff: vec![0.0; robot.dof()],
        }
    }

    /// The end frame at `q` (see [`pose`]), deflected under gravity when the
    /// robot's joints are compliant.
    pub fn end_frame(&mut self, q: &[f64]) -> EndFrame {
        let (rotation, position) = match (self.deflects, self.robot.gravity.as_deref()) {
            (true, Some(g)) => {
                g.torques(q, &mut self.tau);
                self.q_eff.copy_from_slice(q);
                for (f, frame) in self.robot.frames.iter().enumerate() {
                    if let Some(j) = frame.joint {
                        let c = self.table.compliance.get(f).copied().unwrap_or(0.0);
                        self.q_eff[j] += c * self.tau[j];
                    }
                }
                walk(self.robot, self.table, &self.q_eff, &mut self.axes)
            }
            _ => walk(self.robot, self.table, q, &mut self.axes),
        };
        EndFrame { rotation, position }
    }

    /// The gravity torques of the last configuration walked (N·m, N; zeros
    /// for a robot that does not deflect).
    #[must_use]
    pub fn torques(&self) -> &[f64] {
        &self.tau
    }

    /// The end frame at `q`, and in `out` (one entry per unknown, in
    /// [`Robot::unknowns`] order) the [`Motion`] of each unknown: the
    /// columns of the identification Jacobian before a sensor picks its rows.
    pub fn motions(&mut self, q: &[f64], out: &mut [Motion]) -> EndFrame {
        debug_assert_eq!(out.len(), self.robot.unknowns.len());
        let end = self.end_frame(q);
        let p = end.position;
        for (m, u) in out.iter_mut().zip(&self.robot.unknowns) {
            let ax = &self.axes[u.frame];
            *m = match u.symbol {
                Symbol::Gamma => Motion {
                    lin: ax.z.cross(&(p - ax.o_base)),
                    ang: ax.z,
                },
                Symbol::D => Motion {
                    lin: ax.z,
                    ang: Vector3::zeros(),
                },
                Symbol::A => Motion {
                    lin: ax.x,
                    ang: Vector3::zeros(),
                },
                Symbol::Alpha => Motion {
                    lin: ax.x.cross(&(p - ax.o_twist)),
                    ang: ax.x,
                },
                Symbol::Beta => Motion {
                    lin: ax.y.cross(&(p - ax.o_twist)),
                    ang: ax.y,
                },
                // q_j + c·τ_j: the joint's own motion (revolute, about the
                // base z) scaled by the torque.
                Symbol::C => {
                    let t = self.robot.frames[u.frame]
                        .joint
                        .map_or(0.0, |j| self.tau[j]);
                    Motion {
                        lin: ax.z.cross(&(p - ax.o_base)) * t,
                        ang: ax.z * t,
                    }
                }
            };
        }
        end
    }

    /// The end frame at `q`, and in `out` (one entry per joint) the
    /// [`Motion`] of each joint: for the frame driven by joint `j`, `z_j × (p
    /// − o_j)` and `z_j` if revolute (the motion of that frame's γ), `z_j`
    /// and 0 if prismatic (the motion of its `d`). The geometric Jacobian is
    /// a sensor's rows of these.
    pub fn joint_motions(&mut self, q: &[f64], out: &mut [Motion]) -> EndFrame {
        debug_assert_eq!(out.len(), self.robot.dof());
        let end = self.end_frame(q);
        let p = end.position;
        for (f, frame) in self.robot.frames.iter().enumerate() {
            if let Some(j) = frame.joint {
                let ax = &self.axes[f];
                out[j] = match frame.joint_kind {
                    JointKind::Revolute => Motion {
                        lin: ax.z.cross(&(p - ax.o_base)),
                        ang: ax.z,
                    },
                    JointKind::Prismatic => Motion {
                        lin: ax.z,
                        ang: Vector3::zeros(),
                    },
                };
            }
        }
        end
    }
}

/// The chain as fixed placements and joints along z, the form Pinocchio and
/// MuJoCo models are built from: `T(q) = P_0 M_0(q_0) P_1 M_1(q_1) …
/// P_{n−1} M_{n−1}(q_{n−1}) · tool`, where `M_k(q) = Rz(q)` for a revolute
/// joint and `Tz(q)` for a prismatic one (`kinds[k]`).
#[derive(Clone, Debug)]
pub struct JointChain {
    /// `placements[k]`: transform from joint k−1's moving frame (or the
    /// measurement frame for k = 0) to joint k's frame before its motion.
    /// Indexed by joint number.
    pub placements: Vec<Isometry3<f64>>,
    /// Kind of each joint (indexed by joint number): revolute about z or
    /// prismatic along z of its placement frame.
    pub kinds: Vec<JointKind>,
    /// Transform from the last joint's moving frame to the end point frame.
    pub tool: Isometry3<f64>,
}

/// Splits the chain into fixed placements and joints (for the Pinocchio and
/// MuJoCo cross-checks). Joints must drive frames in increasing joint order.
#[must_use]
pub fn joint_chain(robot: &Robot, table: &ParamTable) -> JointChain {
    let mut acc = Isometry3::identity();
    let mut placements = vec![Isometry3::identity(); robot.dof()];
    let mut kinds = vec![JointKind::Revolute; robot.dof()];
    for (frame, row) in robot.frames.iter().zip(&table.rows) {
        let m = frame.motion_at_zero(row);
        acc *= m.rotation_z();
        if let Some(j) = frame.joint {
            // Rz(q) and Tz(q) both act here, after Rz(γ) and before Tz(d).
            placements[j] = acc;
            kinds[j] = frame.joint_kind;
            acc = Isometry3::identity();
        }
        m.apply_after_rotation_z(&mut acc);
    }
    JointChain {
        placements,
        kinds,
        tool: acc,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Translation3, UnitQuaternion};

    fn iso_rz(th: f64) -> Isometry3<f64> {
        Isometry3::from_parts(
            Translation3::identity(),
            UnitQuaternion::from_axis_angle(&Vector3::z_axis(), th),
        )
    }
    use crate::model::Robot;

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
    fn gamma_motions_equal_joint_motions() {
        let r = Robot::puma560();
        let mut ev = Evaluator::new(&r, &r.nominal);
        let mut m = vec![Motion::default(); r.n_unknowns()];
        let mut mj = vec![Motion::default(); r.dof()];
        let q = q_sample(3);
        let e1 = ev.motions(&q, &mut m);
        let e2 = ev.joint_motions(&q, &mut mj);
        assert_eq!(e1, e2);
        // gamma_0 is unknown index 4 and drives joint 0.
        assert_eq!(m[4], mj[0]);
    }
}

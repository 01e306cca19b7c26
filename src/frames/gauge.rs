//! Splitting a calibrated chain into the measurement frame, the robot's
//! joint origins and the tool: the choice among the models that predict
//! every measurement alike.
//!
//! Moving joint `k`'s frame by a transform `G_k` that commutes with its
//! motion — a rotation about its axis and a translation along it (any
//! translation for a prismatic joint) — while its origin becomes `O_k G_k`
//! and the next joint's `G_k⁻¹ O_{k+1}`, changes no prediction. The data
//! cannot choose among these models; this module chooses the one whose
//! robot changes least, so that nothing the data cannot tell apart from the
//! measurement frame or the tool is written into a robot link:
//!
//! * the first joint's origin stays nominal: the measurement frame `M`
//!   (6 DoF) takes all of it;
//! * the `G_k` minimise `Σ_k ‖e_k‖²`, where `e_k = [(t'_k − t_k)/L, log(R_kᵀ
//!   R'_k)]` is origin `k`'s change (translation scaled by the chain's
//!   length `L`, so a unit change cannot alter the choice) — except its
//!   rotation about its own axis for every joint but the last: that is the
//!   joint's zero offset, which belongs to the joint (a rotation of origin
//!   `k+1` about joint `k`'s axis becomes joint `k`'s offset);
//! * the last joint's offset and slide along its axis go to the tool,
//!   which the data see only together with them.
//!
//! The cost is nearly quadratic in the `G_k` (the changes are small), and
//! Gauss–Newton solves it in a few steps; a tiny ridge (1e-12 of the
//! cost's scale) picks the nominal split where a direction has no cost at
//! all (two consecutive joints on one axis line).

use super::chain::UrdfFrames;
use crate::model::JointKind;
use nalgebra::{DMatrix, DVector, Isometry3, Translation3, Unit, UnitQuaternion, Vector3};

/// Gauge coordinates of a joint: 2 for a revolute joint (turn about and
/// slide along its axis), 4 for a prismatic one (turn, and any slide).
fn dims(kind: JointKind) -> usize {
    match kind {
        JointKind::Revolute => 2,
        JointKind::Prismatic => 4,
    }
}

/// The gauge transform of a joint with axis `a` from its coordinates.
fn gauge(kind: JointKind, a: &Vector3<f64>, g: &[f64]) -> Isometry3<f64> {
    let rot = UnitQuaternion::from_axis_angle(&Unit::new_normalize(*a), g[0]);
    let t = match kind {
        JointKind::Revolute => a * g[1],
        JointKind::Prismatic => Vector3::new(g[1], g[2], g[3]),
    };
    Isometry3::from_parts(Translation3::from(t), rot)
}

/// Change of an origin from nominal: `[Δt / L, rotation vector of RᵀR']`,
/// both in the joint's own frame's parent (translation) and child (rotation).
pub fn change(nominal: &Isometry3<f64>, new: &Isometry3<f64>, length: f64) -> [f64; 6] {
    let dt = (new.translation.vector - nominal.translation.vector) / length;
    let dr = (nominal.rotation.inverse() * new.rotation).scaled_axis();
    [dt.x, dt.y, dt.z, dr.x, dr.y, dr.z]
}

/// The calibrated joint frames after the gauge: `J_k G_k`.
pub struct Split {
    /// Each joint's frame, in the measurement frame.
    pub joint: Vec<Isometry3<f64>>,
    /// Each joint's origin (the first one's nominal).
    pub origin: Vec<Isometry3<f64>>,
}

/// Origins of the joints at frames `joint` (the first one's kept nominal).
fn origins(urdf: &UrdfFrames, joint: &[Isometry3<f64>]) -> Vec<Isometry3<f64>> {
    (0..joint.len())
        .map(|k| {
            if k == 0 {
                urdf.origin[0]
            } else {
                (joint[k - 1] * urdf.before[k]).inverse() * joint[k]
            }
        })
        .collect()
}

/// The robot-change residual of gauge coordinates `g` (see the module
/// documentation), with the ridge appended.
fn residual(urdf: &UrdfFrames, cal: &[Isometry3<f64>], length: f64, g: &[f64]) -> Vec<f64> {
    let joint = moved(urdf, cal, g);
    let o = origins(urdf, &joint);
    let n = joint.len();
    let mut r = Vec::with_capacity(6 * n + g.len());
    for k in 1..n {
        let mut e = change(&urdf.origin[k], &o[k], length);
        if k + 1 < n {
            // The joint's own offset is free: remove the turn about its axis.
            let a = urdf.axis[k];
            let along = e[3] * a.x + e[4] * a.y + e[5] * a.z;
            e[3] -= along * a.x;
            e[4] -= along * a.y;
            e[5] -= along * a.z;
        }
        r.extend_from_slice(&e);
    }
    r.extend(g.iter().map(|v| RIDGE * v));
    r
}

/// Weight of the ridge on the gauge coordinates (its square is 1e-12 of a
/// unit cost).
const RIDGE: f64 = 1e-6;

/// The joint frames `J_k G_k` for gauge coordinates `g`.
fn moved(urdf: &UrdfFrames, cal: &[Isometry3<f64>], g: &[f64]) -> Vec<Isometry3<f64>> {
    let mut at = 0;
    cal.iter()
        .enumerate()
        .map(|(k, j)| {
            let d = dims(urdf.kind[k]);
            let t = j * gauge(urdf.kind[k], &urdf.axis[k], &g[at..at + d]);
            at += d;
            t
        })
        .collect()
}

/// Chooses the gauge of calibrated URDF joint frames `cal` (see the module
/// documentation); `length` scales translations against rotations.
#[must_use]
pub fn split(urdf: &UrdfFrames, cal: &[Isometry3<f64>], length: f64) -> Split {
    let m: usize = urdf.kind.iter().map(|&k| dims(k)).sum();
    let mut g = vec![0.0; m];
    // Central differences of a residual of unit-size terms: a step of 1e-6
    // leaves 1e-12 of truncation and 1e-10 of rounding in the Jacobian,
    // which only slows Gauss–Newton (the residual itself is exact).
    let h = 1e-6;
    for _ in 0..MAX_STEPS {
        let r0 = DVector::from_vec(residual(urdf, cal, length, &g));
        let mut jac = DMatrix::zeros(r0.len(), m);
        for i in 0..m {
            let mut gp = g.clone();
            gp[i] += h;
            let mut gm = g.clone();
            gm[i] -= h;
            let rp = residual(urdf, cal, length, &gp);
            let rm = residual(urdf, cal, length, &gm);
            for (row, (a, b)) in rp.iter().zip(&rm).enumerate() {
                jac[(row, i)] = (a - b) / (2.0 * h);
            }
        }
        let jt = jac.transpose();
        let Some(step) = (&jt * &jac).cholesky().map(|c| c.solve(&(-(&jt * &r0)))) else {
            break;
        };
        for (gi, si) in g.iter_mut().zip(step.iter()) {
            *gi += si;
        }
        if step.norm() <= 1e-15 * (1.0 + DVector::from_column_slice(&g).norm()) {
            break;
        }
    }
    let joint = moved(urdf, cal, &g);
    let origin = origins(urdf, &joint);
    Split { joint, origin }
}

/// Most Gauss–Newton steps (the cost is nearly quadratic: 3–5 suffice).
const MAX_STEPS: usize = 30;

//! The full-pose sensor: the end point and the end frame's orientation, 6
//! rows per pose: position `p − y`, then `w · log(R(θ) R_measᵀ)` with `w` =
//! [`crate::model::Robot::orientation_scale`] (see [`super::so3`]).

use super::sensor::{Observation, ObservationBuf, RowKind, Sensor};
use super::so3;
use crate::kinematics::{EndFrame, Motion};
use nalgebra::{Quaternion, UnitQuaternion, Vector3};

/// Measures `(p, R)`; value layout `x y z` then the unit quaternion `w x y z`
/// of `R`. Jacobian rows: the linear velocity of `p`, then `w` times the
/// angular velocity of the end frame (at zero residual), premultiplied by
/// `J_l⁻¹(φ)` for the exact derivative of the residual `φ = log(R R_measᵀ)`.
#[derive(Clone, Copy, Debug)]
pub struct PoseSensor {
    weights: [f64; 6],
}

impl PoseSensor {
    /// A pose sensor with orientation weight `w` (metres per radian).
    #[must_use]
    pub fn new(w: f64) -> Self {
        Self {
            weights: [1.0, 1.0, 1.0, w, w, w],
        }
    }

    fn w(&self) -> f64 {
        self.weights[3]
    }
}

const KINDS: [RowKind; 6] = [
    RowKind::Position,
    RowKind::Position,
    RowKind::Position,
    RowKind::Orientation,
    RowKind::Orientation,
    RowKind::Orientation,
];

/// The unit quaternion stored at `v[3..7]` (`w x y z`, unit by construction).
fn quaternion(v: &[f64]) -> UnitQuaternion<f64> {
    UnitQuaternion::new_unchecked(Quaternion::new(v[3], v[4], v[5], v[6]))
}

fn store(q: &UnitQuaternion<f64>, out: &mut [f64]) {
    out[3] = q.w;
    out[4] = q.i;
    out[5] = q.j;
    out[6] = q.k;
}

impl Sensor for PoseSensor {
    fn describe(&self) -> &'static str {
        "full poses (position and orientation)"
    }

    fn rows(&self) -> usize {
        6
    }

    fn row_kinds(&self) -> &[RowKind] {
        &KINDS
    }

    fn weights(&self) -> &[f64] {
        &self.weights
    }

    fn observed_dof(&self) -> usize {
        6
    }

    fn observes_orientation(&self) -> bool {
        true
    }

    fn points_per_pose(&self) -> usize {
        1
    }

    fn value_len(&self) -> usize {
        7
    }

    fn encode(&self, obs: &Observation<'_>, out: &mut [f64]) {
        out[..3].copy_from_slice(&obs.points[0]);
        let r = obs
            .orientation
            .map_or_else(nalgebra::Matrix3::identity, |r| {
                nalgebra::Matrix3::from_fn(|i, j| r[i][j])
            });
        store(&so3::nearest_rotation(&r), out);
    }

    fn decode(&self, value: &[f64]) -> ObservationBuf {
        let m = quaternion(value).to_rotation_matrix().into_inner();
        ObservationBuf {
            points: vec![[value[0], value[1], value[2]]],
            orientation: Some(std::array::from_fn(|i| std::array::from_fn(|j| m[(i, j)]))),
            tag: None,
        }
    }

    fn predict(&self, end: &EndFrame, _own: &[f64], out: &mut [f64]) {
        out[..3].copy_from_slice(end.position.as_slice());
        store(&so3::to_quaternion(&end.rotation), out);
    }

    /// `p + δ_p`, `R ← exp([δ_R]×) R` (a rotation noise in the base frame).
    fn retract(&self, value: &mut [f64], delta: &[f64]) {
        for (v, d) in value[..3].iter_mut().zip(delta) {
            *v += d;
        }
        let eta = Vector3::new(delta[3], delta[4], delta[5]);
        let turned = so3::to_quaternion(&so3::exp(&eta)) * quaternion(value);
        store(&turned, value);
    }

    fn residual(&self, predicted: &[f64], measured: &[f64], out: &mut [f64]) {
        for c in 0..3 {
            out[c] = predicted[c] - measured[c];
        }
        let phi = so3::difference(&quaternion(predicted), &quaternion(measured));
        let w = self.w();
        for c in 0..3 {
            out[3 + c] = w * phi[c];
        }
    }

    fn motion_rows(
        &self,
        _end: &EndFrame,
        _own: &[f64],
        motions: &[Motion],
        out: &mut [f64],
        ld: usize,
    ) {
        let w = self.w();
        for (c, m) in motions.iter().enumerate() {
            out[c] = m.lin.x;
            out[ld + c] = m.lin.y;
            out[2 * ld + c] = m.lin.z;
            out[3 * ld + c] = w * m.ang.x;
            out[4 * ld + c] = w * m.ang.y;
            out[5 * ld + c] = w * m.ang.z;
        }
    }

    /// Orientation rows `J_l⁻¹(φ) · w ω` with `φ = log(R R_measᵀ)`: a change
    /// `dθ` turns the model by `exp([ω dθ]×)`, so `φ` moves by `J_l⁻¹(φ) ω dθ`
    /// ([`so3::left_jacobian_inverse`]).
    fn residual_rows(
        &self,
        end: &EndFrame,
        own: &[f64],
        motions: &[Motion],
        measured: &[f64],
        out: &mut [f64],
        ld: usize,
    ) {
        self.motion_rows(end, own, motions, out, ld);
        let phi = so3::difference(&so3::to_quaternion(&end.rotation), &quaternion(measured));
        let jinv = so3::left_jacobian_inverse(&phi);
        for c in 0..motions.len() {
            let v = Vector3::new(out[3 * ld + c], out[4 * ld + c], out[5 * ld + c]);
            let u = jinv * v;
            for r in 0..3 {
                out[(3 + r) * ld + c] = u[r];
            }
        }
    }
}

//! The marker sensor: `K` points fixed to the last frame, each measured as a
//! position (a motion-capture rig with several markers on a plate, a laser
//! tracker with several targets). `3K` rows per pose.
//!
//! Marker `k` sits at `m_k = p + R o_k`, with `(R, p)` the end frame and
//! `o_k` its offset in the end frame, an unknown of the sensor's own (see
//! [`super::sensor`]): the offsets are never known to the precision of a
//! calibration, so each marker brings three unknowns, and the tool frame's
//! translation and rotation, which they absorb, are not among the robot's
//! unknowns.
//!
//! Under an elementary motion of the chain with linear velocity `v` of `p`
//! and angular velocity `ω` of the end frame, marker `k` moves with
//! `v + ω × (R o_k)`: its rows of the robot's columns. Its rows of its own
//! offset's columns are `∂m_k/∂o_k = R`; of another marker's offset, zero.
//!
//! Several markers are never flattened into one point: a file with `K`
//! markers per pose is read by this sensor with `K` offsets (see
//! [`crate::io::measurements`]).

use super::sensor::{Observation, ObservationBuf, RowKind, Sensor, ToolRecord};
use crate::kinematics::{EndFrame, Motion};
use nalgebra::Vector3;

/// Measures `K` marker points per pose, `3K` rows, with `3K` offset
/// unknowns of its own.
#[derive(Clone, Debug)]
pub struct MarkerSensor {
    k: usize,
    kinds: Vec<RowKind>,
    ones: Vec<f64>,
}

impl MarkerSensor {
    /// A sensor of `k ≥ 1` markers.
    #[must_use]
    pub fn new(k: usize) -> Self {
        let k = k.max(1);
        Self {
            k,
            kinds: vec![RowKind::Position; 3 * k],
            ones: vec![1.0; 3 * k],
        }
    }

    /// Marker `k`'s offset rotated into the base frame, `R o_k`.
    fn lever(end: &EndFrame, own: &[f64], k: usize) -> Vector3<f64> {
        end.rotation * Vector3::new(own[3 * k], own[3 * k + 1], own[3 * k + 2])
    }
}

impl Sensor for MarkerSensor {
    fn describe(&self) -> &'static str {
        "marker points"
    }

    fn rows(&self) -> usize {
        3 * self.k
    }

    fn row_kinds(&self) -> &[RowKind] {
        &self.kinds
    }

    fn weights(&self) -> &[f64] {
        &self.ones
    }

    /// One marker sees a point (3), two a point and a direction (5), three
    /// or more off a line the whole frame (6).
    fn observed_dof(&self) -> usize {
        match self.k {
            1 => 3,
            2 => 5,
            _ => 6,
        }
    }

    fn observes_orientation(&self) -> bool {
        self.k > 1
    }

    fn measures_orientation(&self) -> bool {
        false
    }

    fn points_per_pose(&self) -> usize {
        self.k
    }

    fn tool_record(&self) -> ToolRecord {
        ToolRecord::Markers
    }

    /// Each marker `p + R o_k`.
    fn measured_points(&self, end: &EndFrame, own: &[f64]) -> Vec<Vector3<f64>> {
        own.chunks_exact(3)
            .map(|o| end.position + end.rotation * Vector3::new(o[0], o[1], o[2]))
            .collect()
    }

    fn value_len(&self) -> usize {
        3 * self.k
    }

    fn n_own_params(&self) -> usize {
        3 * self.k
    }

    fn own_param_names(&self) -> Vec<String> {
        (1..=self.k)
            .flat_map(|k| ["x", "y", "z"].map(|c| format!("marker{k}_{c}")))
            .collect()
    }

    fn encode(&self, obs: &Observation<'_>, out: &mut [f64]) {
        for (o, p) in out.chunks_exact_mut(3).zip(obs.points) {
            o.copy_from_slice(p);
        }
    }

    fn decode(&self, value: &[f64]) -> ObservationBuf {
        ObservationBuf {
            points: value.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
            orientation: None,
            tag: None,
        }
    }

    fn predict(&self, end: &EndFrame, own: &[f64], out: &mut [f64]) {
        for k in 0..self.k {
            let m = end.position + Self::lever(end, own, k);
            out[3 * k..3 * k + 3].copy_from_slice(m.as_slice());
        }
    }

    fn retract(&self, value: &mut [f64], delta: &[f64]) {
        for (v, d) in value.iter_mut().zip(delta) {
            *v += d;
        }
    }

    fn residual(&self, predicted: &[f64], measured: &[f64], out: &mut [f64]) {
        for ((o, p), m) in out.iter_mut().zip(predicted).zip(measured) {
            *o = p - m;
        }
    }

    fn motion_rows(
        &self,
        end: &EndFrame,
        own: &[f64],
        motions: &[Motion],
        out: &mut [f64],
        ld: usize,
    ) {
        for k in 0..self.k {
            let l = Self::lever(end, own, k);
            let rows = &mut out[3 * k * ld..];
            for (c, m) in motions.iter().enumerate() {
                let v = m.lin + m.ang.cross(&l);
                rows[c] = v.x;
                rows[ld + c] = v.y;
                rows[2 * ld + c] = v.z;
            }
        }
    }

    fn own_rows(&self, end: &EndFrame, _own: &[f64], out: &mut [f64], ld: usize) {
        let r = &end.rotation;
        for k in 0..self.k {
            for i in 0..3 {
                let row = &mut out[(3 * k + i) * ld..];
                for j in 0..self.k {
                    for c in 0..3 {
                        row[3 * j + c] = if j == k { r[(i, c)] } else { 0.0 };
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Rotation3;

    fn frame() -> EndFrame {
        EndFrame {
            rotation: *Rotation3::from_euler_angles(0.3, -0.7, 1.1).matrix(),
            position: Vector3::new(0.4, -0.2, 0.9),
        }
    }

    /// Each Jacobian row is the derivative of the prediction: checked by
    /// central differences of `predict` under a rigid motion of the end
    /// frame (robot columns) and under each offset coordinate (own columns).
    /// Step 1e-6 on O(1) quantities: truncation O(h²) ≈ 1e-12, rounding
    /// ε/h ≈ 1e-10; 1e-8 separates a right row from any wrong one (O(0.1)).
    #[test]
    fn rows_are_derivatives_of_the_prediction() {
        let s = MarkerSensor::new(3);
        let own = [0.1, 0.0, 0.45, -0.05, 0.12, 0.5, 0.0, -0.1, 0.55];
        let end = frame();
        let motions = [
            Motion {
                lin: Vector3::new(0.3, -0.1, 0.2),
                ang: Vector3::new(0.0, 0.0, 0.0),
            },
            Motion {
                lin: Vector3::new(0.0, 0.5, 0.0),
                ang: Vector3::new(0.2, -0.4, 0.7),
            },
        ];
        let (p, n) = (motions.len(), motions.len() + 9);
        let mut jac = vec![0.0; 9 * n];
        s.motion_rows(&end, &own, &motions, &mut jac, n);
        s.own_rows(&end, &own, &mut jac[p..], n);
        let h = 1e-6;
        let moved = |c: usize, eps: f64, own: &[f64]| {
            let mut e = end;
            if c < p {
                let m = &motions[c];
                let w = eps * m.ang;
                e.rotation = Rotation3::new(w).matrix() * e.rotation;
                e.position += eps * m.lin;
            }
            let mut out = [0.0; 9];
            s.predict(&e, own, &mut out);
            out
        };
        for c in 0..n {
            let (mut op, mut om) = (own, own);
            if c >= p {
                op[c - p] += h;
                om[c - p] -= h;
            }
            let (fp, fm) = if c < p {
                (moved(c, h, &own), moved(c, -h, &own))
            } else {
                (moved(c, 0.0, &op), moved(c, 0.0, &om))
            };
            for r in 0..9 {
                let fd = (fp[r] - fm[r]) / (2.0 * h);
                assert!(
                    (jac[r * n + c] - fd).abs() < 1e-8,
                    "row {r} col {c}: {} vs {fd}",
                    jac[r * n + c]
                );
            }
        }
        // Own columns of other markers are exactly zero.
        assert_eq!(jac[p + 3], 0.0);
    }

    #[test]
    fn encode_decode_round_trip() {
        let s = MarkerSensor::new(2);
        let pts = [[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]];
        let mut v = [0.0; 6];
        s.encode(
            &Observation {
                points: &pts,
                orientation: None,
                tag: None,
            },
            &mut v,
        );
        assert_eq!(s.decode(&v).points, pts.to_vec());
        assert_eq!(s.own_param_names()[4], "marker2_y");
    }

    /// The sizes a caller reads off the sensor follow `K`: one point, three
    /// rows, three values and three own unknowns per marker; every row a
    /// position of weight 1 (metres, as a point sensor's); one distinct name
    /// per own unknown; no orientation in a value (the markers observe it
    /// through their positions, they do not measure one).
    #[test]
    fn sizes_follow_the_number_of_markers() {
        for k in 1..=4 {
            let s = MarkerSensor::new(k);
            assert_eq!(s.points_per_pose(), k);
            assert_eq!(s.rows(), 3 * k);
            assert_eq!(s.value_len(), 3 * k);
            assert_eq!(s.n_own_params(), 3 * k);
            assert_eq!(s.row_kinds(), vec![RowKind::Position; 3 * k].as_slice());
            assert_eq!(s.weights(), vec![1.0; 3 * k].as_slice());
            let names = s.own_param_names();
            let distinct: std::collections::BTreeSet<&String> = names.iter().collect();
            assert_eq!((names.len(), distinct.len()), (3 * k, 3 * k), "{names:?}");
            assert!(names.iter().all(|n| n.starts_with("marker")), "{names:?}");
            assert!(!s.measures_orientation());
            assert!(s.decode(&vec![0.5; 3 * k]).orientation.is_none());
            assert!(s.describe().contains("marker"), "{}", s.describe());
        }
        // No markers is read as one.
        assert_eq!(MarkerSensor::new(0).points_per_pose(), 1);
    }

    /// `observed_dof` is the rank of the marker rows under the six rigid
    /// motions of the end frame (three translations, three rotations), and
    /// the orientation is observed exactly when the rotations add rank to
    /// the translations' 3: one marker 3, two 5 (the turn about the line
    /// through them is unseen), three or four off a line 6. Rank cut at
    /// 1e-9 of the largest singular value: the rows are O(1) and a
    /// structural zero singular value comes out at rounding size (~1e-16).
    #[test]
    fn observed_dof_is_the_rank_of_the_rigid_motion_rows() {
        let own = [
            0.1, 0.0, 0.45, -0.05, 0.12, 0.5, 0.0, -0.1, 0.55, 0.2, 0.2, 0.3,
        ];
        let end = frame();
        let motions: Vec<Motion> = (0..6)
            .map(|c| {
                let (mut lin, mut ang) = (Vector3::zeros(), Vector3::zeros());
                if c < 3 {
                    lin[c] = 1.0;
                } else {
                    ang[c - 3] = 1.0;
                }
                Motion { lin, ang }
            })
            .collect();
        for k in 1..=4 {
            let s = MarkerSensor::new(k);
            let mut rows = vec![0.0; 3 * k * 6];
            s.motion_rows(&end, &own[..3 * k], &motions, &mut rows, 6);
            let sv = nalgebra::DMatrix::from_row_slice(3 * k, 6, &rows).singular_values();
            let rank = sv.iter().filter(|&&v| v > 1e-9 * sv.max()).count();
            assert_eq!(s.observed_dof(), rank, "{k} markers");
            assert_eq!(s.observes_orientation(), rank > 3, "{k} markers");
        }
    }

    /// `retract` moves a value by `delta` and `residual` is `predicted −
    /// measured`: a value retracted by `delta` has residual `delta` against
    /// the original, and the original `−delta` against it. Values O(1),
    /// one rounding each way: 1e-15 (a few ulps of 1) separates a right
    /// sign from a wrong one (1e-3).
    #[test]
    fn the_residual_of_a_retracted_value_is_its_delta() {
        let s = MarkerSensor::new(2);
        let value = [0.4, -0.2, 0.9, 0.5, 0.1, 1.0];
        let delta = [1e-3, -2e-3, 3e-3, 0.5e-3, 0.0, -1e-3];
        let mut moved = value;
        s.retract(&mut moved, &delta);
        let (mut fwd, mut back) = ([0.0; 6], [0.0; 6]);
        s.residual(&moved, &value, &mut fwd);
        s.residual(&value, &moved, &mut back);
        for i in 0..6 {
            assert!((fwd[i] - delta[i]).abs() < 1e-15, "row {i}: {}", fwd[i]);
            assert!((back[i] + delta[i]).abs() < 1e-15, "row {i}: {}", back[i]);
        }
    }
}

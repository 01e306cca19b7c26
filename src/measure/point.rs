//! The point sensor: the position of the end point, 3 rows per pose
//! (Sun & Hollerbach's measurement, §V: `y_i = p(θ, q_i) + ε_i`).

use super::sensor::{Observation, ObservationBuf, RowKind, Sensor};
use crate::kinematics::{EndFrame, Motion};

/// Measures the end point `p`; residual `p − y`; Jacobian rows the linear
/// velocity of `p` under each parameter's elementary motion.
#[derive(Clone, Copy, Debug, Default)]
pub struct PointSensor;

impl PointSensor {
    /// The point sensor.
    #[must_use]
    pub fn new() -> Self {
        Self
    }
}

const KINDS: [RowKind; 3] = [RowKind::Position; 3];
const ONES: [f64; 3] = [1.0; 3];

impl Sensor for PointSensor {
    fn describe(&self) -> &'static str {
        "points"
    }

    fn rows(&self) -> usize {
        3
    }

    fn row_kinds(&self) -> &[RowKind] {
        &KINDS
    }

    fn weights(&self) -> &[f64] {
        &ONES
    }

    fn observed_dof(&self) -> usize {
        3
    }

    fn observes_orientation(&self) -> bool {
        false
    }

    fn points_per_pose(&self) -> usize {
        1
    }

    fn value_len(&self) -> usize {
        3
    }

    fn encode(&self, obs: &Observation<'_>, out: &mut [f64]) {
        out[..3].copy_from_slice(&obs.points[0]);
    }

    fn decode(&self, value: &[f64]) -> ObservationBuf {
        ObservationBuf {
            points: vec![[value[0], value[1], value[2]]],
            orientation: None,
            tag: None,
        }
    }

    fn predict(&self, end: &EndFrame, _own: &[f64], out: &mut [f64]) {
        out[..3].copy_from_slice(end.position.as_slice());
    }

    fn retract(&self, value: &mut [f64], delta: &[f64]) {
        for (v, d) in value[..3].iter_mut().zip(delta) {
            *v += d;
        }
    }

    fn residual(&self, predicted: &[f64], measured: &[f64], out: &mut [f64]) {
        for c in 0..3 {
            out[c] = predicted[c] - measured[c];
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
        for (c, m) in motions.iter().enumerate() {
            out[c] = m.lin.x;
            out[ld + c] = m.lin.y;
            out[2 * ld + c] = m.lin.z;
        }
    }
}

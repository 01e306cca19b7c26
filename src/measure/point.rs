//! The point sensor: the position of the end point, 3 rows per pose
//! (Sun & Hollerbach's measurement, §V: `y_i = p(θ, q_i) + ε_i`), and
//! sensors that read some coordinates of it (a height gauge: `z`, 1 row).
//!
//! A sensor that reads coordinates of the tool point is a
//! [`PointSensor::reading`] with its description and coordinates: the
//! value, residual and Jacobian rows below serve it as they serve the point.

use super::sensor::{Observation, ObservationBuf, RowKind, Sensor};
use crate::kinematics::{EndFrame, Motion};

/// Measures coordinates of the end point `p` (all three by default):
/// value the read coordinates `p_k` in increasing `k`; residual `p_k − y_k`;
/// Jacobian rows the same coordinates of the linear velocity of `p` under
/// each parameter's elementary motion; unit weights.
#[derive(Clone, Copy, Debug)]
pub struct PointSensor {
    describe: &'static str,
    coordinates: &'static [usize],
}

const ALL: [usize; 3] = [0, 1, 2];
const KINDS: [RowKind; 3] = [RowKind::Position; 3];
const ONES: [f64; 3] = [1.0; 3];

impl PointSensor {
    /// The point sensor: `x y z` of the end point.
    #[must_use]
    pub const fn new() -> Self {
        Self::reading("points", &ALL)
    }

    /// A sensor reading the `coordinates` of the end point (indices into
    /// `x y z`, increasing), described as `describe` in messages (what a
    /// pose's measurement is: `heights of the end point`).
    ///
    /// # Panics
    /// When `coordinates` is empty, not increasing or indexes past `z`: a
    /// programming error (and a compile error where the sensor is a
    /// `const`).
    #[must_use]
    pub const fn reading(describe: &'static str, coordinates: &'static [usize]) -> Self {
        assert!(!coordinates.is_empty(), "a sensor reads a coordinate");
        let mut i = 0;
        while i < coordinates.len() {
            assert!(coordinates[i] < 3, "a coordinate is 0, 1 or 2 (x y z)");
            assert!(i == 0 || coordinates[i - 1] < coordinates[i], "increasing");
            i += 1;
        }
        Self {
            describe,
            coordinates,
        }
    }

    /// Coordinates read, i.e. rows per pose.
    fn n(&self) -> usize {
        self.coordinates.len()
    }
}

impl Default for PointSensor {
    fn default() -> Self {
        Self::new()
    }
}

impl Sensor for PointSensor {
    fn describe(&self) -> &'static str {
        self.describe
    }

    fn rows(&self) -> usize {
        self.n()
    }

    fn row_kinds(&self) -> &[RowKind] {
        &KINDS[..self.n()]
    }

    fn weights(&self) -> &[f64] {
        &ONES[..self.n()]
    }

    fn observed_dof(&self) -> usize {
        self.n()
    }

    fn observes_orientation(&self) -> bool {
        false
    }

    fn points_per_pose(&self) -> usize {
        1
    }

    fn point_coordinates(&self) -> &'static [usize] {
        self.coordinates
    }

    fn value_len(&self) -> usize {
        self.n()
    }

    fn encode(&self, obs: &Observation<'_>, out: &mut [f64]) {
        for (o, &k) in out.iter_mut().zip(self.coordinates) {
            *o = obs.points[0][k];
        }
    }

    /// The point with the read coordinates, the others 0.
    fn decode(&self, value: &[f64]) -> ObservationBuf {
        let mut p = [0.0; 3];
        for (v, &k) in value.iter().zip(self.coordinates) {
            p[k] = *v;
        }
        ObservationBuf {
            points: vec![p],
            orientation: None,
            tag: None,
        }
    }

    fn predict(&self, end: &EndFrame, _own: &[f64], out: &mut [f64]) {
        for (o, &k) in out.iter_mut().zip(self.coordinates) {
            *o = end.position[k];
        }
    }

    fn retract(&self, value: &mut [f64], delta: &[f64]) {
        for (v, d) in value[..self.n()].iter_mut().zip(delta) {
            *v += d;
        }
    }

    fn residual(&self, predicted: &[f64], measured: &[f64], out: &mut [f64]) {
        for c in 0..self.n() {
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
        for (r, &k) in self.coordinates.iter().enumerate() {
            let row = &mut out[r * ld..r * ld + motions.len()];
            for (o, m) in row.iter_mut().zip(motions) {
                *o = m.lin[k];
            }
        }
    }
}

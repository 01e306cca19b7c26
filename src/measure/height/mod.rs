//! The height sensor: the height `z` of the end point above the
//! measurement frame's `xy` plane, 1 row per pose — a dial gauge or laser
//! displacement sensor reading the tool point's height against a flat.
//!
//! It is the proof that a sensor is one folder behind [`Sensor`]
//! (issue #50): this folder and one line of `measure/mod.rs`'s
//! `registered_sensors!` make it a [`MeasurementKind::Registered`] sensor
//! that every library pipeline selects, bounds, fits and reports by the
//! trait alone (`tests/seam_sensor.rs`).
//!
//! One row per pose sees one coordinate of the end point: the base's
//! position in `x` and `y` and its turn about `z` are invisible, so
//! [`crate::model::Robot::with_measurement`] keeps fewer unknowns than for a
//! point. A measured value is a point whose `z` alone is read (measurement
//! files hold its `z1` column alone, [`Sensor::point_coordinates`]; a
//! simulated one has `x = y = 0`).

use super::sensor::{Observation, ObservationBuf, RowKind, Sensor};
use crate::kinematics::{EndFrame, Motion};
use crate::model::{MeasurementKind, SensorKey};

/// The key [`MeasurementKind::Registered`] names this sensor by.
pub const KEY: SensorKey = SensorKey {
    name: "height",
    rows: 1,
};

/// The measurement kind of a robot measured by its end point's height.
pub const KIND: MeasurementKind = MeasurementKind::Registered(KEY);

/// Its registration: the key and how to build the sensor.
pub const REGISTRATION: super::Registration = super::Registration {
    key: KEY,
    make: |_| Box::new(HeightSensor),
};

/// Measures the end point's height `p_z`; residual `p_z − y`; Jacobian row
/// the `z` component of the end point's linear velocity under each
/// parameter's elementary motion.
#[derive(Clone, Copy, Debug, Default)]
pub struct HeightSensor;

const KINDS: [RowKind; 1] = [RowKind::Position];
const ONES: [f64; 1] = [1.0];

impl Sensor for HeightSensor {
    fn describe(&self) -> &'static str {
        "heights of the end point"
    }

    fn rows(&self) -> usize {
        KEY.rows
    }

    fn row_kinds(&self) -> &[RowKind] {
        &KINDS
    }

    fn weights(&self) -> &[f64] {
        &ONES
    }

    fn observed_dof(&self) -> usize {
        1
    }

    fn observes_orientation(&self) -> bool {
        false
    }

    fn points_per_pose(&self) -> usize {
        1
    }

    fn point_coordinates(&self) -> &'static [usize] {
        &[2]
    }

    fn value_len(&self) -> usize {
        1
    }

    fn encode(&self, obs: &Observation<'_>, out: &mut [f64]) {
        out[0] = obs.points[0][2];
    }

    fn decode(&self, value: &[f64]) -> ObservationBuf {
        ObservationBuf {
            points: vec![[0.0, 0.0, value[0]]],
            orientation: None,
            tag: None,
        }
    }

    fn predict(&self, end: &EndFrame, _own: &[f64], out: &mut [f64]) {
        out[0] = end.position.z;
    }

    fn retract(&self, value: &mut [f64], delta: &[f64]) {
        value[0] += delta[0];
    }

    fn residual(&self, predicted: &[f64], measured: &[f64], out: &mut [f64]) {
        out[0] = predicted[0] - measured[0];
    }

    fn motion_rows(
        &self,
        _end: &EndFrame,
        _own: &[f64],
        motions: &[Motion],
        out: &mut [f64],
        _ld: usize,
    ) {
        for (c, m) in motions.iter().enumerate() {
            out[c] = m.lin.z;
        }
    }
}

#[cfg(test)]
mod tests;

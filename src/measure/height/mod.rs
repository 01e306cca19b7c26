//! The height sensor: the height `z` of the end point above the
//! measurement frame's `xy` plane, 1 row per pose — a dial gauge or laser
//! displacement sensor reading the tool point's height against a flat.
//!
//! It is the proof that a sensor is one folder behind [`Sensor`](super::Sensor)
//! (issue #50): this folder and one line of `measure/mod.rs`'s
//! `registered_sensors!` make it a [`MeasurementKind::Registered`] sensor
//! that every library pipeline selects, bounds, fits and reports by the
//! trait alone (`tests/seam_sensor.rs`).
//!
//! One row per pose sees one coordinate of the end point: the base's
//! position in `x` and `y` and its turn about `z` are invisible, so
//! [`crate::model::Robot::with_measurement`] keeps fewer unknowns than for a
//! point, and a calibration is validated by the height error alone. A
//! measured value is a point whose `z` alone is read (measurement files
//! hold its `z1` column alone,
//! [`point_coordinates`](super::Sensor::point_coordinates); a simulated
//! one has `x = y = 0`).
//!
//! A sensor reading coordinates of the tool point needs no code of its
//! own: it is a [`PointSensor::reading`] those coordinates, which gives its
//! value, residual, Jacobian rows and the validation in its own rows.

use super::point::PointSensor;
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
    make: |_| Box::new(SENSOR),
};

/// The sensor: the end point's `z` alone ([`PointSensor::reading`]), so its
/// residual is `p_z − y` and its Jacobian row the `z` component of the end
/// point's linear velocity under each parameter's elementary motion.
pub const SENSOR: PointSensor = PointSensor::reading("heights of the end point", &[2]);

#[cfg(test)]
mod tests;

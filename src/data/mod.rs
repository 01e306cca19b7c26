//! Measured data as the library holds it, below the algorithms that read
//! it (identification, frames, reports) and the readers that fill it
//! (`io`): points and orientations measured at known joints
//! ([`Measurements`], checked against a robot, with their [`DataError`]),
//! contacts ([`ContactFile`]) and a camera's pixels
//! ([`CameraObservations`]).

pub mod camera;
pub mod contacts;
pub mod measurements;

pub use camera::CameraObservations;
pub use contacts::{ContactFile, MIN_DISTINCT, NamedDistance, NamedPlane};
#[cfg(test)]
pub(crate) use measurements::matrix;
pub(crate) use measurements::rows;
pub use measurements::{DataError, Measurements, ROTATION_TOLERANCE};

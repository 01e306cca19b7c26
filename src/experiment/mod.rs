//! Experiments: whole pipelines that return typed reports.
//!
//! Each command's pipeline is a module here; the command line and the
//! Python package call them with [`crate::options`] and render what they
//! return. The values a pipeline returns and takes back (a pool and its
//! Jacobian, a fit, calibrated frames) are named below, where front ends
//! find them, though they are defined beside the algorithms that make them.

pub mod acts_on;
pub mod bag;
pub mod bench;
pub mod bound;
pub mod camera;
pub mod camera_select;
pub mod contact_run;
pub mod contact_screen;
pub mod contacts;
pub mod error;
pub mod gap;
pub mod measured;
pub mod paper;
pub mod pool;
pub mod select;
pub mod simulated;
pub mod socket_design;
pub mod visiting;

pub use error::ExperimentError;

/// A pool of poses and its identification Jacobian, as
/// [`pool::build_pool`] returns them and selection takes them back.
pub use crate::blocks::Blocks;
pub use crate::pool::Pool;

/// A fit, as every calibration pipeline returns it.
pub use crate::identify::Identification;

/// A URDF robot's calibrated frames, as a calibration returns them and the
/// writers take them.
pub use crate::frames::CalibratedFrames;

/// The sensor a robot is measured with: what a front end asks of it (its
/// rows, whether it measures orientation) to check its options.
pub use crate::measure::{Sensor, sensor_for};

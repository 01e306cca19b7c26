//! activecal: choose the poses to measure for robot kinematic calibration,
//! certify how close the choice is to optimal, and run the calibration.
//!
//! Data flows one way: [`model`] → [`kinematics`] → [`measure`] → Jacobian
//! [`blocks`] → [`pool`] → [`observability`] → [`criterion`] state →
//! [`select`] / [`bound`] → [`identify`] → report; [`io`] reads and writes
//! files into and out of these types.
#![warn(missing_docs)]

pub mod blocks;
pub mod bound;
pub mod collision;
pub mod criterion;
pub mod data;
pub mod error;
pub mod experiment;
pub mod frames;
pub mod how_many;
pub mod identify;
pub mod io;
pub mod kinematics;
pub(crate) mod linalg;
pub mod lsq;
pub mod measure;
pub mod model;
pub mod names;
pub mod observability;
pub mod options;
pub mod pool;
pub mod progress;
pub mod render;
pub mod report;
pub mod resources;
pub mod select;
mod settings;
pub mod stats;
pub mod units;
pub mod write;

pub use error::{Error, Result};

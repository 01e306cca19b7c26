//! activecal: choose the poses to measure for robot kinematic calibration,
//! certify how close the choice is to optimal, and run the calibration.
//!
//! Data flows one way: [`robot`] model → [`pool`] of poses → Jacobian
//! [`blocks`] → criterion state → selection algorithm → report.
#![warn(missing_docs)]

pub mod blocks;
pub mod bound;
pub mod criterion;
pub mod design;
pub mod error;
pub mod identify;
pub mod kinematics;
pub mod pool;
pub mod robot;
pub mod select;
pub mod urdf;

pub use error::{Error, Result};

//! Experiments: whole pipelines that return typed reports.

pub mod acts_on;
pub mod bag;
pub mod bench;
pub mod camera;
pub mod camera_select;
pub mod contact_run;
pub mod contact_screen;
pub mod contacts;
pub mod error;
pub mod gap;
pub mod measured;
pub mod paper;
pub mod select;
pub mod simulated;
pub mod socket_design;

pub use error::ExperimentError;
pub mod visiting;

//! Experiments: whole pipelines that return typed reports.

pub mod acts_on;
pub mod camera;
pub mod contact_screen;
pub mod contacts;
pub mod measured;
pub mod paper;
pub mod simulated;
pub mod visiting;

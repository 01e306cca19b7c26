//! Experiments: whole pipelines that return typed reports.

pub mod measured;
pub mod paper;
pub mod simulated;

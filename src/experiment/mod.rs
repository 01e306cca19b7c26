//! Experiments: whole pipelines that return typed reports.

pub mod paper;
pub mod simulated;

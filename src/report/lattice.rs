//! `pool`'s report: the size of a lattice, and one pose of it.

use super::chain;
use crate::model::Robot;
use serde::Serialize;

/// `pool`: the size of a lattice, and one pose of it.
#[derive(Clone, Debug, Serialize)]
pub struct LatticeReport {
    /// Robot name or description path.
    pub robot: String,
    /// Driven frames.
    pub chain: Vec<String>,
    /// Values per joint.
    pub levels: usize,
    /// Lattice poses.
    pub size: usize,
    /// Index of the pose asked for.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub index: Option<usize>,
    /// Its digits.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub digits: Option<Vec<usize>>,
    /// Its joint values.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub q: Option<Vec<f64>>,
}

impl LatticeReport {
    /// The lattice of `levels` for `robot`, and the pose of `digits` if given.
    pub fn new(robot: &Robot, levels: usize, digits: Option<Vec<usize>>) -> crate::Result<Self> {
        let lattice = crate::pool::Lattice::new(robot, levels)?;
        let index = digits.as_ref().map(|d| lattice.index_of(d)).transpose()?;
        Ok(Self {
            robot: robot.name.clone(),
            chain: chain(robot),
            levels,
            size: lattice.size(),
            q: index.map(|i| lattice.q(i)).transpose()?,
            index,
            digits,
        })
    }
}

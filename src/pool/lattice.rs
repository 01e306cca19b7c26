//! The joint-space lattice of the paper: `levels` evenly spaced values per
//! joint, every combination, indexed with joint 1 the most significant digit.

use crate::error::{Error, Result};
use crate::model::Robot;
use serde::Serialize;

/// A joint-space lattice of `levels` values per joint: `linspace(lo, hi,
/// levels)`, both ends included. Pose index `Σ digit_i · k^(n−1−i)`, joint 1
/// the most significant digit, 0-based (the paper's 030412 → 1982 with k = 5).
#[derive(Clone, Debug, Serialize)]
pub struct Lattice {
    /// Values per joint.
    pub levels: usize,
    /// Joint limits `[lo, hi]` in radians.
    pub limits: Vec<[f64; 2]>,
    size: usize,
}

impl Lattice {
    /// A lattice over a robot's joint limits.
    pub fn new(robot: &Robot, levels: usize) -> Result<Lattice> {
        if levels < 2 {
            return Err(Error::TooFewLevels(levels));
        }
        for (j, &[lo, hi]) in robot.limits.iter().enumerate() {
            if !(lo.is_finite() && hi.is_finite() && lo <= hi) {
                return Err(Error::InvalidLimits {
                    joint: j + 1,
                    lo,
                    hi,
                });
            }
        }
        let dof = robot.dof();
        let size = (0..dof)
            .try_fold(1usize, |acc, _| acc.checked_mul(levels))
            .filter(|&s| s <= 1 << 32)
            .ok_or(Error::LatticeTooLarge { levels, dof })?;
        Ok(Lattice {
            levels,
            limits: robot.limits.clone(),
            size,
        })
    }

    /// Number of lattice poses, `levels^dof`.
    #[must_use]
    pub fn size(&self) -> usize {
        self.size
    }

    /// Number of joints.
    #[must_use]
    pub fn dof(&self) -> usize {
        self.limits.len()
    }

    /// Index of a digit vector.
    pub fn index_of(&self, digits: &[usize]) -> Result<usize> {
        if digits.len() != self.dof() || digits.iter().any(|&d| d >= self.levels) {
            return Err(Error::InvalidDigits {
                digits: digits.to_vec(),
                dof: self.dof(),
                levels: self.levels,
            });
        }
        Ok(digits.iter().fold(0, |acc, &d| acc * self.levels + d))
    }

    /// Digits of an index (joint 1 first).
    pub fn digits(&self, index: usize) -> Result<Vec<usize>> {
        self.check_index(index)?;
        let mut d = vec![0; self.dof()];
        let mut rest = index;
        for v in d.iter_mut().rev() {
            *v = rest % self.levels;
            rest /= self.levels;
        }
        Ok(d)
    }

    pub(crate) fn check_index(&self, index: usize) -> Result<()> {
        if index >= self.size {
            return Err(Error::PoseNotInPool {
                index,
                reason: format!("the lattice has {} poses, 0..{}", self.size, self.size - 1),
            });
        }
        Ok(())
    }

    /// Joint angles (radians) of a lattice index, written into `q`.
    pub fn q_into(&self, index: usize, q: &mut [f64]) {
        let mut rest = index;
        for j in (0..self.dof()).rev() {
            let d = rest % self.levels;
            rest /= self.levels;
            let [lo, hi] = self.limits[j];
            // lo·(1−f) + hi·f is exact at both ends (lo + (hi−lo)·f is not at f = 1).
            let f = d as f64 / (self.levels - 1) as f64;
            q[j] = lo * (1.0 - f) + hi * f;
        }
    }

    /// Joint angles (radians) of a lattice index.
    pub fn q(&self, index: usize) -> Result<Vec<f64>> {
        self.check_index(index)?;
        let mut q = vec![0.0; self.dof()];
        self.q_into(index, &mut q);
        Ok(q)
    }
}

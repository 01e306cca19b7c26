//! The joint-space lattice of the paper: `levels` evenly spaced values per
//! joint, every combination, indexed with joint 1 the most significant digit.
//! A revolute joint whose evenly spaced levels would put two on one angle
//! (its range spans whole turns: the ±2π of a UR arm, where −2π, 0 and 2π
//! are one angle, or the ±π of its elbow) gets `levels` angles `2π/levels`
//! apart from its lower limit instead ([`super::turn`]). A range of more
//! than a turn whose levels are all distinct angles keeps them: the paper's
//! PUMA lattice (joint 6 over −176°..356°, levels at 184°, 317°, 90°, 223°
//! and 356° on the circle) is unchanged.

use crate::error::{Error, Result};
use crate::model::Robot;
use serde::Serialize;

/// A joint-space lattice of `levels` values per joint: `linspace(lo, hi,
/// levels)`, both ends included, or `lo + 2π·d/levels` for a joint whose
/// evenly spaced levels would repeat an angle (see the module docs). Pose
/// index `Σ digit_i · k^(n−1−i)`, joint 1
/// the most significant digit, 0-based (the paper's 030412 → 1982 with k = 5).
#[derive(Clone, Debug, Serialize)]
pub struct Lattice {
    /// Values per joint.
    pub levels: usize,
    /// Joint limits `[lo, hi]` in radians.
    pub limits: Vec<[f64; 2]>,
    /// Whether each joint is revolute.
    #[serde(skip)]
    revolute: Vec<bool>,
    /// Whether each joint turns all the way round (levels on the circle).
    #[serde(skip)]
    turns: Vec<bool>,
    size: usize,
}

/// Level `d` of `levels` evenly spaced over `[lo, hi]`, both ends included:
/// `lo·(1−f) + hi·f`, exact at both ends (`lo + (hi−lo)·f` is not at f = 1).
fn lerp([lo, hi]: [f64; 2], d: usize, levels: usize) -> f64 {
    let f = d as f64 / (levels - 1) as f64;
    lo * (1.0 - f) + hi * f
}

/// The `levels` evenly spaced values of `[lo, hi]`.
fn linspace(lim: [f64; 2], levels: usize) -> Vec<f64> {
    (0..levels).map(|d| lerp(lim, d, levels)).collect()
}

impl Lattice {
    /// A lattice over a robot's joint limits.
    pub fn new(robot: &Robot, levels: usize) -> Result<Lattice> {
        Self::within(robot, levels, &robot.limits)
    }

    /// A lattice over `limits` (the robot's, shrunk by a margin), whose
    /// joints are laid on the circle when the robot's own limits would put
    /// two evenly spaced levels on one angle and one turn of levels fits in
    /// `limits`.
    pub fn within(robot: &Robot, levels: usize, limits: &[[f64; 2]]) -> Result<Lattice> {
        if levels < 2 {
            return Err(Error::TooFewLevels(levels));
        }
        for (j, &[lo, hi]) in robot.limits.iter().chain(limits).enumerate() {
            let j = j % robot.dof().max(1);
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
        let revolute = super::turn::revolute_joints(robot);
        let turns = robot
            .limits
            .iter()
            .zip(limits)
            .zip(&revolute)
            .map(|((&own, &[lo, hi]), &r)| {
                let even = linspace(own, levels);
                let repeats = super::turn::distinct_values(r, &even) < levels;
                let turn_fits =
                    lo + std::f64::consts::TAU * (levels - 1) as f64 / levels as f64 <= hi;
                r && repeats && turn_fits
            })
            .collect();
        Ok(Lattice {
            levels,
            limits: limits.to_vec(),
            revolute,
            turns,
            size,
        })
    }

    /// The value of level `d` of joint `j`.
    fn level(&self, j: usize, d: usize) -> f64 {
        let [lo, _] = self.limits[j];
        if self.turns[j] {
            return lo + std::f64::consts::TAU * d as f64 / self.levels as f64;
        }
        lerp(self.limits[j], d, self.levels)
    }

    /// The values of joint `j`'s levels, in digit order.
    #[must_use]
    pub fn levels_of(&self, j: usize) -> Vec<f64> {
        (0..self.levels).map(|d| self.level(j, d)).collect()
    }

    /// Whether joint `j`'s levels are spaced on the circle (it turns all the
    /// way round).
    #[must_use]
    pub fn turns(&self, j: usize) -> bool {
        self.turns[j]
    }

    /// How many distinct places each joint's levels put it in (revolute
    /// values compared on one turn, [`super::turn::distinct_values`]).
    #[must_use]
    pub fn distinct_levels(&self) -> Vec<usize> {
        (0..self.dof())
            .map(|j| super::turn::distinct_values(self.revolute[j], &self.levels_of(j)))
            .collect()
    }

    /// How many distinct poses the lattice has: the product of
    /// [`distinct_levels`](Self::distinct_levels) (saturating).
    #[must_use]
    pub fn distinct_poses(&self) -> usize {
        self.distinct_levels()
            .iter()
            .fold(1usize, |a, &d| a.saturating_mul(d))
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
            q[j] = self.level(j, d);
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

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{PI, TAU};

    #[test]
    fn the_paper_lattice_keeps_its_even_levels() {
        // PUMA joint 6 spans 532°, more than a turn, but its 5 even levels
        // are 5 distinct angles: the paper's lattice is unchanged.
        let r = Robot::puma560();
        let l = Lattice::new(&r, 5).unwrap();
        for (j, &lim) in r.limits.iter().enumerate() {
            assert!(!l.turns(j));
            assert_eq!(l.levels_of(j), linspace(lim, 5));
        }
        assert_eq!(l.distinct_poses(), 15_625);
    }

    #[test]
    fn whole_turns_are_laid_on_the_circle() {
        let mut r = Robot::builtin("ur5").unwrap();
        r.limits = vec![
            [-TAU, TAU],
            [-PI, PI],
            [-1.0, 1.0],
            [-TAU, TAU],
            [-TAU, TAU],
            [-PI, PI],
        ];
        let l = Lattice::new(&r, 5).unwrap();
        assert_eq!(
            l.levels_of(0),
            (0..5)
                .map(|d| -TAU + TAU * d as f64 / 5.0)
                .collect::<Vec<_>>()
        );
        assert!(l.turns(1) && !l.turns(2));
        assert_eq!(l.distinct_poses(), 15_625);
        // With a margin the turn starts inside the lower limit.
        let m = 2f64.to_radians();
        let shrunk: Vec<[f64; 2]> = r.limits.iter().map(|&[a, b]| [a + m, b - m]).collect();
        let l = Lattice::within(&r, 5, &shrunk).unwrap();
        assert!(l.turns(0) && l.turns(1));
        assert_eq!(l.levels_of(1)[0], -PI + m);
        assert!(l.levels_of(1)[4] <= PI - m);
    }
}

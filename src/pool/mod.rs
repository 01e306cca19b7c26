//! Pose pools: the candidate joint configurations of a selection, from a
//! source (the joint-space [`Lattice`] today) through filters (sensor
//! visibility), and the identification Jacobian of every pose, built in one
//! parallel pass.

pub mod lattice;

pub use lattice::Lattice;

use crate::blocks::Blocks;
use crate::error::{Error, Result};
use crate::kinematics::position;
use crate::measure::Visibility;
use crate::model::{ParamTable, Robot};
use rayon::prelude::*;

/// The candidate poses: lattice indices that survive the visibility filter.
#[derive(Clone, Debug)]
pub struct Pool {
    /// The lattice the poses come from.
    pub lattice: Lattice,
    /// Lattice index of each pool pose, ascending.
    pub indices: Vec<usize>,
}

impl Pool {
    /// Every lattice pose.
    pub fn full(robot: &Robot, levels: usize) -> Result<Pool> {
        let lattice = Lattice::new(robot, levels)?;
        let indices = (0..lattice.size()).collect();
        Ok(Pool { lattice, indices })
    }

    /// The lattice poses whose end point (at `table`) the sensor sees. An
    /// empty result is an error.
    pub fn filtered(
        robot: &Robot,
        table: &ParamTable,
        levels: usize,
        vis: &Visibility,
    ) -> Result<Pool> {
        let lattice = Lattice::new(robot, levels)?;
        let indices: Vec<usize> = (0..lattice.size())
            .into_par_iter()
            .filter(|&i| {
                let mut q = vec![0.0; lattice.dof()];
                lattice.q_into(i, &mut q);
                vis.sees(&position(robot, table, &q))
            })
            .collect();
        if indices.is_empty() {
            return Err(Error::Invalid(
                "the visibility filter removed every pose of the pool".into(),
            ));
        }
        Ok(Pool { lattice, indices })
    }

    /// Number of pool poses.
    #[must_use]
    pub fn len(&self) -> usize {
        self.indices.len()
    }

    /// Whether the pool is empty.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.indices.is_empty()
    }

    /// Position in the pool of a lattice index, or an error saying why it is
    /// not there.
    pub fn position_of(&self, lattice_index: usize) -> Result<usize> {
        self.lattice.check_index(lattice_index)?;
        self.indices
            .binary_search(&lattice_index)
            .map_err(|_| Error::PoseNotInPool {
                index: lattice_index,
                reason: "removed by the visibility filter".into(),
            })
    }

    /// Positions in the pool of lattice indices.
    pub fn positions_of(&self, lattice_indices: &[usize]) -> Result<Vec<usize>> {
        lattice_indices
            .iter()
            .map(|&i| self.position_of(i))
            .collect()
    }

    /// Joint angles of pool pose `k`.
    #[must_use]
    pub fn q(&self, k: usize) -> Vec<f64> {
        let mut q = vec![0.0; self.lattice.dof()];
        self.lattice.q_into(self.indices[k], &mut q);
        q
    }

    /// Identification Jacobian of every pool pose (t rows per pose, p
    /// columns), computed in parallel; pose `k` at rows `t·k..t·k+t`.
    #[must_use]
    pub fn jacobian(&self, robot: &Robot, table: &ParamTable) -> Blocks {
        crate::blocks::jacobian_of(robot, table, self.len(), |k, q| {
            self.lattice.q_into(self.indices[k], q)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paper_index_example() {
        let r = Robot::puma560();
        let l = Lattice::new(&r, 5).unwrap();
        assert_eq!(l.size(), 15_625);
        assert_eq!(l.index_of(&[0, 3, 0, 4, 1, 2]).unwrap(), 1982);
        assert_eq!(l.digits(1982).unwrap(), vec![0, 3, 0, 4, 1, 2]);
        let q = l.q(0).unwrap();
        assert_eq!(q, r.limits.iter().map(|l| l[0]).collect::<Vec<_>>());
        let q = l.q(15_624).unwrap();
        assert_eq!(q, r.limits.iter().map(|l| l[1]).collect::<Vec<_>>());
        assert!(l.q(15_625).is_err());
        assert!(l.index_of(&[0, 5, 0, 0, 0, 0]).is_err());
        assert!(matches!(Lattice::new(&r, 1), Err(Error::TooFewLevels(1))));
    }

    #[test]
    fn visibility_filter_keeps_indices() {
        let r = Robot::puma560();
        let vis = Visibility::Box {
            min: [-100.0, -100.0, -100.0],
            max: [100.0, 100.0, 100.0],
        };
        let all = Pool::filtered(&r, &r.nominal, 3, &vis).unwrap();
        assert_eq!(all.len(), 729);
        // A cone around the direction to the base keeps some but not all.
        let base = position(&r, &r.nominal, &[0.0; 6]);
        let vis = Visibility::Cone {
            apex: [0.0; 3],
            axis: [base.x, base.y, base.z],
            half_angle: 0.02,
            max_range: 100.0,
        };
        let some = Pool::filtered(&r, &r.nominal, 3, &vis).unwrap();
        assert!(!some.is_empty() && some.len() < 729);
        for (k, &i) in some.indices.iter().enumerate() {
            assert_eq!(some.position_of(i).unwrap(), k);
            let p = position(&r, &r.nominal, &some.q(k));
            assert!(vis.sees(&p));
        }
        let hidden = (0..729)
            .find(|i| some.indices.binary_search(i).is_err())
            .unwrap();
        assert!(some.position_of(hidden).is_err());
        let none = Visibility::Box {
            min: [1e3; 3],
            max: [2e3; 3],
        };
        assert!(Pool::filtered(&r, &r.nominal, 3, &none).is_err());
    }
}

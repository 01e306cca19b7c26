//! Pose pools: the candidate joint configurations of a selection.
//!
//! A pool is made from a [`PoolSpec`]: a [`PoolSource`] (the joint-space
//! [`Lattice`] today) through [`PoolFilter`]s (sensor visibility). One
//! function, [`PoolSpec::build`], makes it for every command. The [`Pool`]
//! holds the configurations (contiguous, `n × dof`), a stable id per pose
//! (the lattice index for lattice poses) and the spec it was made from, and
//! computes the identification Jacobian of every pose in one parallel pass.
//!
//! A new source (random samples, a file of configurations) is a variant of
//! [`PoolSource`] and an arm of [`PoolSource::generate`]; nothing else
//! changes.

pub mod lattice;

pub use lattice::Lattice;

use crate::blocks::Blocks;
use crate::error::{Error, Result};
use crate::kinematics::position;
use crate::measure::Visibility;
use crate::model::{ParamTable, Robot};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Where the candidate configurations come from.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PoolSource {
    /// Every pose of a joint-space lattice of `levels` values per joint; a
    /// pose's id is its lattice index.
    Lattice {
        /// Values per joint.
        levels: usize,
    },
}

/// A rule that removes candidate configurations.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PoolFilter {
    /// Keep the poses whose end point (at the build's parameter table) the
    /// sensor sees.
    Visibility(Visibility),
}

impl PoolFilter {
    /// Whether the configuration `q` passes.
    fn keeps(&self, robot: &Robot, table: &ParamTable, q: &[f64]) -> bool {
        match self {
            PoolFilter::Visibility(v) => v.sees(&position(robot, table, q)),
        }
    }
}

/// How a pool is made: a source, then filters in order.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct PoolSpec {
    /// The candidate configurations before filtering.
    pub source: PoolSource,
    /// Filters applied to every candidate (none: keep them all).
    #[serde(default)]
    pub filters: Vec<PoolFilter>,
}

impl PoolSpec {
    /// Every pose of a `levels`-value lattice, unfiltered.
    #[must_use]
    pub fn lattice(levels: usize) -> Self {
        Self {
            source: PoolSource::Lattice { levels },
            filters: Vec::new(),
        }
    }

    /// The spec with one more filter.
    #[must_use]
    pub fn with_filter(mut self, filter: PoolFilter) -> Self {
        self.filters.push(filter);
        self
    }

    /// Lattice values per joint, when the source is a lattice.
    #[must_use]
    pub fn levels(&self) -> Option<usize> {
        match self.source {
            PoolSource::Lattice { levels } => Some(levels),
        }
    }

    /// Builds the pool for `robot`: generates the source's configurations
    /// and keeps those that pass every filter (evaluated at `table`, the
    /// model the sensor region is known in, usually the nominal one). A pool
    /// that the filters leave empty is an error, and so is a filter whose
    /// region is malformed ([`Visibility::validate`]).
    pub fn build(&self, robot: &Robot, table: &ParamTable) -> Result<Pool> {
        for f in &self.filters {
            match f {
                PoolFilter::Visibility(v) => v
                    .validate()
                    .map_err(|e| Error::Invalid(format!("visibility filter: {e}")))?,
            }
        }
        let n = match self.source {
            PoolSource::Lattice { levels } => Lattice::new(robot, levels)?.size(),
        };
        check_memory(robot, n)?;
        let (ids, lattice) = self.source.generate(robot, |q| {
            self.filters.iter().all(|f| f.keeps(robot, table, q))
        })?;
        if ids.is_empty() {
            return Err(Error::Invalid(
                "the visibility filter removed every pose of the pool".into(),
            ));
        }
        let dof = robot.dof();
        let mut q = vec![0.0; ids.len() * dof];
        if dof > 0 {
            q.par_chunks_mut(dof)
                .zip(ids.par_iter())
                .for_each(|(row, &id)| self.source.fill(lattice.as_ref(), id, row));
        }
        Ok(Pool {
            spec: self.clone(),
            dof,
            q,
            ids,
            lattice,
        })
    }
}

/// Bytes a pool of `n` candidates takes through selection: its id and joint
/// values, its identification Jacobian (`t·p` values a pose), and one
/// workspace of the Jacobian's size (the pool variances' `Y = X L⁻ᵀ`, the
/// bound's scaled copy).
#[must_use]
pub fn memory_estimate(robot: &Robot, n: usize) -> u64 {
    let per_pose = 8 * (1 + robot.dof() + 2 * robot.rows_per_pose() * robot.n_unknowns());
    crate::resources::bytes_of(n, per_pose)
}

/// Refuses, before anything is allocated, a pool whose
/// [`memory_estimate`] exceeds the memory budget.
fn check_memory(robot: &Robot, n: usize) -> Result<()> {
    crate::resources::MemoryBudget::from_env()?.check(
        &format!(
            "a pool of {n} poses (its {}×{} Jacobian and one workspace of that size)",
            n.saturating_mul(robot.rows_per_pose()),
            robot.n_unknowns()
        ),
        memory_estimate(robot, n),
    )
}

impl PoolSource {
    /// The ids of the candidates that `keep` accepts, ascending, and the
    /// lattice when the source is one.
    fn generate<K>(&self, robot: &Robot, keep: K) -> Result<(Vec<usize>, Option<Lattice>)>
    where
        K: Fn(&[f64]) -> bool + Sync,
    {
        match *self {
            PoolSource::Lattice { levels } => {
                let lattice = Lattice::new(robot, levels)?;
                let ids = (0..lattice.size())
                    .into_par_iter()
                    .filter(|&i| {
                        let mut q = vec![0.0; lattice.dof()];
                        lattice.q_into(i, &mut q);
                        keep(&q)
                    })
                    .collect();
                Ok((ids, Some(lattice)))
            }
        }
    }

    /// Writes the configuration of candidate `id` into `q`.
    fn fill(&self, lattice: Option<&Lattice>, id: usize, q: &mut [f64]) {
        match self {
            PoolSource::Lattice { .. } => lattice
                .expect("a lattice source has its lattice")
                .q_into(id, q),
        }
    }

    /// Why an id is not a candidate of the source at all, if it is not.
    fn check_id(&self, lattice: Option<&Lattice>, id: usize) -> Result<()> {
        match self {
            PoolSource::Lattice { .. } => lattice.map_or(Ok(()), |l| l.check_index(id)),
        }
    }
}

/// The candidate poses: joint configurations with stable ids, made from a
/// [`PoolSpec`].
#[derive(Clone, Debug)]
pub struct Pool {
    /// How the pool was made.
    pub spec: PoolSpec,
    dof: usize,
    /// Configurations, `n × dof`, row-major.
    q: Vec<f64>,
    /// Stable id of each pool pose, ascending (the lattice index for lattice
    /// poses).
    pub ids: Vec<usize>,
    lattice: Option<Lattice>,
}

impl Pool {
    /// Every pose of a `levels`-value lattice ([`PoolSpec::lattice`]); the
    /// filter evaluation needs no parameter table.
    pub fn full(robot: &Robot, levels: usize) -> Result<Pool> {
        PoolSpec::lattice(levels).build(robot, &robot.nominal)
    }

    /// The lattice poses whose end point (at `table`) the sensor sees. An
    /// empty result is an error.
    pub fn filtered(
        robot: &Robot,
        table: &ParamTable,
        levels: usize,
        vis: &Visibility,
    ) -> Result<Pool> {
        PoolSpec::lattice(levels)
            .with_filter(PoolFilter::Visibility(vis.clone()))
            .build(robot, table)
    }

    /// Number of pool poses.
    #[must_use]
    pub fn len(&self) -> usize {
        self.ids.len()
    }

    /// Whether the pool is empty.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.ids.is_empty()
    }

    /// Number of joints.
    #[must_use]
    pub fn dof(&self) -> usize {
        self.dof
    }

    /// The lattice the poses come from, when the source is a lattice.
    #[must_use]
    pub fn lattice(&self) -> Option<&Lattice> {
        self.lattice.as_ref()
    }

    /// Stable id of pool pose `k`.
    #[must_use]
    pub fn id(&self, k: usize) -> usize {
        self.ids[k]
    }

    /// Stable ids of pool poses.
    #[must_use]
    pub fn ids_of(&self, positions: &[usize]) -> Vec<usize> {
        positions.iter().map(|&k| self.ids[k]).collect()
    }

    /// Position in the pool of a pose id, or an error saying why it is not
    /// there.
    pub fn position_of(&self, id: usize) -> Result<usize> {
        self.spec.source.check_id(self.lattice.as_ref(), id)?;
        self.ids
            .binary_search(&id)
            .map_err(|_| Error::PoseNotInPool {
                index: id,
                reason: "removed by the visibility filter".into(),
            })
    }

    /// Positions in the pool of pose ids.
    pub fn positions_of(&self, ids: &[usize]) -> Result<Vec<usize>> {
        ids.iter().map(|&i| self.position_of(i)).collect()
    }

    /// Joint values of pool pose `k`.
    #[must_use]
    pub fn config(&self, k: usize) -> &[f64] {
        &self.q[k * self.dof..(k + 1) * self.dof]
    }

    /// Joint values of every pool pose, `n × dof`, row-major.
    #[must_use]
    pub fn configs(&self) -> &[f64] {
        &self.q
    }

    /// Joint values of pool pose `k`, owned.
    #[must_use]
    pub fn q(&self, k: usize) -> Vec<f64> {
        self.config(k).to_vec()
    }

    /// Identification Jacobian of every pool pose (t rows per pose, p
    /// columns), computed in parallel; pose `k` at rows `t·k..t·k+t`.
    #[must_use]
    pub fn jacobian(&self, robot: &Robot, table: &ParamTable) -> Blocks {
        crate::blocks::jacobian_of(robot, table, self.len(), |k, q| {
            q.copy_from_slice(self.config(k));
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
    fn lattice_pool_holds_configurations_ids_and_spec() {
        let r = Robot::puma560();
        let pool = PoolSpec::lattice(3).build(&r, &r.nominal).unwrap();
        assert_eq!(pool.len(), 729);
        assert_eq!(pool.configs().len(), 729 * 6);
        assert_eq!(pool.spec.levels(), Some(3));
        let l = pool.lattice().unwrap();
        for k in [0, 1, 364, 728] {
            assert_eq!(pool.id(k), k);
            assert_eq!(pool.config(k), l.q(k).unwrap().as_slice());
        }
        // The spec round-trips through JSON.
        let text = serde_json::to_string(&pool.spec).unwrap();
        let back: PoolSpec = serde_json::from_str(&text).unwrap();
        assert_eq!(back.source, PoolSource::Lattice { levels: 3 });
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
        let lattice = some.lattice().unwrap().clone();
        for (k, &i) in some.ids.iter().enumerate() {
            assert_eq!(some.position_of(i).unwrap(), k);
            assert_eq!(some.q(k), lattice.q(i).unwrap());
            let p = position(&r, &r.nominal, &some.q(k));
            assert!(vis.sees(&p));
        }
        let hidden = (0..729)
            .find(|i| some.ids.binary_search(i).is_err())
            .unwrap();
        assert!(some.position_of(hidden).is_err());
        assert!(some.position_of(729).is_err());
        let none = Visibility::Box {
            min: [1e3; 3],
            max: [2e3; 3],
        };
        assert!(Pool::filtered(&r, &r.nominal, 3, &none).is_err());
    }
}

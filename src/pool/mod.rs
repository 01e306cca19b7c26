//! Pose pools: the candidate joint configurations of a selection.
//!
//! A pool is made from a [`PoolSpec`]: a [`PoolSource`] (the joint-space
//! [`Lattice`], uniform random or Sobol samples inside the joint limits
//! ([`sampled`]), or a file of configurations ([`file`](mod@file))) through
//! [`PoolFilter`]s (sensor visibility). One function, [`PoolSpec::build`],
//! makes it for every command. The [`Pool`] holds the configurations
//! (contiguous, `n × dof`), a stable id per pose (its index in the source:
//! the lattice index, the sample number, the file's data row), the spec it
//! was made from and what each filter removed ([`PoolStats`]), and computes
//! the identification Jacobian of every pose in one parallel pass.
//!
//! A new source is a variant of [`PoolSource`] and an arm of the private
//! `Candidates` (its size and the configuration of an id); nothing else
//! changes.

mod build;
pub mod camera_view;
pub mod file;
pub mod lattice;
pub mod line_of_sight;
pub mod sampled;
mod source_kind;
pub mod stats;
pub mod summary;
pub mod turn;

pub use crate::pool::file::{Configurations, read_configurations, read_configurations_in};
pub use build::memory_estimate;
pub use lattice::Lattice;
pub use sampled::{Sobol, Uniform};
pub use source_kind::{DEFAULT_COUNT, DEFAULT_LEVELS, PoolKind};

use crate::blocks::Blocks;
use crate::collision::CollisionFilter;
use crate::error::{Error, Result};
use crate::kinematics::position;
use crate::measure::Visibility;
use crate::model::{ParamTable, Robot};
use serde::{Deserialize, Serialize};

/// Where the candidate configurations come from. A pose's id is its index
/// in the source (before filtering), so ids are stable: the same spec gives
/// the same ids and joint values on every machine and thread count.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PoolSource {
    /// Every pose of a joint-space lattice of `levels` values per joint; a
    /// pose's id is its lattice index.
    Lattice {
        /// Values per joint.
        levels: usize,
    },
    /// `count` configurations drawn uniformly inside the joint limits from
    /// ChaCha8 seeded with `seed` ([`Uniform`]); id `k` is the `k`-th draw.
    Random {
        /// Samples.
        count: usize,
        /// Seed of the stream.
        seed: u64,
    },
    /// The first `count` points of the Sobol sequence mapped onto the joint
    /// box ([`Sobol`]); id `k` is point `k`. With a seed, the sequence is
    /// scrambled (random linear matrix and digital shift).
    Sobol {
        /// Points.
        count: usize,
        /// Seed of the scramble; none for the plain sequence.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        seed: Option<u64>,
    },
    /// Joint configurations listed in a CSV or JSON file
    /// ([`file`](mod@self::file)); id `k` is the `k`-th data row (0-based).
    File {
        /// The file, as given.
        path: String,
    },
}

impl PoolSource {
    /// A short name: `lattice`, `random`, `sobol` or `file`.
    #[must_use]
    pub fn kind(&self) -> &'static str {
        match self {
            PoolSource::Lattice { .. } => "lattice",
            PoolSource::Random { .. } => "random",
            PoolSource::Sobol { .. } => "sobol",
            PoolSource::File { .. } => "file",
        }
    }

    /// Number of candidates before any file is read, when the spec alone
    /// says it (every source but a file).
    fn declared_size(&self, robot: &Robot) -> Result<Option<usize>> {
        Ok(match *self {
            PoolSource::Lattice { levels } => Some(Lattice::new(robot, levels)?.size()),
            PoolSource::Random { count, .. } | PoolSource::Sobol { count, .. } => Some(count),
            PoolSource::File { .. } => None,
        })
    }
}

/// A rule that removes candidate configurations.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PoolFilter {
    /// Keep the poses whose end point (at the build's parameter table) the
    /// sensor sees.
    Visibility(Visibility),
    /// Keep the poses where no two links touch and no link touches an
    /// obstacle ([`crate::collision`]).
    Collision(CollisionFilter),
    /// Keep the poses where a camera sees its target well
    /// ([`camera_view`]).
    Camera(camera_view::CameraView),
}

impl PoolFilter {
    /// Whether the configuration `q` passes (evaluated at `table`).
    #[must_use]
    pub fn keeps(&self, robot: &Robot, table: &ParamTable, q: &[f64]) -> bool {
        match self {
            PoolFilter::Visibility(v) => v.sees(&position(robot, table, q)),
            PoolFilter::Collision(c) => c.keeps(q),
            PoolFilter::Camera(c) => c.keeps(robot, table, q),
        }
    }

    /// A short name: `visibility`, `self-collision`, `obstacles`,
    /// `collision` or `camera view`.
    #[must_use]
    pub fn kind(&self) -> &'static str {
        match self {
            PoolFilter::Visibility(_) => "visibility",
            PoolFilter::Collision(c) => c.kind(),
            PoolFilter::Camera(_) => "camera view",
        }
    }
}

/// How many candidates one filter removed.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FilterStat {
    /// The filter ([`PoolFilter::kind`]).
    pub filter: String,
    /// Candidates that reached it (passed every filter before it).
    pub seen: usize,
    /// Of those, the ones it removed.
    pub removed: usize,
    /// For a collision filter: which pairs of links (or link and obstacle)
    /// removed them.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub contacts: Option<stats::ContactCounts>,
    /// A warning: the filter removed more than [`stats::MOST`] of what
    /// reached it (naming the pair that removed most).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub warning: Option<String>,
}

/// What building a pool did: candidates of the source, what each filter
/// removed, what was kept, and notes (columns of a file that were ignored).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PoolStats {
    /// Candidates of the source, before filtering.
    pub candidates: usize,
    /// One entry per filter, in the order they were applied.
    pub filters: Vec<FilterStat>,
    /// Candidates kept.
    pub kept: usize,
    /// Notes (ignored columns of a configuration file).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub notes: Vec<String>,
}

/// How a pool is made: a source, then filters in order.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct PoolSpec {
    /// The candidate configurations before filtering.
    pub source: PoolSource,
    /// Filters applied to every candidate (none: keep them all).
    #[serde(default)]
    pub filters: Vec<PoolFilter>,
    /// Margin kept inside every revolute joint's limits, radians
    /// ([`turn::shrunk_limits`]): a lattice or sampled source is made over
    /// the shrunk ranges; a file's rows closer to a limit are removed (the
    /// `margin` entry of the pool statistics). 0 (the default): the limits.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub margin: f64,
}

#[allow(clippy::trivially_copy_pass_by_ref)]
fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

/// The joint-limit margin of a URDF robot's generated pool when none is
/// given, degrees: clear of the hard stops, where a badly calibrated arm's
/// controller faults, by more than a calibration's usual joint offsets
/// (tenths of a degree).
pub const DEFAULT_URDF_MARGIN_DEG: f64 = 2.0;

/// The joint-limit margin of a pool when none is given, degrees:
/// [`DEFAULT_URDF_MARGIN_DEG`] for a URDF robot (`urdf`) and a generated
/// pool, else 0 (a built-in arm keeps the paper's lattice, a `.toml`
/// description states its limits as its pools should use them, listed
/// configurations are taken as given).
#[must_use]
pub fn default_margin_deg(urdf: bool, source: &PoolSource) -> f64 {
    if urdf && !matches!(source, PoolSource::File { .. }) {
        DEFAULT_URDF_MARGIN_DEG
    } else {
        0.0
    }
}

impl PoolSpec {
    /// Every pose of a `levels`-value lattice, unfiltered.
    #[must_use]
    pub fn lattice(levels: usize) -> Self {
        Self::of(PoolSource::Lattice { levels })
    }

    /// The unfiltered pool of a source.
    #[must_use]
    pub fn of(source: PoolSource) -> Self {
        Self {
            source,
            filters: Vec::new(),
            margin: 0.0,
        }
    }

    /// The spec with a joint-limit margin of `margin` radians.
    #[must_use]
    pub fn with_margin(mut self, margin: f64) -> Self {
        self.margin = margin;
        self
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
            _ => None,
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
    /// Candidates of the source before filtering (ids are below it).
    source_size: usize,
    /// What the build did (candidates, removals per filter, notes).
    pub stats: PoolStats,
    /// Every configuration of a file source, before filtering, in id order.
    listed: Option<Vec<Vec<f64>>>,
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

    /// Every configuration of a [`PoolSource::File`] source, before
    /// filtering, in id order (what a design file stores so that it needs
    /// no access to the file); `None` for the other sources, which their
    /// spec regenerates.
    #[must_use]
    pub fn listed(&self) -> Option<&[Vec<f64>]> {
        self.listed.as_deref()
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
        if let Some(l) = &self.lattice {
            l.check_index(id)?;
        } else if id >= self.source_size {
            return Err(Error::PoseNotInPool {
                index: id,
                reason: format!(
                    "the {} source has {} candidates, 0..{}",
                    self.spec.source.kind(),
                    self.source_size,
                    self.source_size - 1
                ),
            });
        }
        self.ids
            .binary_search(&id)
            .map_err(|_| Error::PoseNotInPool {
                index: id,
                reason: format!(
                    "removed by the pool's {} filter",
                    self.spec
                        .filters
                        .iter()
                        .map(PoolFilter::kind)
                        .collect::<Vec<_>>()
                        .join(" or ")
                ),
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

    /// [`jacobian`](Self::jacobian) with the matrix reserved fallibly: an
    /// allocation the system refuses is an error naming the pool and the
    /// figure, not an abort.
    pub fn try_jacobian(&self, robot: &Robot, table: &ParamTable) -> Result<Blocks> {
        let what = format!(
            "the {}×{} Jacobian of a pool of {} poses",
            self.len() * robot.rows_per_pose(),
            robot.n_params(),
            self.len()
        );
        crate::blocks::try_jacobian_of(&what, robot, table, self.len(), |k, q| {
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

//! What `pool` reports about a built pool: its size, how many of its poses
//! are distinct (a pool whose poses repeat is refused), the lattice's levels
//! per joint, and the kept poses written out as a configuration file.

use super::{Pool, PoolStats, turn};
use crate::error::{Error, Result};
use crate::model::Robot;
use crate::pool::file::joint_names;
use serde::Serialize;

/// One joint of a lattice: its levels and how many distinct places they are.
#[derive(Clone, Debug, Serialize)]
pub struct LatticeJoint {
    /// The joint's name (the chain's label).
    pub name: String,
    /// The level values, radians or metres, in digit order.
    pub levels: Vec<f64>,
    /// Distinct places among them (revolute values compared on one turn).
    pub distinct: usize,
    /// Whether the levels are spaced on the circle (a joint that turns all
    /// the way round).
    pub full_turn: bool,
}

/// A built pool, as `pool` reports it.
#[derive(Clone, Debug, Serialize)]
pub struct PoolSummary {
    /// Robot name or description path.
    pub robot: String,
    /// The chain's joint names, in configuration order.
    pub joints: Vec<String>,
    /// How the pool was made.
    pub pool: super::PoolSpec,
    /// Candidates, what each filter removed, what was kept.
    pub pool_stats: PoolStats,
    /// Poses kept.
    pub size: usize,
    /// Distinct poses among them (equal to `size`: a pool with repeats is
    /// refused).
    pub distinct: usize,
    /// The lattice's joints, when the source is a lattice.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lattice: Option<Vec<LatticeJoint>>,
}

impl PoolSummary {
    /// The summary of `pool` for `robot`; an error when two of its poses are
    /// one pose (naming the joints whose levels repeat for a lattice, the two
    /// ids otherwise).
    pub fn new(robot: &Robot, pool: &Pool) -> Result<Self> {
        let names = joint_names(robot);
        let revolute = turn::revolute_joints(robot);
        let lattice = pool.lattice().map(|l| {
            let distinct = l.distinct_levels();
            (0..l.dof())
                .map(|j| LatticeJoint {
                    name: names[j].clone(),
                    levels: l.levels_of(j),
                    distinct: distinct[j],
                    full_turn: l.turns(j),
                })
                .collect::<Vec<_>>()
        });
        if let Some(js) = &lattice
            && let Some(j) = js.iter().position(|j| j.distinct < j.levels.len())
        {
            let l = pool.lattice().expect("a lattice pool");
            return Err(Error::Invalid(format!(
                "the {}-level lattice has {} distinct poses of {}: the {} levels of joint {} '{}' ({:?}) are {} distinct places",
                l.levels,
                l.distinct_poses(),
                l.size(),
                js[j].levels.len(),
                j + 1,
                js[j].name,
                js[j].levels,
                js[j].distinct
            )));
        }
        if let Some((a, b)) = turn::first_repeat(&revolute, pool.configs()) {
            return Err(Error::Invalid(format!(
                "poses {} and {} of the pool are one pose ({:?} and {:?}; revolute joints compared on one turn, to {:e})",
                pool.id(a),
                pool.id(b),
                pool.config(a),
                pool.config(b),
                turn::SAME_TOL
            )));
        }
        Ok(Self {
            robot: robot.name.clone(),
            joints: names,
            pool: pool.spec.clone(),
            pool_stats: pool.stats.clone(),
            size: pool.len(),
            distinct: pool.len(),
            lattice,
        })
    }
}

/// The poses `positions` of `pool` as CSV: a header of the joint names and
/// `id`, one pose a row (full precision: the shortest text that reads back
/// as the same `f64`), as `--pool file:` reads it.
#[must_use]
pub fn poses_csv(names: &[String], qs: &[Vec<f64>], ids: &[usize]) -> String {
    let mut s = names.join(",") + ",id\n";
    for (q, id) in qs.iter().zip(ids) {
        for v in q {
            s += &format!("{v:?},");
        }
        s += &format!("{id}\n");
    }
    s
}

/// The poses as JSON `{"robot", "joints", "ids", "qs"}`, as `--pool file:`
/// reads it.
#[must_use]
pub fn poses_json(robot: &str, names: &[String], qs: &[Vec<f64>], ids: &[usize]) -> String {
    let v = serde_json::json!({ "robot": robot, "joints": names, "ids": ids, "qs": qs });
    serde_json::to_string_pretty(&v).expect("poses serialize") + "\n"
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pool::PoolSpec;

    #[test]
    fn a_lattice_summary_counts_distinct_poses() {
        let r = Robot::puma560();
        let pool = PoolSpec::lattice(3).build(&r, &r.nominal).unwrap();
        let s = PoolSummary::new(&r, &pool).unwrap();
        assert_eq!((s.size, s.distinct), (729, 729));
        let l = s.lattice.unwrap();
        assert!(l.iter().all(|j| j.distinct == 3 && !j.full_turn));
    }

    #[test]
    fn csv_of_poses_reads_back_exactly() {
        let r = Robot::puma560();
        let pool = PoolSpec::lattice(3).build(&r, &r.nominal).unwrap();
        let qs: Vec<Vec<f64>> = [5, 100, 700].iter().map(|&k| pool.q(k)).collect();
        let text = poses_csv(&joint_names(&r), &qs, &[5, 100, 700]);
        let back = crate::pool::file::parse_csv(std::path::Path::new("p.csv"), &text, &r).unwrap();
        assert_eq!(back.qs, qs);
        let text = poses_json(&r.name, &joint_names(&r), &qs, &[5, 100, 700]);
        let back =
            crate::pool::file::parse_json(std::path::Path::new("p.json"), &text, &r).unwrap();
        assert_eq!(back.qs, qs);
    }
}

//! Pose pools: a joint-space lattice, an optional sensor-visibility filter, and
//! the identification Jacobian of every pose, built in one parallel pass.

use crate::blocks::Blocks;
use crate::error::{Error, Result};
use crate::kinematics::{Evaluator, position};
use crate::robot::{ParamTable, Robot};
use nalgebra::Vector3;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

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

    fn check_index(&self, index: usize) -> Result<()> {
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

/// A simple sensor-visibility region in the measurement frame: a pose is
/// visible when its end point (at nominal parameters) lies inside.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase", deny_unknown_fields)]
pub enum Visibility {
    /// Every pose is visible.
    All,
    /// A viewing cone: apex at the sensor, unit axis, half-angle (radians),
    /// optional maximum range (metres).
    Cone {
        /// Sensor position.
        apex: [f64; 3],
        /// Viewing direction (normalised on use).
        axis: [f64; 3],
        /// Half-angle in radians.
        half_angle: f64,
        /// Maximum distance from the apex.
        max_range: f64,
    },
    /// An axis-aligned box.
    Box {
        /// Lower corner.
        min: [f64; 3],
        /// Upper corner.
        max: [f64; 3],
    },
}

impl Visibility {
    /// Whether a point is visible.
    #[must_use]
    pub fn sees(&self, p: &Vector3<f64>) -> bool {
        match self {
            Visibility::All => true,
            Visibility::Cone {
                apex,
                axis,
                half_angle,
                max_range,
            } => {
                let v = p - Vector3::from(*apex);
                let ax = Vector3::from(*axis).normalize();
                let dist = v.norm();
                dist <= *max_range && (dist == 0.0 || v.dot(&ax) / dist >= half_angle.cos())
            }
            Visibility::Box { min, max } => (0..3).all(|i| p[i] >= min[i] && p[i] <= max[i]),
        }
    }
}

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
        jacobian_of(robot, table, self.len(), |k, q| {
            self.lattice.q_into(self.indices[k], q)
        })
    }
}

/// Identification Jacobian of `n` poses whose joint angles `fill_q(k, q)`
/// writes, computed in parallel into one [`Blocks`].
pub fn jacobian_of<F>(robot: &Robot, table: &ParamTable, n: usize, fill_q: F) -> Blocks
where
    F: Fn(usize, &mut [f64]) + Sync,
{
    let p = robot.n_unknowns();
    let t = robot.rows_per_pose();
    let dof = robot.dof();
    // Written straight into the column-major matrix, chunk by chunk of rows
    // (no row-major copy: a 10⁶-pose pool's Jacobian is 650 MB already).
    let mut mat = faer::Mat::<f64>::zeros(n * t, p);
    const CHUNK: usize = 256;
    mat.as_mut()
        .par_row_chunks_mut(CHUNK * t)
        .enumerate()
        .for_each(|(c, mut chunk)| {
            let mut ev = Evaluator::new(robot, table);
            let mut q = vec![0.0; dof];
            let mut jac = vec![0.0; t * p];
            for k in 0..chunk.nrows() / t {
                fill_q(c * CHUNK + k, &mut q);
                ev.eval(&q, &mut jac);
                for r in 0..t {
                    for col in 0..p {
                        chunk[(k * t + r, col)] = jac[r * p + col];
                    }
                }
            }
        });
    Blocks::new(mat, t)
}

/// Result of an identifiability check.
#[derive(Clone, Debug, Serialize)]
pub struct Identifiability {
    /// Numerical rank of the column-scaled stacked Jacobian.
    pub rank: usize,
    /// Number of unknowns.
    pub p: usize,
    /// Unknowns with a significant component in the numerical null space.
    pub unidentifiable: Vec<String>,
    /// Singular values of the column-scaled Jacobian, largest first.
    pub singular_values: Vec<f64>,
}

/// Numerical rank of a stacked Jacobian and the unknowns it cannot determine.
///
/// Columns are scaled to unit norm first (rank is scale-invariant, the
/// tolerance is not); a zero column is unidentifiable outright. Singular
/// values below `max(rows, p) · ε · σ_max` count as zero, and an unknown is
/// named when its entry in a null-space vector exceeds 1e-6 in magnitude.
#[must_use]
pub fn identifiability(robot: &Robot, x: &Blocks) -> Identifiability {
    let m = x.mat();
    let (rows, p) = (m.nrows(), m.ncols());
    let norms: Vec<f64> = (0..p).map(|c| m.col(c).norm_l2()).collect();
    let scaled = faer::Mat::from_fn(rows, p, |r, c| {
        if norms[c] > 0.0 {
            m[(r, c)] / norms[c]
        } else {
            0.0
        }
    });
    let names = robot.parameter_names();
    let svd = scaled.svd().expect("SVD of a finite matrix converges");
    let s: Vec<f64> = (0..p.min(rows)).map(|i| svd.S()[i]).collect();
    let smax = s.iter().cloned().fold(0.0, f64::max);
    let tol = rows.max(p) as f64 * f64::EPSILON * smax.max(f64::MIN_POSITIVE);
    let rank = s.iter().filter(|&&v| v > tol).count();
    let v = svd.V();
    let mut flagged = vec![false; p];
    for k in rank..p {
        for (c, f) in flagged.iter_mut().enumerate() {
            if v[(c, k)].abs() > 1e-6 {
                *f = true;
            }
        }
    }
    let unidentifiable = names
        .into_iter()
        .zip(flagged)
        .filter(|(_, f)| *f)
        .map(|(n, _)| n)
        .collect();
    Identifiability {
        rank,
        p,
        unidentifiable,
        singular_values: s,
    }
}

/// Checks that every unknown is identifiable from `x`, or returns
/// [`Error::Unidentifiable`] naming the ones that are not.
pub fn require_identifiable(robot: &Robot, x: &Blocks) -> Result<Identifiability> {
    let id = identifiability(robot, x);
    if id.rank < id.p {
        return Err(Error::Unidentifiable {
            names: id.unidentifiable.clone(),
            rank: id.rank,
            p: id.p,
        });
    }
    Ok(id)
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

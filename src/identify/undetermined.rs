//! What measured data cannot see: before a fit, the unknowns the given data
//! do not determine are found on the data's own Jacobian at the start and
//! fixed at their start (nominal) values, each with a reason, so that the
//! fit goes on with the rest instead of ending rank deficient.
//!
//! The rule is the one every command shares (`linalg::rank`): rank
//! on the column-scaled Jacobian, which no change of units moves. The
//! columns are scaled to unit norm and factored by a column-pivoted QR
//! (modified Gram–Schmidt, twice, the largest remaining column first) in
//! three groups, each pivoted within itself:
//! 1. always kept: the sensor's own marker offsets and the parameters the
//!    caller forces free (`--free`);
//! 2. the other unknowns;
//! 3. the unknowns of the frames that move or place the axis of a joint
//!    that never moves in these data (its column constant over the rows):
//!    the frame it drives and the frames before it up to the previous
//!    driven one — pivoted last, so that those are the parameters fixed
//!    and the reason can name the joint.
//!
//! A column whose remaining norm is at or below [`PIVOT_TOL`] is not
//! determined. The kept set is then checked with the rank rule itself, and
//! the last kept pivots (outside group 1) are dropped until it passes.

use super::{Calibration, Residuals, Result};
use crate::data::Measurements;
use crate::linalg::rank::{MAX_CONDITION, equilibrated_rank};
use crate::model::{ParamTable, Robot};
use crate::units::joint_names;
use faer::Mat;
use serde::Serialize;

/// A pivot (the norm of a unit column's part orthogonal to the columns
/// kept before it) at or below this marks the column as not determined:
/// `√p`·10 / √MAX_CONDITION for `p` columns would be exact for the rank
/// rule if the pivots were the singular values; this constant takes `p ≤
/// 100` (√p ≤ 10), so `100 / √1e13 = 3.2e-5`. A frozen joint leaves exact
/// dependences (pivots of 1e-15 and below, rounding), real near-
/// dependences of a well-spread data set stay above 1e-3; the final rank
/// check catches what the pivots alone would let through.
pub const PIVOT_TOL: f64 = 3.162_277_660_168_379_5e-5;

/// A joint whose values differ by no more than this over the rows (radians
/// or metres) never moves in the data.
pub const FROZEN_JOINT_SPAN: f64 = 1e-12;

/// A parameter fixed because the data do not determine it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FixedParameter {
    /// The parameter's name.
    pub name: String,
    /// The value it is held at (the start table's: nominal).
    pub value: f64,
    /// Why the data do not determine it.
    pub reason: String,
}

/// The robot reduced to the unknowns the data determine.
#[derive(Clone, Debug)]
pub struct Determined {
    /// The robot with the undetermined unknowns removed (held at their
    /// values in the start table).
    pub robot: Robot,
    /// What was fixed and why, in parameter order.
    pub fixed: Vec<FixedParameter>,
}

/// The reason given for a parameter that is not determined and belongs to
/// no frozen joint.
pub const GENERIC_REASON: &str =
    "not determined by these data (column-pivoted QR on the column-scaled Jacobian)";

/// The reason given for a joint compliance the data do not tell from the
/// geometry.
pub const COMPLIANCE_REASON: &str = "compliance not determined by these data: the sag it would explain is indistinguishable from the geometry's (held at 0)";

/// Finds the unknowns of `robot` that `meas` do not determine at `start`
/// and fixes them (see the module documentation); `keep` names the
/// parameters never to fix (the user's `--free`).
pub fn fix_undetermined(
    robot: &Robot,
    start: &ParamTable,
    meas: &Measurements,
    keep: &[String],
) -> Result<Determined> {
    // The Jacobian checks the data against the robot first.
    let x = jacobian_at(robot, start, meas)?;
    fix_undetermined_of(robot, start, meas.qs(), &x, keep)
}

/// As [`fix_undetermined`], on a given Jacobian `x` of the poses `qs` (its
/// columns: `robot`'s unknowns, then a sensor's own unknowns, which are
/// always kept): for sensors that are not the robot's own
/// ([`crate::measure::contact`]).
pub fn fix_undetermined_of(
    robot: &Robot,
    start: &ParamTable,
    qs: &[Vec<f64>],
    x: &Mat<f64>,
    keep: &[String],
) -> Result<Determined> {
    fix_undetermined_below(robot, start, qs, x, keep, PIVOT_TOL)
}

/// As [`fix_undetermined_of`], fixing the columns whose pivot is at or
/// below `pivot_tol` (not [`PIVOT_TOL`]): a stricter bar for data whose
/// near-dependences are weaker than their noise can carry.
pub fn fix_undetermined_below(
    robot: &Robot,
    start: &ParamTable,
    qs: &[Vec<f64>],
    x: &Mat<f64>,
    keep: &[String],
    pivot_tol: f64,
) -> Result<Determined> {
    let mut names = robot.parameter_names();
    let n_kin = robot.n_unknowns();
    names.truncate(n_kin);
    let frozen = frozen_joints_of(robot, qs);
    let group = |k: usize| -> usize {
        if k >= n_kin || keep.contains(&names[k]) {
            0
        } else if frozen_frame_joint(robot, k, &frozen).is_some()
            || robot.unknowns[k].symbol == crate::model::Symbol::C
        {
            // A compliance is pivoted last: where sag and geometry cannot
            // be told apart, the compliance is the one held (at 0).
            2
        } else {
            1
        }
    };
    let kept = pivoted_selection(x, &(0..x.ncols()).map(group).collect::<Vec<_>>(), pivot_tol);
    let fixed_idx: Vec<usize> = (0..n_kin).filter(|k| !kept.contains(k)).collect();
    if fixed_idx.is_empty() {
        return Ok(Determined {
            robot: robot.clone(),
            fixed: Vec::new(),
        });
    }
    let jnames = joint_names(robot);
    let fixed = fixed_idx
        .iter()
        .map(|&k| FixedParameter {
            name: names[k].clone(),
            value: start.get(robot.unknowns[k]),
            reason: match frozen_frame_joint(robot, k, &frozen) {
                Some(j) => format!("joint {} never moves in these data", jnames[j]),
                None if robot.unknowns[k].symbol == crate::model::Symbol::C => {
                    COMPLIANCE_REASON.to_string()
                }
                None => GENERIC_REASON.to_string(),
            },
        })
        .collect();
    let mut r = robot.clone();
    r.unknowns = robot
        .unknowns
        .iter()
        .enumerate()
        .filter(|(k, _)| !fixed_idx.contains(k))
        .map(|(_, &u)| u)
        .collect();
    r.validate()?;
    Ok(Determined { robot: r, fixed })
}

/// Joints (by index) whose value spans no more than [`FROZEN_JOINT_SPAN`]
/// over the rows (of `meas` checked against `robot`: one value a joint).
#[must_use]
pub fn frozen_joints(robot: &Robot, meas: &Measurements) -> Vec<bool> {
    frozen_joints_of(robot, meas.qs())
}

/// As [`frozen_joints`], of joint vectors `qs`.
#[must_use]
pub fn frozen_joints_of(robot: &Robot, qs: &[Vec<f64>]) -> Vec<bool> {
    (0..robot.dof())
        .map(|j| {
            let (lo, hi) = qs
                .iter()
                .filter_map(|q| q.get(j).copied())
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                    (a.min(v), b.max(v))
                });
            qs.len() > 1 && hi - lo <= FROZEN_JOINT_SPAN
        })
        .collect()
}

/// The frozen joint whose axis the frame of unknown `k` moves or places, if
/// any: the frame driven by a joint `j` that never moves, or a frame whose
/// next driven frame is `j`'s (it places axis `j`: with `j` frozen, where
/// that axis lies is not seen, only the fixed transform through it).
fn frozen_frame_joint(robot: &Robot, k: usize, frozen: &[bool]) -> Option<usize> {
    let u = robot.unknowns.get(k)?;
    let is_frozen = |j: usize| frozen.get(j).copied().unwrap_or(false);
    if let Some(j) = robot.frames[u.frame].joint
        && is_frozen(j)
    {
        return Some(j);
    }
    let next = robot.frames[u.frame + 1..].iter().find_map(|f| f.joint)?;
    is_frozen(next).then_some(next)
}

/// The identification Jacobian of `meas` at `start` (all parameters).
fn jacobian_at(robot: &Robot, start: &ParamTable, meas: &Measurements) -> Result<Mat<f64>> {
    let mut prob = Calibration::new(robot, start, meas)?;
    let theta = robot.unknown_values(start);
    let mut r = vec![0.0; prob.n_residuals()];
    let mut x = Mat::<f64>::zeros(prob.n_residuals(), prob.n_params());
    prob.eval(&theta, &mut r, Some(&mut x));
    Ok(x)
}

/// The columns of `x` the rule leaves undetermined (see the module
/// documentation), ascending: `group[c]` is column `c`'s group (0 always
/// kept, then 1, 2, … pivoted in that order), `pivot_tol` the pivot bar
/// ([`PIVOT_TOL`] for the shared rule).
#[must_use]
pub fn undetermined_columns(x: &Mat<f64>, group: &[usize], pivot_tol: f64) -> Vec<usize> {
    let kept = pivoted_selection(x, group, pivot_tol);
    (0..x.ncols()).filter(|c| !kept.contains(c)).collect()
}

/// The columns kept by the grouped column-pivoted QR (see the module
/// documentation), in pivot order.
fn pivoted_selection(x: &Mat<f64>, group: &[usize], pivot_tol: f64) -> Vec<usize> {
    let (m, p) = x.shape();
    let unit: Vec<Option<Vec<f64>>> = (0..p)
        .map(|c| {
            let v: Vec<f64> = (0..m).map(|i| x[(i, c)]).collect();
            let n = v.iter().map(|a| a * a).sum::<f64>().sqrt();
            (n.is_finite() && n > 0.0).then(|| v.iter().map(|a| a / n).collect())
        })
        .collect();
    let mut basis: Vec<Vec<f64>> = Vec::new();
    let mut kept: Vec<usize> = Vec::new();
    for g in 0..3 {
        let mut rest: Vec<(usize, Vec<f64>)> = (0..p)
            .filter(|&c| group[c] == g)
            .filter_map(|c| unit[c].clone().map(|v| (c, v)))
            .collect();
        // A group's columns orthogonalised against the basis so far, then
        // (modified Gram–Schmidt) against each vector the group adds: each
        // projection twice ("twice is enough"), O(p² m) in all.
        for (_, v) in &mut rest {
            basis.iter().for_each(|b| project_out_twice(v, b));
        }
        while !rest.is_empty() {
            let norms: Vec<f64> = rest
                .iter()
                .map(|(_, v)| v.iter().map(|a| a * a).sum::<f64>().sqrt())
                .collect();
            let (best, &nb) = norms
                .iter()
                .enumerate()
                .max_by(|a, b| a.1.total_cmp(b.1))
                .expect("rest is not empty");
            if g > 0 && nb <= pivot_tol {
                break;
            }
            let (c, mut v) = rest.swap_remove(best);
            if nb > 0.0 {
                v.iter_mut().for_each(|a| *a /= nb);
                rest.iter_mut().for_each(|(_, r)| project_out_twice(r, &v));
                basis.push(v);
            }
            kept.push(c);
        }
    }
    // The rank rule itself on the kept columns: drop the last pivots that
    // are not forced until it passes — unless the forced columns alone fail
    // it (what the caller forces free is the caller's: the fit says).
    let gram = x.transpose() * x;
    let forced: Vec<usize> = kept.iter().copied().filter(|&c| group[c] == 0).collect();
    if !forced.is_empty() && !passes_rank_rule(&gram, &forced) {
        return kept;
    }
    while kept.len() > 1 && !passes_rank_rule(&gram, &kept) {
        match kept.iter().rposition(|&c| group[c] > 0) {
            Some(i) => {
                kept.remove(i);
            }
            None => break,
        }
    }
    kept
}

/// `v` less its component along the unit vector `b`, removed twice (the
/// second pass takes what rounding left of the first).
fn project_out_twice(v: &mut [f64], b: &[f64]) {
    for _ in 0..2 {
        let d: f64 = b.iter().zip(v.iter()).map(|(a, c)| a * c).sum();
        v.iter_mut().zip(b).for_each(|(y, a)| *y -= d * a);
    }
}

/// Whether the columns `cols` of a matrix `X` have full rank by the shared
/// rule, from its Gram matrix `gram` = `XᵀX` (formed once for every subset
/// the caller tries).
fn passes_rank_rule(gram: &Mat<f64>, cols: &[usize]) -> bool {
    let g = Mat::<f64>::from_fn(cols.len(), cols.len(), |a, b| gram[(cols[a], cols[b])]);
    equilibrated_rank(g.as_ref(), MAX_CONDITION) == cols.len()
}

#[cfg(test)]
mod tests {

    /// Columns 0, 1 (group 0) and 2, 3 (group 1), column 3 a multiple of
    /// column 1 plus column 0: it is the one left undetermined (a later
    /// group yields), column 2 (independent) is kept; with column 2 equal
    /// to column 0 as well, both group-1 columns are reported.
    #[test]
    fn undetermined_columns_names_the_later_groups_dependent_column() {
        let x = Mat::<f64>::from_fn(6, 4, |i, c| {
            let (a, b) = (i as f64, ((i * i) % 5) as f64);
            match c {
                0 => a,
                1 => b,
                2 => (i as f64).sin(),
                _ => 3.0 * b - 0.5 * a,
            }
        });
        assert_eq!(undetermined_columns(&x, &[0, 0, 1, 1], PIVOT_TOL), [3]);
        let y = Mat::<f64>::from_fn(6, 4, |i, c| if c == 2 { x[(i, 0)] } else { x[(i, c)] });
        assert_eq!(undetermined_columns(&y, &[0, 0, 1, 1], PIVOT_TOL), [2, 3]);
    }
    use super::*;
    use crate::identify::simulate;
    use crate::identify::trial_rng;
    use crate::pool::Pool;

    #[test]
    fn a_frozen_joint_gets_its_parameters_fixed_with_its_name() {
        let robot = Robot::puma560();
        let pool = Pool::full(&robot, 5).unwrap();
        // 40 poses spread over the lattice, joint 4 held at one value.
        let qs: Vec<Vec<f64>> = (0..40)
            .map(|k| {
                let mut q = pool.q(k * 389);
                q[3] = 0.3;
                q
            })
            .collect();
        let meas = simulate(&robot, &robot.real, &qs, 0.0, &mut trial_rng(1, 0)).unwrap();
        let d = fix_undetermined(&robot, &robot.nominal, &meas, &[]).unwrap();
        assert!(!d.fixed.is_empty());
        let j4 = &joint_names(&robot)[3];
        assert!(
            d.fixed.iter().any(|f| f.reason.contains(j4.as_str())),
            "{:?}",
            d.fixed
        );
        // What is left is determined by the data: the fit converges.
        let id = crate::identify::identify(&d.robot, &robot.nominal, &meas, &Default::default())
            .unwrap();
        assert!(
            id.converged(),
            "{:?} {:?} fixed {:?}",
            id.status,
            id.unidentifiable,
            d.fixed
        );
        // With every joint moving nothing is fixed.
        let qs: Vec<Vec<f64>> = (0..40).map(|k| pool.q(k * 389)).collect();
        let meas = simulate(&robot, &robot.real, &qs, 0.0, &mut trial_rng(1, 0)).unwrap();
        let d = fix_undetermined(&robot, &robot.nominal, &meas, &[]).unwrap();
        assert!(d.fixed.is_empty(), "{:?}", d.fixed);
    }
}

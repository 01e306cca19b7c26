//! Joints that turn all the way round, and joint-limit margins.
//!
//! A revolute joint whose range spans a full turn (2π) or more reaches every
//! angle; its values `lo` and `lo + 2π` are one pose. The lattice puts such a
//! joint's levels `2π/levels` apart from its lower limit, and the sampled
//! sources draw it on `[lo, lo + 2π)`, so that no pool repeats a pose. A
//! margin shrinks every revolute joint's range before either is made.

use crate::error::{Error, Result};
use crate::model::{JointKind, Robot};
use std::f64::consts::TAU;

/// Slack on "spans a full turn", radians: limits written as ±3.14159265
/// (eight digits of π) still count as one turn.
pub const TURN_TOL: f64 = 1e-7;

/// Two joint values closer than this (radians or metres, after reducing
/// revolute ones onto one turn) are the same value: far below any motion a
/// robot resolves, far above the rounding of the lattice's arithmetic.
pub const SAME_TOL: f64 = 1e-9;

/// Whether each joint is revolute, in joint order.
#[must_use]
pub fn revolute_joints(robot: &Robot) -> Vec<bool> {
    let mut r = vec![true; robot.dof()];
    for f in &robot.frames {
        if let Some(j) = f.joint
            && j < r.len()
        {
            r[j] = f.joint_kind == JointKind::Revolute;
        }
    }
    r
}

/// Whether a joint with these limits turns all the way round.
#[must_use]
pub fn is_full_turn(revolute: bool, [lo, hi]: [f64; 2]) -> bool {
    revolute && hi - lo >= TAU - TURN_TOL
}

/// The interval a sampled source draws a joint from, the top excluded:
/// `[lo, hi]` for a joint that does not turn all the way round, one turn
/// `[lo, min(hi, lo + 2π)]` for one that does.
#[must_use]
pub fn sampling_range(revolute: bool, lim: [f64; 2]) -> [f64; 2] {
    if is_full_turn(revolute, lim) {
        [lim[0], lim[1].min(lim[0] + TAU)]
    } else {
        lim
    }
}

/// A joint value as an angle on one turn, `[0, 2π)` (revolute joints), or
/// itself (prismatic joints): two values with the same canonical value,
/// within [`SAME_TOL`], put the joint in the same place.
#[must_use]
pub fn canonical(revolute: bool, v: f64) -> f64 {
    if revolute { v.rem_euclid(TAU) } else { v }
}

/// How many distinct places `values` put a joint in (see [`canonical`]).
#[must_use]
pub fn distinct_values(revolute: bool, values: &[f64]) -> usize {
    let mut c: Vec<f64> = values.iter().map(|&v| canonical(revolute, v)).collect();
    c.sort_by(f64::total_cmp);
    c.dedup_by(|a, b| (*a - *b).abs() <= SAME_TOL);
    // 0 and 2π − ε are one angle.
    if revolute && c.len() > 1 && c[0] + TAU - c[c.len() - 1] <= SAME_TOL {
        c.pop();
    }
    c.len()
}

/// A configuration as a hashable key: each value [`canonical`], in steps of
/// [`SAME_TOL`] (an angle's last step is its first: 2π − ε is 0).
fn key(revolute: &[bool], q: &[f64]) -> Vec<i64> {
    let turn = (TAU / SAME_TOL).round() as i64;
    q.iter()
        .zip(revolute)
        .map(|(&v, &r)| {
            let k = (canonical(r, v) / SAME_TOL).round() as i64;
            if r { k.rem_euclid(turn) } else { k }
        })
        .collect()
}

/// The first two of `configs` (`dof` values each, row-major) that put the
/// robot in the same pose (every joint the same, [`canonical`], to
/// [`SAME_TOL`] steps), as row positions `(earlier, later)`.
#[must_use]
pub fn first_repeat(revolute: &[bool], configs: &[f64]) -> Option<(usize, usize)> {
    let dof = revolute.len();
    if dof == 0 {
        return None;
    }
    let mut seen = std::collections::HashMap::with_capacity(configs.len() / dof);
    for (k, q) in configs.chunks_exact(dof).enumerate() {
        if let Some(&first) = seen.get(&key(revolute, q)) {
            return Some((first, k));
        }
        seen.insert(key(revolute, q), k);
    }
    None
}

/// The joint limits with a margin of `margin` radians taken off both ends of
/// every revolute joint's range (prismatic joints keep theirs). A margin of
/// half a joint's range or more is an error naming the joint (by number and
/// `names`), its range and the margin.
pub fn shrunk_limits(robot: &Robot, names: &[String], margin: f64) -> Result<Vec<[f64; 2]>> {
    if !(margin.is_finite() && margin >= 0.0) {
        return Err(Error::Invalid(format!(
            "a joint-limit margin must be a finite angle >= 0, got {margin} rad"
        )));
    }
    let revolute = revolute_joints(robot);
    robot
        .limits
        .iter()
        .zip(&revolute)
        .enumerate()
        .map(|(j, (&[lo, hi], &rev))| {
            if !rev || margin == 0.0 {
                return Ok([lo, hi]);
            }
            if 2.0 * margin >= hi - lo {
                return Err(Error::Invalid(format!(
                    "a joint-limit margin of {:.4}° is half or more of the range of joint {} '{}' ([{:.4}°, {:.4}°], {:.4}° wide): no value is that far inside both limits",
                    margin.to_degrees(),
                    j + 1,
                    names.get(j).map_or("", String::as_str),
                    lo.to_degrees(),
                    hi.to_degrees(),
                    (hi - lo).to_degrees()
                )));
            }
            Ok([lo + margin, hi - margin])
        })
        .collect()
}

/// Whether each joint turns all the way round ([`is_full_turn`]), in joint
/// order.
#[must_use]
pub fn turning_joints(robot: &Robot) -> Vec<bool> {
    revolute_joints(robot)
        .into_iter()
        .zip(&robot.limits)
        .map(|(r, &lim)| is_full_turn(r, lim))
        .collect()
}

/// Whether `a` and `b` put the robot in the same place to `tol` (radians or
/// metres) per joint: a joint that turns all the way round (`turning`)
/// compared on the circle, so that values a whole turn apart agree.
#[must_use]
pub fn same_place(turning: &[bool], a: &[f64], b: &[f64], tol: f64) -> bool {
    a.len() == b.len()
        && a.iter().zip(b).enumerate().all(|(j, (x, y))| {
            let d = (x - y).abs();
            if turning.get(j).copied().unwrap_or(false) {
                let r = d.rem_euclid(TAU);
                r.min(TAU - r) <= tol
            } else {
                d <= tol
            }
        })
}

/// Per joint, the limits (less `margin`, as [`shrunk_limits`]) within
/// which its value may change by whole turns without moving any link, for
/// a joint that turns all the way round ([`is_full_turn`] on its own
/// limits), else `None`.
pub fn whole_turn_limits(
    robot: &Robot,
    names: &[String],
    margin: f64,
) -> Result<Vec<Option<[f64; 2]>>> {
    let shrunk = shrunk_limits(robot, names, margin)?;
    Ok(turning_joints(robot)
        .into_iter()
        .zip(shrunk)
        .map(|(t, s)| t.then_some(s))
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn values_a_whole_turn_apart_are_one_place_only_on_a_turning_joint() {
        let tol = 1e-9;
        let (a, b) = ([-5.9, 0.3], [-5.9 + TAU, 0.3]);
        assert!(same_place(&[true, false], &a, &b, tol));
        assert!(!same_place(&[false, false], &a, &b, tol));
        // The second joint a turn away, but it does not turn round.
        assert!(!same_place(&[true, false], &a, &[-5.9, 0.3 + TAU], tol));
        // Near the seam of the circle: 2π − 1e-12 is 0 to the tolerance.
        assert!(same_place(&[true], &[0.0], &[TAU - 1e-12], tol));
        assert!(!same_place(&[true], &[0.0], &[1e-6], tol));
        assert!(!same_place(&[true], &[0.0], &[0.0, 0.0], tol));
    }

    #[test]
    fn full_turns_are_told_from_shorter_ranges() {
        assert!(is_full_turn(true, [-PI, PI]));
        assert!(is_full_turn(true, [-TAU, TAU]));
        // Eight digits of π: still a turn (TURN_TOL).
        assert!(is_full_turn(true, [-3.141_592_65, 3.141_592_65]));
        assert!(!is_full_turn(true, [-3.0, 3.0]));
        assert!(!is_full_turn(false, [-10.0, 10.0]));
        assert_eq!(sampling_range(true, [-TAU, TAU]), [-TAU, 0.0]);
        assert_eq!(sampling_range(true, [-1.0, 1.0]), [-1.0, 1.0]);
    }

    #[test]
    fn distinct_values_fold_angles_onto_one_turn() {
        // The old ±2π lattice of 5 levels: −2π, −π, 0, π, 2π are 2 angles.
        let old = [-TAU, -PI, 0.0, PI, TAU];
        assert_eq!(distinct_values(true, &old), 2);
        // As lengths they are 5 places.
        assert_eq!(distinct_values(false, &old), 5);
        // 0 and 2π − 1e-12 are one angle.
        assert_eq!(distinct_values(true, &[0.0, TAU - 1e-12]), 1);
        assert_eq!(distinct_values(true, &[0.0, 1.0, 2.0]), 3);
    }

    #[test]
    fn repeats_are_found_on_the_circle() {
        let rev = [true, false];
        // −π and π are one angle; 0.5 m is 0.5 m.
        let c = [-PI, 0.5, 1.0, 0.5, PI, 0.5];
        assert_eq!(first_repeat(&rev, &c), Some((0, 2)));
        // As a prismatic joint they differ.
        assert_eq!(first_repeat(&[false, false], &c), None);
        assert_eq!(first_repeat(&rev, &[0.0, 0.0, TAU, 0.0]), Some((0, 1)));
        assert_eq!(first_repeat(&rev, &[0.0, 0.0, 0.0, 1e-6]), None);
    }

    #[test]
    fn margins_shrink_revolute_ranges_and_name_the_joint() {
        let r = Robot::builtin("ur5").unwrap();
        let names: Vec<String> = (1..=6).map(|j| format!("j{j}")).collect();
        let m = 2f64.to_radians();
        let s = shrunk_limits(&r, &names, m).unwrap();
        for (a, b) in s.iter().zip(&r.limits) {
            assert!((a[0] - (b[0] + m)).abs() < 1e-15 && (a[1] - (b[1] - m)).abs() < 1e-15);
        }
        // Joint 2 of the UR5 spans 180°: a 90° margin leaves nothing.
        let e = shrunk_limits(&r, &names, 90f64.to_radians())
            .unwrap_err()
            .to_string();
        assert!(e.contains("joint 2 'j2'"), "{e}");
        assert!(shrunk_limits(&r, &names, -1.0).is_err());
    }
}

//! Whole turns of the joints that turn all the way round. Such a joint's
//! values `v` and `v ± 2π` put every link in the same place, so a pose may
//! be reached by any whole-turn equivalent of its joint values that lies
//! within the joint's limits: the measurement, the kinematics and the
//! identification Jacobian are the same (every revolute joint enters them
//! through its angle's sine and cosine), only the way the arm moves there
//! changes. A visiting order plans with the shortest way round
//! (`MoveCost::turning` in [`crate::select::tour`]) and then chooses, pose by pose, the equivalents
//! that make its moves take the least time ([`choose_turns`]).

use std::f64::consts::TAU;

/// Most combinations of equivalents of one pose the exact choice weighs
/// against those of the pose before (`S²` move times a move): beyond it,
/// each joint takes the equivalent nearest the previous pose's value.
pub const MAX_COMBINATIONS: usize = 256;

/// Whole turns (−2 … 2) that keep a joint's value `v` within `limits`
/// (`None`: the joint does not turn all the way round, only 0); 0 always
/// comes first.
#[must_use]
pub fn turns_within(v: f64, limits: Option<[f64; 2]>) -> Vec<i32> {
    let mut out = vec![0];
    if let Some([lo, hi]) = limits {
        for t in [-2, -1, 1, 2] {
            let w = v + f64::from(t) * TAU;
            if w >= lo && w <= hi {
                out.push(t);
            }
        }
    }
    out
}

/// `q` with `turns[j]` whole turns added to joint `j`.
#[must_use]
pub fn turned(q: &[f64], turns: &[i32]) -> Vec<f64> {
    q.iter()
        .zip(turns)
        .map(|(v, &t)| v + f64::from(t) * TAU)
        .collect()
}

/// Every combination of whole turns of `q`'s joints within `limits`, the
/// unturned one first; `None` beyond [`MAX_COMBINATIONS`].
fn combinations(q: &[f64], limits: &[Option<[f64; 2]>]) -> Option<Vec<Vec<i32>>> {
    let per_joint: Vec<Vec<i32>> = q
        .iter()
        .zip(limits)
        .map(|(&v, &l)| turns_within(v, l))
        .collect();
    let count = per_joint
        .iter()
        .try_fold(1usize, |n, o| n.checked_mul(o.len()))?;
    if count > MAX_COMBINATIONS {
        return None;
    }
    Some(product(&per_joint))
}

/// Every combination of one choice per joint, in order (the combination of
/// the first choices first).
#[must_use]
pub fn product(per_joint: &[Vec<i32>]) -> Vec<Vec<i32>> {
    let mut out: Vec<Vec<i32>> = vec![Vec::with_capacity(per_joint.len())];
    for o in per_joint {
        out = out
            .into_iter()
            .flat_map(|pre| {
                o.iter().map(move |&t| {
                    let mut x = pre.clone();
                    x.push(t);
                    x
                })
            })
            .collect();
    }
    out
}

/// Per joint, the whole turns of `q` within `limits` that bring it nearest
/// `prev` (ties: the fewest turns).
fn nearest_turns(prev: &[f64], q: &[f64], limits: &[Option<[f64; 2]>]) -> Vec<i32> {
    q.iter()
        .zip(prev)
        .zip(limits)
        .map(|((&v, &p), &l)| {
            turns_within(v, l)
                .into_iter()
                .min_by(|&a, &b| {
                    let d = |t: i32| (v + f64::from(t) * TAU - p).abs();
                    d(a).total_cmp(&d(b)).then(a.abs().cmp(&b.abs()))
                })
                .unwrap_or(0)
        })
        .collect()
}

/// The whole turns to add to each pose of `qs` (indexed as `qs`) so that
/// visiting them in `order` from `home` takes the least time, a move from
/// `a` to `b` taking `time(a, b)` (which must not itself take the shortest
/// way round): an exact dynamic
/// programme over each pose's combinations of equivalents (the time to a
/// pose's combination is the least, over the previous pose's
/// combinations, of the time to that one plus the move), ties kept on the
/// unturned values; a pose with more than [`MAX_COMBINATIONS`] takes, per
/// joint, the equivalent nearest the pose chosen before it.
#[must_use]
pub fn choose_turns(
    time: impl Fn(&[f64], &[f64]) -> f64,
    home: Option<&[f64]>,
    qs: &[Vec<f64>],
    order: &[usize],
    limits: &[Option<[f64; 2]>],
) -> Vec<Vec<i32>> {
    let dof = limits.len();
    let mut chosen = vec![vec![0; dof]; qs.len()];
    let mut stages: Vec<Stage> = Vec::with_capacity(order.len());
    for &k in order {
        let prev = stages.last();
        let turns = combinations(&qs[k], limits).unwrap_or_else(|| {
            // One candidate: nearest the previous pose's best.
            let reference = match prev {
                Some(s) => s.configs[argmin(&s.times)].clone(),
                None => home.map_or_else(|| qs[k].clone(), <[f64]>::to_vec),
            };
            vec![nearest_turns(&reference, &qs[k], limits)]
        });
        let configs: Vec<Vec<f64>> = turns.iter().map(|t| turned(&qs[k], t)).collect();
        let (times, from) = configs
            .iter()
            .map(|q| match prev {
                Some(s) => s
                    .configs
                    .iter()
                    .zip(&s.times)
                    .enumerate()
                    .map(|(i, (p, &acc))| (acc + time(p, q), i))
                    .fold(
                        (f64::INFINITY, 0),
                        |best, x| if x.0 < best.0 { x } else { best },
                    ),
                None => (home.map_or(0.0, |h| time(h, q)), 0),
            })
            .unzip();
        stages.push(Stage {
            turns,
            configs,
            times,
            from,
        });
    }
    // Back from the last pose's best.
    let Some(last) = stages.last() else {
        return chosen;
    };
    let mut i = argmin(&last.times);
    for (s, &k) in stages.iter().zip(order).rev() {
        chosen[k].clone_from(&s.turns[i]);
        i = s.from[i];
    }
    chosen
}

/// One pose of [`choose_turns`]' programme: its candidate turns, their
/// joint values, the least time to reach each, and the candidate of the
/// pose before it came from.
struct Stage {
    turns: Vec<Vec<i32>>,
    configs: Vec<Vec<f64>>,
    times: Vec<f64>,
    from: Vec<usize>,
}

/// The position of the least of `t` (the first among equals).
fn argmin(t: &[f64]) -> usize {
    t.iter()
        .enumerate()
        .fold(
            (0, f64::INFINITY),
            |best, (i, &x)| {
                if x < best.1 { (i, x) } else { best }
            },
        )
        .0
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A synchronised move's time at `speeds`: the slowest joint's.
    fn move_time(speeds: &[f64]) -> impl Fn(&[f64], &[f64]) -> f64 + '_ {
        move |a, b| {
            a.iter()
                .zip(b)
                .zip(speeds)
                .map(|((x, y), v)| (y - x).abs() / v)
                .fold(0.0, f64::max)
        }
    }

    #[test]
    fn turns_stay_within_the_limits_and_zero_comes_first() {
        let lim = Some([-TAU, TAU]);
        assert_eq!(turns_within(-1.0, lim), vec![0, 1]);
        assert_eq!(turns_within(1.0, lim), vec![0, -1]);
        assert_eq!(turns_within(1.0, None), vec![0]);
        // ±3.1 rad (less than a turn): none.
        assert_eq!(turns_within(1.0, Some([-3.1, 3.1])), vec![0]);
        // 4.5 turns of range: two either way from the middle.
        assert_eq!(
            turns_within(0.0, Some([-2.25 * TAU, 2.25 * TAU])),
            vec![0, -2, -1, 1, 2]
        );
    }

    #[test]
    fn the_choice_is_the_least_time_over_every_combination() {
        // Three poses of two turning joints (speeds 1 and 2 rad/s), from a
        // home: the dynamic programme's time must equal the least time of
        // every assignment of turns, found by enumeration (4 combinations
        // per pose, 64 assignments), and beat the unturned values.
        let cost = move_time(&[1.0, 2.0]);
        let lim = [Some([-TAU, TAU]), Some([-TAU, TAU])];
        let home = [0.0, 0.0];
        let qs = vec![vec![-5.9, 2.0], vec![-0.4, -5.5], vec![5.0, -3.0]];
        let order = [0, 1, 2];
        let path_time = |turns: &[Vec<i32>]| {
            let mut prev = home.to_vec();
            let mut t = 0.0;
            for &k in &order {
                let q = turned(&qs[k], &turns[k]);
                t += cost(&prev, &q);
                prev = q;
            }
            t
        };
        let per_pose: Vec<Vec<Vec<i32>>> =
            qs.iter().map(|q| combinations(q, &lim).unwrap()).collect();
        let mut best = f64::INFINITY;
        for a in &per_pose[0] {
            for b in &per_pose[1] {
                for c in &per_pose[2] {
                    best = best.min(path_time(&[a.clone(), b.clone(), c.clone()]));
                }
            }
        }
        let chosen = choose_turns(&cost, Some(&home), &qs, &order, &lim);
        let got = path_time(&chosen);
        // Sums of three exact maxima of differences: equal to rounding.
        assert!((got - best).abs() < 1e-12, "{got} vs {best}");
        assert!(got < path_time(&[vec![0, 0], vec![0, 0], vec![0, 0]]) - 1.0);
        // Every chosen value within the limits.
        for (q, t) in qs.iter().zip(&chosen) {
            assert!(turned(q, t).iter().all(|v| v.abs() <= TAU));
        }
    }

    #[test]
    fn without_turning_joints_nothing_turns() {
        let cost = move_time(&[1.0]);
        let qs = vec![vec![-3.0], vec![3.0]];
        let chosen = choose_turns(&cost, None, &qs, &[0, 1], &[Some([-3.1, 3.1])]);
        assert_eq!(chosen, vec![vec![0], vec![0]]);
    }

    #[test]
    fn beyond_the_combination_cap_each_joint_takes_its_nearest_equivalent() {
        // 9 turning joints: 2⁹ = 512 combinations, over the cap. From home
        // at 0, −5.9 is nearest as 0.38 (+1 turn), −0.4 as itself.
        let cost = move_time(&[1.0; 9]);
        let lim = [Some([-TAU, TAU]); 9];
        let mut q = vec![-0.4; 9];
        q[0] = -5.9;
        let chosen = choose_turns(&cost, Some(&[0.0; 9]), &[q], &[0], &lim);
        let mut expected = vec![0; 9];
        expected[0] = 1;
        assert_eq!(chosen, vec![expected]);
    }
}

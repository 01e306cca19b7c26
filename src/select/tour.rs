//! A visiting order for a design: the order to measure its poses in so that
//! the arm spends the least time moving between them.
//!
//! A move from `a` to `b` takes `max_j |b_j − a_j| / v_j` (every joint at
//! its speed limit `v_j`, the slowest joint deciding, as a synchronised
//! joint-space move does). The path starts at a home configuration, when one
//! is given, and visits every pose once (no return); without a home it may
//! start anywhere. The order is found by nearest neighbour (from every first
//! pose when there is no home, the best kept), then improved by 2-opt
//! (reversing a stretch) and Or-opt (moving a stretch of 1 to 3 poses,
//! either way round, elsewhere) until neither gains.

use crate::error::{Error, Result};
use crate::select::turns::{choose_turns, turned};
use serde::Serialize;
use std::f64::consts::TAU;

/// Speed assumed for a joint whose limit the robot does not state, rad/s
/// (or m/s).
pub const FALLBACK_SPEED: f64 = 1.0;

/// Gains below this, seconds, are not taken (rounding would otherwise let
/// two equal orders swap forever).
const GAIN_TOL: f64 = 1e-12;

/// Longest stretch Or-opt moves.
const OR_OPT_MAX: usize = 3;

/// The cost of moving between configurations.
#[derive(Clone, Debug)]
pub struct MoveCost {
    /// `1 / v_j` per joint (seconds per radian or metre).
    inv_speed: Vec<f64>,
    /// Joints whose moves are taken the shortest way round (empty: none).
    wrap: Vec<bool>,
}

impl MoveCost {
    /// Moves at the joint speed limits `speeds` (radians or metres per
    /// second, each finite and > 0).
    pub fn new(speeds: &[f64]) -> Result<Self> {
        if let Some(j) = speeds.iter().position(|v| !(v.is_finite() && *v > 0.0)) {
            return Err(Error::Invalid(format!(
                "joint {}: speed limit {} must be finite and > 0",
                j + 1,
                speeds[j]
            )));
        }
        Ok(Self {
            inv_speed: speeds.iter().map(|v| 1.0 / v).collect(),
            wrap: Vec::new(),
        })
    }

    /// The same speeds, the joints marked in `wrap` (those that turn all
    /// the way round) moving the shortest way round, at most half a turn:
    /// the time of the best whole-turn equivalents of the two poses, for
    /// planning an order before they are chosen
    /// ([`crate::select::turns::choose_turns`]).
    #[must_use]
    pub fn turning(mut self, wrap: Vec<bool>) -> Self {
        self.wrap = wrap;
        self
    }

    /// Seconds a move from `a` to `b` takes.
    #[must_use]
    pub fn time(&self, a: &[f64], b: &[f64]) -> f64 {
        a.iter()
            .zip(b)
            .zip(&self.inv_speed)
            .enumerate()
            .map(|(j, ((x, y), w))| {
                let d = (y - x).abs();
                if self.wrap.get(j).copied().unwrap_or(false) {
                    let r = d.rem_euclid(TAU);
                    r.min(TAU - r) * w
                } else {
                    d * w
                }
            })
            .fold(0.0, f64::max)
    }
}

/// The largest joint travel of a move, radians or metres.
#[must_use]
pub fn largest_travel(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (y - x).abs())
        .fold(0.0, f64::max)
}

/// Totals of a path through poses in a given order.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct PathTotals {
    /// Summed move time, seconds.
    pub time_s: f64,
    /// Summed largest joint travel of the moves, radians (metres for a
    /// prismatic joint that decides a move).
    pub travel: f64,
}

/// The totals of visiting `qs` in `order`, from `home` when given.
#[must_use]
pub fn totals(
    cost: &MoveCost,
    home: Option<&[f64]>,
    qs: &[Vec<f64>],
    order: &[usize],
) -> PathTotals {
    let mut t = PathTotals {
        time_s: 0.0,
        travel: 0.0,
    };
    let mut prev: Option<&[f64]> = home;
    for &k in order {
        if let Some(p) = prev {
            t.time_s += cost.time(p, &qs[k]);
            t.travel += largest_travel(p, &qs[k]);
        }
        prev = Some(&qs[k]);
    }
    t
}

/// Move times between every two nodes: node 0 is the start (home, or a
/// free start costing nothing), node `k + 1` is pose `k`.
struct Times {
    n: usize,
    d: Vec<f64>,
}

impl Times {
    fn new(cost: &MoveCost, home: Option<&[f64]>, qs: &[Vec<f64>]) -> Self {
        let n = qs.len() + 1;
        let mut d = vec![0.0; n * n];
        for a in 1..n {
            d[a] = home.map_or(0.0, |h| cost.time(h, &qs[a - 1]));
            d[a * n] = d[a];
            for b in 1..n {
                d[a * n + b] = cost.time(&qs[a - 1], &qs[b - 1]);
            }
        }
        Self { n, d }
    }

    fn at(&self, a: usize, b: usize) -> f64 {
        self.d[a * self.n + b]
    }

    /// Time of the open path `path` (node 0 first).
    fn path(&self, path: &[usize]) -> f64 {
        path.windows(2).map(|w| self.at(w[0], w[1])).sum()
    }
}

/// Nearest neighbour from node 0 through `first` (when given).
fn nearest_neighbour(t: &Times, first: Option<usize>) -> Vec<usize> {
    let mut path = vec![0];
    let mut left: Vec<usize> = (1..t.n).collect();
    if let Some(f) = first {
        left.retain(|&x| x != f);
        path.push(f);
    }
    while !left.is_empty() {
        let cur = *path.last().expect("the start");
        let (i, _) = left
            .iter()
            .enumerate()
            .min_by(|a, b| t.at(cur, *a.1).total_cmp(&t.at(cur, *b.1)))
            .expect("a pose left");
        path.push(left.swap_remove(i));
    }
    path
}

/// One pass of 2-opt on the open path (node 0 fixed first): reverses
/// `path[i..=j]` whenever that shortens it; whether anything changed.
fn two_opt(t: &Times, path: &mut [usize]) -> bool {
    let n = path.len();
    let mut improved = false;
    for i in 1..n.saturating_sub(1) {
        for j in i + 1..n {
            let (a, b, c) = (path[i - 1], path[i], path[j]);
            let after = (j + 1 < n).then(|| path[j + 1]);
            let before = t.at(a, b) + after.map_or(0.0, |d| t.at(c, d));
            let reversed = t.at(a, c) + after.map_or(0.0, |d| t.at(b, d));
            if reversed < before - GAIN_TOL {
                path[i..=j].reverse();
                improved = true;
            }
        }
    }
    improved
}

/// One pass of Or-opt: moves a stretch of 1..=3 poses (either way round)
/// to the place where it costs least, whenever that shortens the path;
/// whether anything changed.
fn or_opt(t: &Times, path: &mut Vec<usize>) -> bool {
    let mut improved = false;
    for len in 1..=OR_OPT_MAX {
        let mut i = 1;
        while i + len <= path.len() {
            let base = t.path(path);
            let seg: Vec<usize> = path[i..i + len].to_vec();
            let mut rest: Vec<usize> = path[..i].to_vec();
            rest.extend_from_slice(&path[i + len..]);
            let mut best: Option<(f64, Vec<usize>)> = None;
            for k in 1..=rest.len() {
                for rev in [false, true] {
                    let mut cand = rest[..k].to_vec();
                    if rev {
                        cand.extend(seg.iter().rev());
                    } else {
                        cand.extend_from_slice(&seg);
                    }
                    cand.extend_from_slice(&rest[k..]);
                    let c = t.path(&cand);
                    if c < base - GAIN_TOL && best.as_ref().is_none_or(|(b, _)| c < *b) {
                        best = Some((c, cand));
                    }
                }
            }
            if let Some((_, cand)) = best {
                *path = cand;
                improved = true;
            }
            i += 1;
        }
    }
    improved
}

/// The order to visit `qs` in (indices into `qs`), starting from `home`
/// when given: nearest neighbour, then 2-opt and Or-opt until neither
/// gains (see the module docs).
#[must_use]
pub fn plan(cost: &MoveCost, home: Option<&[f64]>, qs: &[Vec<f64>]) -> Vec<usize> {
    if qs.is_empty() {
        return Vec::new();
    }
    let t = Times::new(cost, home, qs);
    let starts: Vec<Option<usize>> = if home.is_some() {
        vec![None]
    } else {
        (1..t.n).map(Some).collect()
    };
    let mut path = starts
        .into_iter()
        .map(|f| nearest_neighbour(&t, f))
        .min_by(|a, b| t.path(a).total_cmp(&t.path(b)))
        .expect("at least one start");
    loop {
        let a = two_opt(&t, &mut path);
        let b = or_opt(&t, &mut path);
        if !(a || b) {
            break;
        }
    }
    path[1..].iter().map(|&k| k - 1).collect()
}

/// What ordering a design did: the path in selection order and in the
/// order chosen, with the speeds and start it was planned with.
#[derive(Clone, Debug, Serialize)]
pub struct TourReport {
    /// Whether the poses were reordered (false: selection order kept, the
    /// figures are for that order alone).
    pub reordered: bool,
    /// Joint speed limits the move times assume, rad/s or m/s.
    pub speeds: Vec<f64>,
    /// Joints whose speed the robot does not state (1 rad/s assumed).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub assumed_speeds: Vec<String>,
    /// The start of the path, when given.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub home: Option<Vec<f64>>,
    /// The path in selection order.
    pub selection_order: PathTotals,
    /// The path in the visiting order.
    pub visiting_order: PathTotals,
    /// Visiting time over selection order's (1 when not reordered).
    pub time_ratio: f64,
    /// Poses reached by whole-turn equivalents of their joint values (the
    /// same poses, [`crate::select::turns`]) to shorten the moves.
    pub turned_poses: usize,
}

/// Plans the visiting order of `qs` ([`plan`]) when `reorder`, and reports
/// it against selection order: the order (indices into `qs`) and the
/// report (`speeds` and `assumed_speeds` as the cost was made). A joint
/// with limits in `turns` turns all the way round: the order is planned
/// with its moves the shortest way round, and each pose of `qs` is then
/// changed to the whole-turn equivalents within those limits that make the
/// order's moves take the least time ([`choose_turns`]). Errors on a speed
/// that is not finite and positive.
pub fn visit(
    speeds: &[f64],
    assumed_speeds: Vec<String>,
    home: Option<&[f64]>,
    qs: &mut [Vec<f64>],
    reorder: bool,
    turns: &[Option<[f64; 2]>],
) -> Result<(Vec<usize>, TourReport)> {
    let cost = MoveCost::new(speeds)?;
    let identity: Vec<usize> = (0..qs.len()).collect();
    let before = totals(&cost, home, qs, &identity);
    let mut turned_poses = 0;
    let order = if reorder {
        let wrap: Vec<bool> = turns.iter().map(Option::is_some).collect();
        // Planned the shortest way round and as the values are; each with
        // its best turns, the faster kept (the limits can keep a joint
        // from going the shortest way, so either may win).
        let (order, chosen) = [
            plan(&cost.clone().turning(wrap), home, qs),
            plan(&cost, home, qs),
        ]
        .into_iter()
        .map(|order| {
            let chosen = choose_turns(|a, b| cost.time(a, b), home, qs, &order, turns);
            let turned_qs: Vec<Vec<f64>> =
                qs.iter().zip(&chosen).map(|(q, t)| turned(q, t)).collect();
            let time = totals(&cost, home, &turned_qs, &order).time_s;
            (time, order, chosen)
        })
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, o, c)| (o, c))
        .expect("two plans");
        for (q, t) in qs.iter_mut().zip(chosen) {
            if t.iter().any(|&x| x != 0) {
                *q = turned(q, &t);
                turned_poses += 1;
            }
        }
        order
    } else {
        identity
    };
    let after = totals(&cost, home, qs, &order);
    let time_ratio = if before.time_s > 0.0 {
        after.time_s / before.time_s
    } else {
        1.0
    };
    Ok((
        order,
        TourReport {
            reordered: reorder,
            speeds: speeds.to_vec(),
            assumed_speeds,
            home: home.map(<[f64]>::to_vec),
            selection_order: before,
            visiting_order: after,
            time_ratio,
            turned_poses,
        },
    ))
}

/// The time (s) at which each pose of `qs` is reached, visiting them in
/// order from `home` (or from the first pose, reached at 0), each move
/// taking [`MoveCost::time`] at `speeds`.
pub fn arrival_times(speeds: &[f64], home: Option<&[f64]>, qs: &[Vec<f64>]) -> Result<Vec<f64>> {
    let cost = MoveCost::new(speeds)?;
    let mut t = 0.0;
    let mut prev: Option<&[f64]> = home;
    Ok(qs
        .iter()
        .map(|q| {
            if let Some(p) = prev {
                t += cost.time(p, q);
            }
            prev = Some(q);
            t
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn random_poses(rng: &mut ChaCha8Rng, n: usize, dof: usize) -> Vec<Vec<f64>> {
        (0..n)
            .map(|_| (0..dof).map(|_| rng.random_range(-3.0..3.0)).collect())
            .collect()
    }

    /// The best open path by trying every order (node 0 first).
    fn brute_force(t: &Times) -> f64 {
        fn go(t: &Times, path: &mut Vec<usize>, left: &mut Vec<usize>, best: &mut f64) {
            if left.is_empty() {
                *best = best.min(t.path(path));
                return;
            }
            for k in 0..left.len() {
                let x = left.remove(k);
                path.push(x);
                go(t, path, left, best);
                path.pop();
                left.insert(k, x);
            }
        }
        let mut best = f64::INFINITY;
        go(t, &mut vec![0], &mut (1..t.n).collect(), &mut best);
        best
    }

    #[test]
    fn move_time_is_the_slowest_joints() {
        let c = MoveCost::new(&[1.0, 2.0]).unwrap();
        // Joint 1: 1 rad at 1 rad/s; joint 2: 3 rad at 2 rad/s.
        assert_eq!(c.time(&[0.0, 0.0], &[1.0, 3.0]), 1.5);
        assert!(MoveCost::new(&[1.0, 0.0]).is_err());
        assert!(MoveCost::new(&[f64::NAN]).is_err());
    }

    #[test]
    fn whole_turns_shorten_the_tour_and_keep_every_pose() {
        // Six joints, five turning within ±2π (the UR arms'), values drawn
        // on one turn [−2π, 0) as the pool draws them: visiting with whole
        // turns never takes longer than the same planner without them, and
        // every visited value is its pose's value plus whole turns, within
        // the limits.
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let speeds = [2.16, 2.16, 3.15, 3.2, 3.2, 3.2];
        let lim = Some([-TAU, TAU]);
        let turns = [lim, lim, None, lim, lim, lim];
        let (mut gained, trials) = (0, 20);
        for _ in 0..trials {
            let qs: Vec<Vec<f64>> = (0..20)
                .map(|_| (0..6).map(|_| rng.random_range(-TAU..0.0)).collect())
                .collect();
            let mut plain = qs.clone();
            let (o1, r1) = visit(&speeds, Vec::new(), None, &mut plain, true, &[None; 6]).unwrap();
            assert_eq!(plain, qs, "nothing turns without turning joints");
            let mut turned_qs = qs.clone();
            let (o2, r2) = visit(&speeds, Vec::new(), None, &mut turned_qs, true, &turns).unwrap();
            assert!(r2.visiting_order.time_s <= r1.visiting_order.time_s + 1e-12);
            assert_eq!(
                r1.selection_order, r2.selection_order,
                "the baseline is untouched"
            );
            gained += usize::from(r2.visiting_order.time_s < 0.95 * r1.visiting_order.time_s);
            for ((a, b), t) in qs
                .iter()
                .zip(&turned_qs)
                .flat_map(|(q, w)| q.iter().zip(w))
                .zip(turns.iter().cycle())
            {
                let k = (b - a) / TAU;
                // Whole turns to rounding (a turn added to a value of
                // order 2π: a few ulps).
                assert!((k - k.round()).abs() < 1e-12 && b.abs() <= TAU);
                assert!(t.is_some() || k == 0.0);
            }
            let count = qs.iter().zip(&turned_qs).filter(|(a, b)| a != b).count();
            assert_eq!(r2.turned_poses, count);
            for o in [&o1, &o2] {
                let mut sorted = o.clone();
                sorted.sort_unstable();
                assert_eq!(sorted, (0..20).collect::<Vec<_>>());
            }
        }
        // Values on one turn of a ±2π joint sit up to 2π apart, the way
        // round at most π: most tours gain more than 5 %.
        assert!(gained > trials / 2, "{gained} of {trials}");
    }

    #[test]
    fn improvements_never_lengthen_the_path() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let cost = MoveCost::new(&[2.0, 1.0, 3.0, 1.5]).unwrap();
        for _ in 0..50 {
            let qs = random_poses(&mut rng, 15, 4);
            let t = Times::new(&cost, None, &qs);
            let mut path: Vec<usize> = (0..t.n).collect();
            let mut prev = t.path(&path);
            for _ in 0..20 {
                let a = two_opt(&t, &mut path);
                // A pass that changes the path shortens it by more than the
                // tolerance; one that changes nothing leaves it as it was.
                let now = t.path(&path);
                assert!(now <= prev + 1e-12 && (a || now == prev), "{now} > {prev}");
                prev = now;
                or_opt(&t, &mut path);
                let now = t.path(&path);
                assert!(now <= prev + 1e-12, "{now} > {prev}");
                prev = now;
            }
            let mut sorted = path.clone();
            sorted.sort_unstable();
            assert_eq!(sorted, (0..t.n).collect::<Vec<_>>(), "a permutation");
            assert_eq!(path[0], 0, "the start stays first");
        }
    }

    #[test]
    fn small_instances_reach_or_come_close_to_the_optimum() {
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let cost = MoveCost::new(&[2.175, 2.175, 2.61]).unwrap();
        let (mut optimal, trials) = (0, 100);
        for trial in 0..trials {
            let qs = random_poses(&mut rng, 7, 3);
            let home: Vec<f64> = vec![0.0; 3];
            let home = (trial % 2 == 0).then_some(home.as_slice());
            let t = Times::new(&cost, home, &qs);
            let best = brute_force(&t);
            let order = plan(&cost, home, &qs);
            let got = totals(&cost, home, &qs, &order).time_s;
            // Never better than the optimum (up to rounding of the sums).
            assert!(got >= best - 1e-9, "{got} < optimum {best}");
            // Local search on 7 poses: within 10 % of the optimum always.
            assert!(got <= 1.10 * best, "{got} vs optimum {best}");
            if got <= best + 1e-9 {
                optimal += 1;
            }
        }
        // 2-opt + Or-opt find the exact optimum of most 7-pose instances.
        assert!(optimal >= 80, "optimal in {optimal} of {trials}");
    }

    #[test]
    fn poses_on_a_line_are_visited_in_order() {
        let cost = MoveCost::new(&[1.0]).unwrap();
        let qs: Vec<Vec<f64>> = [5.0, 1.0, 4.0, 2.0, 3.0].iter().map(|&x| vec![x]).collect();
        let order = plan(&cost, Some(&[0.0]), &qs);
        assert_eq!(order, vec![1, 3, 4, 2, 0]);
        assert_eq!(totals(&cost, Some(&[0.0]), &qs, &order).time_s, 5.0);
        // Without a home, from one end to the other: 4 s.
        let order = plan(&cost, None, &qs);
        assert_eq!(totals(&cost, None, &qs, &order).time_s, 4.0);
    }
}

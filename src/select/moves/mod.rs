//! The moves of a visiting order checked for collision: every straight
//! joint-space move (home → first → … → last) is checked against the
//! pool's collision models ([`CollisionModel::check_move`]); a move that
//! collides is replaced, when possible, by reversing a stretch of the tour
//! (a 2-opt move), moving one of its poses elsewhere (Or-opt), or turning
//! a joint of a stretch of poses by a whole turn (the same poses, reached
//! the other way round) so that every new move is free; a move that still
//! collides goes through a via configuration where one makes it free, and
//! what cannot be replaced is reported with its pair of links.

mod repair;

use crate::collision::{CollisionModel, ContactPair};
use crate::select::tour::{MoveCost, largest_travel};
use crate::select::turns::turned;
use rayon::prelude::*;
use serde::Serialize;
use std::collections::HashMap;

/// A move of the tour that collides.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct CollidingMove {
    /// Position in the visiting order of the pose the move starts from
    /// (`None`: from home).
    pub from: Option<usize>,
    /// Position in the visiting order of the pose the move goes to.
    pub to: usize,
    /// The links (or link and obstacle) that touch.
    pub pair: ContactPair,
    /// Where on the move (0 = start, 1 = end).
    pub at: f64,
}

/// A move of the tour made free by passing through a via configuration:
/// the operator's controller goes `from → q → to` (two straight joint-space
/// moves, each checked free), and the robot is not measured at `q`.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct ViaMove {
    /// Position in the visiting order of the pose the move starts from
    /// (`None`: from home).
    pub from: Option<usize>,
    /// Position in the visiting order of the pose the move goes to.
    pub to: usize,
    /// The via configuration's joint values.
    pub q: Vec<f64>,
    /// Its index among the candidates it was taken from (the pool's kept
    /// configurations).
    pub candidate: usize,
}

/// Via candidates tried for one colliding move, in order of the joint
/// travel they add (the least first): each try checks up to two moves
/// (a fraction of a second each on a meshed arm), so the search is kept
/// short.
pub const VIA_TRIES: usize = 12;

/// A pose whose joint values were changed by whole turns so that the moves
/// to and from it are free: the same pose (every link in the same place),
/// reached the other way round.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct TurnedPose {
    /// Position in the visiting order.
    pub pose: usize,
    /// Whole turns (2π) added to each joint's value (0 for most).
    pub turns: Vec<i32>,
}

/// Repairs tried for one colliding move, in order of the move time they
/// add (the least first): each checks up to three moves (memoised).
pub const REPAIR_TRIES: usize = 64;

/// Repairs whose moves are checked together (in parallel) before the
/// first free one of them is taken: the same repair is chosen as one by
/// one; a fixed number, so that the moves checked do not depend on the
/// number of threads. One: a repair's own two or three moves already run
/// in parallel, and on the xArm7 case two at a time took the same time
/// (2.75 s against 2.85 s, median of 5) for more moves checked.
pub const REPAIR_BATCH: usize = 1;

/// What a tour's moves are checked against, and what a repair may use.
#[derive(Clone, Copy, Debug)]
pub struct MoveSpace<'a> {
    /// The collision models every move is checked against.
    pub models: &'a [&'a CollisionModel],
    /// Largest motion of a link point between two checks, metres.
    pub resolution: f64,
    /// Via candidates: free configurations (the pool's).
    pub vias: &'a [Vec<f64>],
    /// Per joint, its limits when it turns all the way round (a pose's
    /// value may then change by whole turns within them), else `None`.
    pub turns: &'a [Option<[f64; 2]>],
    /// The time a move takes: repairs adding the least are tried first.
    pub cost: &'a MoveCost,
    /// The order is the user's (selection order kept): a colliding move
    /// may be avoided by whole turns or a via configuration, never by
    /// visiting the poses in another order.
    pub keep_order: bool,
}

/// What checking a tour's moves found.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct MovesReport {
    /// Largest motion of a link point between two checks, metres.
    pub resolution_m: f64,
    /// Moves checked (the repair's and the via search's trials included;
    /// a colliding move travelled against the way it was first checked is
    /// checked again).
    pub moves_checked: usize,
    /// Configurations checked along them.
    pub configurations_checked: usize,
    /// Moves of the planned order that collided.
    pub colliding_before: usize,
    /// Whether the order was changed to avoid them.
    pub reordered: bool,
    /// Poses whose joint values were turned by whole turns to avoid them.
    pub turned: Vec<TurnedPose>,
    /// Moves of the final order that collide straight and were made free
    /// through a via configuration.
    pub via: Vec<ViaMove>,
    /// Moves of the final order that still collide (none when every move
    /// is free).
    pub colliding: Vec<CollidingMove>,
}

/// Memoised move checks against every model.
struct Checker<'a> {
    models: &'a [&'a CollisionModel],
    resolution: f64,
    home: Option<&'a [f64]>,
    qs: &'a mut [Vec<f64>],
    memo: HashMap<(usize, usize), Option<(ContactPair, f64)>>,
    /// Moves checked, and configurations along them.
    moves: usize,
    configurations: usize,
    /// Whole turns added to each pose's joints.
    turned: Vec<Vec<i32>>,
    /// The time a move takes.
    cost: &'a MoveCost,
    /// Moves with a turned end checked so far: free or not.
    turned_memo: HashMap<(End, End), bool>,
}

/// An end of a move: a node, with whole turns added to its joints (none
/// when empty).
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub(super) struct End {
    pub node: usize,
    pub turns: Vec<i32>,
}

impl End {
    /// A node as it is.
    pub fn at(node: usize) -> Self {
        Self {
            node,
            turns: Vec::new(),
        }
    }
}

impl Checker<'_> {
    /// Node 0 is home, node `k + 1` pose `k`.
    fn node(&self, n: usize) -> &[f64] {
        if n == 0 {
            self.home.unwrap_or(&[])
        } else {
            &self.qs[n - 1]
        }
    }

    /// Turns pose node `n`'s joints by `turns` whole turns; its memoised
    /// moves are forgotten.
    fn turn(&mut self, n: usize, turns: &[i32]) {
        self.qs[n - 1] = turned(&self.qs[n - 1], turns);
        for (total, t) in self.turned[n - 1].iter_mut().zip(turns) {
            *total += t;
        }
        self.memo.retain(|k, _| k.0 != n && k.1 != n);
        self.turned_memo
            .retain(|k, _| k.0.node != n && k.1.node != n);
    }

    /// The joint values of an end.
    fn config(&self, e: &End) -> Vec<f64> {
        if e.turns.is_empty() {
            self.node(e.node).to_vec()
        } else {
            turned(self.node(e.node), &e.turns)
        }
    }

    /// Seconds the move between two ends takes.
    fn time(&self, a: &End, b: &End) -> f64 {
        self.cost.time(&self.config(a), &self.config(b))
    }

    /// Whether the move between two ends is free (memoised).
    fn free(&mut self, a: &End, b: &End) -> bool {
        if a.turns.is_empty() && b.turns.is_empty() {
            return self.contact(a.node, b.node).is_none();
        }
        let key = (a.clone(), b.clone());
        if let Some(&f) = self.turned_memo.get(&key) {
            return f;
        }
        let f = self.check(&self.config(a), &self.config(b)).is_none();
        self.turned_memo.insert(key, f);
        f
    }

    /// The first contact on the straight move from `qa` to `qb` against
    /// the models in turn (not memoised), its configurations counted.
    fn check(&mut self, qa: &[f64], qb: &[f64]) -> Option<(ContactPair, f64)> {
        let (checks, contact) = check_against(self.models, qa, qb, self.resolution);
        self.moves += 1;
        self.configurations += checks;
        contact
    }

    /// Checks the moves between the node pairs `keys` not checked yet, in
    /// parallel, and memoises them: the same verdicts as checking them one
    /// by one (each move's check is its own), in a fraction of the time.
    fn prefetch(&mut self, keys: &[(usize, usize)]) {
        let mut todo: Vec<(usize, usize)> = keys
            .iter()
            .map(|&(a, b)| (a.min(b), a.max(b)))
            .filter(|k| !self.memo.contains_key(k))
            .collect();
        todo.sort_unstable();
        todo.dedup();
        let found: Vec<(usize, Option<(ContactPair, f64)>)> = todo
            .par_iter()
            .map(|&(a, b)| check_against(self.models, self.node(a), self.node(b), self.resolution))
            .collect();
        for (key, (checks, contact)) in todo.into_iter().zip(found) {
            self.moves += 1;
            self.configurations += checks;
            self.memo.insert(key, contact);
        }
    }

    /// The first contact on the move between nodes `a` and `b`.
    fn contact(&mut self, a: usize, b: usize) -> Option<(ContactPair, f64)> {
        let key = (a.min(b), a.max(b));
        if let Some(c) = self.memo.get(&key) {
            return c.clone();
        }
        let (qa, qb) = (self.node(key.0).to_vec(), self.node(key.1).to_vec());
        let found = self.check(&qa, &qb);
        self.memo.insert(key, found.clone());
        found
    }

    /// The first contact on the move from node `a` to node `b`, in the
    /// direction of travel: the memo holds each move checked from its
    /// lower node, whose first contact is the last one when travelling the
    /// other way, so such a move is checked again from `a`.
    fn first_contact_along(&mut self, a: usize, b: usize) -> (ContactPair, f64) {
        let memo = self.contact(a, b).expect("a colliding move");
        if a < b {
            return memo;
        }
        let (qa, qb) = (self.node(a).to_vec(), self.node(b).to_vec());
        // The fallback is unreachable in exact arithmetic (the move
        // collides); the memo's contact, seen from the travel direction, is
        // the best left.
        self.check(&qa, &qb).unwrap_or((memo.0, 1.0 - memo.1))
    }

    /// The nodes of a visiting order (home first when given).
    fn path(&self, order: &[usize]) -> Vec<usize> {
        let start = usize::from(self.home.is_none());
        let mut p: Vec<usize> = Vec::with_capacity(order.len() + 1);
        if start == 0 {
            p.push(0);
        }
        p.extend(order.iter().map(|&k| k + 1));
        p
    }

    /// Checks the moves between ends `moves` not checked yet, in parallel,
    /// and memoises them, as [`Self::prefetch`] does for plain nodes.
    fn prefetch_ends(&mut self, moves: &[(End, End)]) {
        let plain = |(a, b): &(End, End)| a.turns.is_empty() && b.turns.is_empty();
        let nodes: Vec<(usize, usize)> = moves
            .iter()
            .filter(|m| plain(m))
            .map(|(a, b)| (a.node, b.node))
            .collect();
        self.prefetch(&nodes);
        let mut todo: Vec<(End, End)> = Vec::new();
        for m in moves.iter().filter(|m| !plain(m)) {
            if !self.turned_memo.contains_key(m) && !todo.contains(m) {
                todo.push(m.clone());
            }
        }
        let found: Vec<(usize, bool)> = todo
            .par_iter()
            .map(|(a, b)| {
                let (qa, qb) = (self.config(a), self.config(b));
                let (checks, contact) = check_against(self.models, &qa, &qb, self.resolution);
                (checks, contact.is_none())
            })
            .collect();
        for (key, (checks, free)) in todo.into_iter().zip(found) {
            self.moves += 1;
            self.configurations += checks;
            self.turned_memo.insert(key, free);
        }
    }

    /// Positions `i` in `path` whose move `path[i] → path[i+1]` collides.
    fn colliding(&mut self, path: &[usize]) -> Vec<usize> {
        let keys: Vec<(usize, usize)> = path.windows(2).map(|w| (w[0], w[1])).collect();
        self.prefetch(&keys);
        (0..path.len().saturating_sub(1))
            .filter(|&i| self.contact(path[i], path[i + 1]).is_some())
            .collect()
    }
}

/// The configurations checked on the straight move from `qa` to `qb`
/// against `models` in turn, and the first contact.
fn check_against(
    models: &[&CollisionModel],
    qa: &[f64],
    qb: &[f64],
    resolution: f64,
) -> (usize, Option<(ContactPair, f64)>) {
    let mut checks = 0;
    for m in models {
        let r = m.check_move(qa, qb, resolution);
        checks += r.checks;
        if r.contact.is_some() {
            return (checks, r.contact);
        }
    }
    (checks, None)
}

/// A via configuration for the colliding move from node `a` to node `b`:
/// among `vias`, the first (of the [`VIA_TRIES`] that add the least
/// largest-joint travel) whose moves from `a` and to `b` are both free.
fn via_for(c: &mut Checker<'_>, a: usize, b: usize, vias: &[Vec<f64>]) -> Option<usize> {
    let (qa, qb) = (c.node(a).to_vec(), c.node(b).to_vec());
    let mut order: Vec<(f64, usize)> = vias
        .iter()
        .enumerate()
        .map(|(k, v)| (largest_travel(&qa, v) + largest_travel(v, &qb), k))
        .collect();
    let tries = VIA_TRIES.min(order.len());
    if tries == 0 {
        return None;
    }
    order.select_nth_unstable_by(tries - 1, |x, y| x.0.total_cmp(&y.0));
    order.truncate(tries);
    order.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
    order
        .into_iter()
        .map(|(_, k)| k)
        .find(|&k| c.check(&qa, &vias[k]).is_none() && c.check(&vias[k], &qb).is_none())
}

/// Checks the moves of visiting `qs` in `order` from `home` against
/// `space`'s models at its resolution, and removes colliding moves where
/// it can: of the 2-opt reversals, Or-opt relocations of one pose and whole
/// turns of a stretch of poses that replace a colliding move (the home kept
/// first), the one adding the least move time whose new moves are all free
/// is applied ([`repair::repair`]; only the turns when `space.keep_order`); a move that still collides goes through
/// a via configuration from `space.vias` when one makes both its halves
/// free ([`ViaMove`]). `order` and the turned poses' values in `qs` are
/// updated.
pub fn check_tour(
    space: &MoveSpace<'_>,
    home: Option<&[f64]>,
    qs: &mut [Vec<f64>],
    order: &mut Vec<usize>,
) -> MovesReport {
    let dof = qs.first().map_or(0, Vec::len);
    let turned = vec![vec![0; dof]; qs.len()];
    let mut c = Checker {
        models: space.models,
        resolution: space.resolution,
        home,
        qs,
        memo: HashMap::new(),
        moves: 0,
        configurations: 0,
        turned,
        cost: space.cost,
        turned_memo: HashMap::new(),
    };
    let mut path = c.path(order);
    let before = c.colliding(&path).len();
    let first = usize::from(home.is_some()); // the home node never moves
    let mut reordered = false;
    // Each accepted change removes at least one colliding move and adds
    // none (its new moves are all free; a turned stretch's inner moves are
    // the same moves).
    for _ in 0..before {
        let bad = c.colliding(&path);
        let Some(next) = bad
            .iter()
            .find_map(|&i| repair::repair(&mut c, &path, i, first, space))
        else {
            break;
        };
        reordered |= next != path;
        path = next;
    }
    let pos = |n: usize| path[first..].iter().position(|&x| x == n);
    let from_of = |n: usize| {
        if n == 0 && home.is_some() {
            None
        } else {
            pos(n)
        }
    };
    let mut via = Vec::new();
    let mut colliding = Vec::new();
    for i in c.colliding(&path) {
        match via_for(&mut c, path[i], path[i + 1], space.vias) {
            Some(k) => via.push(ViaMove {
                from: from_of(path[i]),
                to: pos(path[i + 1]).unwrap_or(0),
                q: space.vias[k].clone(),
                candidate: k,
            }),
            None => {
                let (pair, at) = c.first_contact_along(path[i], path[i + 1]);
                colliding.push(CollidingMove {
                    from: from_of(path[i]),
                    to: pos(path[i + 1]).unwrap_or(0),
                    pair,
                    at,
                });
            }
        }
    }
    let turned = path[first..]
        .iter()
        .enumerate()
        .filter(|&(_, &n)| c.turned[n - 1].iter().any(|&t| t != 0))
        .map(|(k, &n)| TurnedPose {
            pose: k,
            turns: c.turned[n - 1].clone(),
        })
        .collect();
    *order = path[first..].iter().map(|&n| n - 1).collect();
    MovesReport {
        resolution_m: space.resolution,
        moves_checked: c.moves,
        configurations_checked: c.configurations,
        colliding_before: before,
        reordered,
        turned,
        via,
        colliding,
    }
}

//! The moves of a visiting order checked for collision: every straight
//! joint-space move (home → first → … → last) is checked against the
//! pool's collision models ([`CollisionModel::check_move`]); a move that
//! collides is replaced, when possible, by reversing a stretch of the tour
//! (a 2-opt move) or moving one of its poses elsewhere (Or-opt) so that
//! every new move is free; what cannot be replaced is reported with its
//! pair of links.

use crate::collision::{CollisionModel, ContactPair};
use crate::select::tour::largest_travel;
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

/// What checking a tour's moves found.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct MovesReport {
    /// Largest motion of a link point between two checks, metres.
    pub resolution_m: f64,
    /// Moves checked (distinct moves, the repair's trials included).
    pub moves_checked: usize,
    /// Configurations checked along them.
    pub configurations_checked: usize,
    /// Moves of the planned order that collided.
    pub colliding_before: usize,
    /// Whether the order was changed to avoid them.
    pub reordered: bool,
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
    qs: &'a [Vec<f64>],
    memo: HashMap<(usize, usize), Option<(ContactPair, f64)>>,
    configurations: usize,
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

    /// The first contact on the straight move from `qa` to `qb` against
    /// the models in turn (not memoised), its configurations counted.
    fn check(&mut self, qa: &[f64], qb: &[f64]) -> Option<(ContactPair, f64)> {
        for m in self.models {
            let r = m.check_move(qa, qb, self.resolution);
            self.configurations += r.checks;
            if r.contact.is_some() {
                return r.contact;
            }
        }
        None
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

    /// Positions `i` in `path` whose move `path[i] → path[i+1]` collides.
    fn colliding(&mut self, path: &[usize]) -> Vec<usize> {
        (0..path.len().saturating_sub(1))
            .filter(|&i| self.contact(path[i], path[i + 1]).is_some())
            .collect()
    }
}

/// A 2-opt reversal that removes the colliding move `path[i] → path[i+1]`
/// with free new moves: a stretch after it (`path[i+1..=j]`, whose new
/// moves are `i → j` and `i+1 → j+1`) or one ending at it (`path[k..=i]`,
/// new moves `k−1 → i` and `k → i+1`), the nodes before `first` kept.
fn reversal(c: &mut Checker<'_>, path: &[usize], i: usize, first: usize) -> Option<Vec<usize>> {
    let n = path.len();
    for j in (i + 2)..n {
        if c.contact(path[i], path[j]).is_none()
            && (j + 1 >= n || c.contact(path[i + 1], path[j + 1]).is_none())
        {
            let mut p = path.to_vec();
            p[i + 1..=j].reverse();
            return Some(p);
        }
    }
    for k in (first..i).rev() {
        if (k == 0 || c.contact(path[k - 1], path[i]).is_none())
            && c.contact(path[k], path[i + 1]).is_none()
        {
            let mut p = path.to_vec();
            p[k..=i].reverse();
            return Some(p);
        }
    }
    None
}

/// An Or-opt relocation that removes the colliding move `path[i] →
/// path[i+1]`: one of its two poses taken out (its neighbours joined) and
/// put between two other poses, every new move free; insertion places are
/// tried in order of the joint travel they add (the least first).
fn relocation(c: &mut Checker<'_>, path: &[usize], i: usize, first: usize) -> Option<Vec<usize>> {
    for at in [i + 1, i] {
        if at < first {
            continue;
        }
        let x = path[at];
        let mut rest = path.to_vec();
        rest.remove(at);
        if at > 0 && at < rest.len() && c.contact(rest[at - 1], rest[at]).is_some() {
            continue;
        }
        let travel = |a: usize, b: usize| largest_travel(c.node(a), c.node(b));
        let mut places: Vec<(f64, usize)> = (first.max(1)..=rest.len())
            .filter(|&j| j != at)
            .map(|j| {
                let added = travel(rest[j - 1], x)
                    + if j < rest.len() {
                        travel(x, rest[j]) - travel(rest[j - 1], rest[j])
                    } else {
                        0.0
                    };
                (added, j)
            })
            .collect();
        places.sort_by(|a, b| a.0.total_cmp(&b.0));
        for (_, j) in places {
            if c.contact(rest[j - 1], x).is_none()
                && (j == rest.len() || c.contact(x, rest[j]).is_none())
            {
                let mut p = rest.clone();
                p.insert(j, x);
                return Some(p);
            }
        }
    }
    None
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
/// `models` at `resolution` metres, and reorders `order` (2-opt
/// reversals and Or-opt relocations of one pose whose new moves are free,
/// the home kept first) to remove colliding moves where it can; a move
/// that still collides goes through a via configuration from `vias` when
/// one makes both its halves free ([`ViaMove`]).
pub fn check_tour(
    models: &[&CollisionModel],
    resolution: f64,
    home: Option<&[f64]>,
    qs: &[Vec<f64>],
    order: &mut Vec<usize>,
    vias: &[Vec<f64>],
) -> MovesReport {
    let mut c = Checker {
        models,
        resolution,
        home,
        qs,
        memo: HashMap::new(),
        configurations: 0,
    };
    let mut path = c.path(order);
    let before = c.colliding(&path).len();
    let first = usize::from(home.is_some()); // the home node never moves
    let mut reordered = false;
    // Each accepted change removes at least one colliding move and adds
    // none (its new moves are all free).
    for _ in 0..before {
        let bad = c.colliding(&path);
        let Some(next) = bad.iter().find_map(|&i| {
            reversal(&mut c, &path, i, first).or_else(|| relocation(&mut c, &path, i, first))
        }) else {
            break;
        };
        path = next;
        reordered = true;
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
    let mut still = Vec::new();
    for i in c.colliding(&path) {
        match via_for(&mut c, path[i], path[i + 1], vias) {
            Some(k) => via.push(ViaMove {
                from: from_of(path[i]),
                to: pos(path[i + 1]).unwrap_or(0),
                q: vias[k].clone(),
                candidate: k,
            }),
            None => still.push(i),
        }
    }
    let colliding: Vec<CollidingMove> = still
        .into_iter()
        .map(|i| {
            let (pair, at) = c.first_contact_along(path[i], path[i + 1]);
            let pos = |n: usize| path[first..].iter().position(|&x| x == n);
            CollidingMove {
                from: if path[i] == 0 && home.is_some() {
                    None
                } else {
                    pos(path[i])
                },
                to: pos(path[i + 1]).unwrap_or(0),
                pair,
                at,
            }
        })
        .collect();
    *order = path[first..].iter().map(|&n| n - 1).collect();
    MovesReport {
        resolution_m: resolution,
        moves_checked: c.memo.len(),
        configurations_checked: c.configurations,
        colliding_before: before,
        reordered,
        via,
        colliding,
    }
}

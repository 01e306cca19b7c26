//! Repairs of a colliding move of a tour. Three kinds of change replace
//! the move `path[i] → path[i+1]` by others: a 2-opt reversal of a stretch
//! after it or ending at it, an Or-opt relocation of one of its two poses,
//! and whole turns of the joints of a stretch of poses starting at its
//! destination or ending at its start (a joint that turns all the way
//! round reaches the same angle a turn away, so the poses and the moves
//! inside the stretch are unchanged and only its entry and exit moves go
//! the other way round, [`crate::select::turns`]). Every candidate is
//! priced by the move time it adds, and the cheapest whose new moves are
//! all free is applied.

use super::{Checker, End, MoveSpace, REPAIR_BATCH, REPAIR_TRIES};
use crate::select::turns::{product, turns_within};

/// A change that replaces a colliding move.
struct Candidate {
    /// Move time it adds, seconds (negative: it saves).
    added: f64,
    /// The new path (`None`: the same path).
    path: Option<Vec<usize>>,
    /// The stretch of positions `lo..=hi` it turns, and by how many whole
    /// turns per joint.
    turn: Option<(usize, usize, Vec<i32>)>,
    /// The moves it adds: each must be free.
    moves: Vec<(End, End)>,
}

impl Candidate {
    /// A new order of the same poses.
    fn reorder(added: f64, path: Vec<usize>, moves: Vec<(End, End)>) -> Self {
        Self {
            added,
            path: Some(path),
            turn: None,
            moves,
        }
    }
}

/// Replaces the colliding move `path[i] → path[i+1]` (positions before
/// `first` stay): of the candidate reversals, relocations and turned
/// stretches (only the turned stretches when `space.keep_order`), the
/// [`REPAIR_TRIES`] adding the least move time are tried in that order
/// ([`REPAIR_BATCH`] at a time, their moves checked in parallel), and the
/// first whose new moves are all free is applied (a turned stretch
/// to the checker's poses). Returns the new path.
pub(super) fn repair(
    c: &mut Checker<'_>,
    path: &[usize],
    i: usize,
    first: usize,
    space: &MoveSpace<'_>,
) -> Option<Vec<usize>> {
    let mut all = if space.keep_order {
        Vec::new()
    } else {
        let mut v = reversals(c, path, i, first);
        v.extend(relocations(c, path, i, first));
        v
    };
    all.extend(stretches(c, path, i, first, space.turns));
    // Stable: on equal times, reorders before turns.
    all.sort_by(|a, b| a.added.total_cmp(&b.added));
    all.truncate(REPAIR_TRIES);
    for batch in all.chunks(REPAIR_BATCH) {
        let moves: Vec<(End, End)> = batch.iter().flat_map(|k| k.moves.iter().cloned()).collect();
        c.prefetch_ends(&moves);
        let Some(found) = batch
            .iter()
            .find(|k| k.moves.iter().all(|(a, b)| c.free(a, b)))
        else {
            continue;
        };
        if let Some((lo, hi, turns)) = &found.turn {
            for &n in &path[*lo..=*hi] {
                c.turn(n, turns);
            }
        }
        return Some(found.path.clone().unwrap_or_else(|| path.to_vec()));
    }
    None
}

/// The seconds of the move between nodes `a` and `b` as they are.
fn t(c: &Checker<'_>, a: usize, b: usize) -> f64 {
    c.time(&End::at(a), &End::at(b))
}

/// The move between nodes `a` and `b` as they are.
fn mv(a: usize, b: usize) -> (End, End) {
    (End::at(a), End::at(b))
}

/// 2-opt reversals: a stretch after the move (`path[i+1..=j]`, new moves
/// `i → j` and `i+1 → j+1`) or one ending at it (`path[k..=i]`, new moves
/// `k−1 → i` and `k → i+1`).
fn reversals(c: &Checker<'_>, path: &[usize], i: usize, first: usize) -> Vec<Candidate> {
    let n = path.len();
    let mut out = Vec::new();
    for j in (i + 2)..n {
        let mut moves = vec![mv(path[i], path[j])];
        let mut added = t(c, path[i], path[j]) - t(c, path[i], path[i + 1]);
        if j + 1 < n {
            moves.push(mv(path[i + 1], path[j + 1]));
            added += t(c, path[i + 1], path[j + 1]) - t(c, path[j], path[j + 1]);
        }
        let mut p = path.to_vec();
        p[i + 1..=j].reverse();
        out.push(Candidate::reorder(added, p, moves));
    }
    for k in first..i {
        let mut moves = vec![mv(path[k], path[i + 1])];
        let mut added = t(c, path[k], path[i + 1]) - t(c, path[i], path[i + 1]);
        if k > 0 {
            moves.push(mv(path[k - 1], path[i]));
            added += t(c, path[k - 1], path[i]) - t(c, path[k - 1], path[k]);
        }
        let mut p = path.to_vec();
        p[k..=i].reverse();
        out.push(Candidate::reorder(added, p, moves));
    }
    out
}

/// Or-opt relocations: one of the move's two poses taken out (its
/// neighbours joined) and put between two others (or at either end).
fn relocations(c: &Checker<'_>, path: &[usize], i: usize, first: usize) -> Vec<Candidate> {
    let n = path.len();
    let mut out = Vec::new();
    for at in [i + 1, i] {
        if at < first {
            continue;
        }
        let x = path[at];
        let mut rest = path.to_vec();
        rest.remove(at);
        // Taking it out: its moves go, its neighbours are joined.
        let mut join = Vec::new();
        let mut removed = 0.0;
        if at > 0 {
            removed -= t(c, path[at - 1], x);
        }
        if at + 1 < n {
            removed -= t(c, x, path[at + 1]);
        }
        if at > 0 && at + 1 < n {
            join.push(mv(path[at - 1], path[at + 1]));
            removed += t(c, path[at - 1], path[at + 1]);
        }
        for j in (first..=rest.len()).filter(|&j| j != at) {
            let mut moves = join.clone();
            let mut added = removed;
            if j > 0 {
                moves.push(mv(rest[j - 1], x));
                added += t(c, rest[j - 1], x);
            }
            if j < rest.len() {
                moves.push(mv(x, rest[j]));
                added += t(c, x, rest[j]);
            }
            if j > 0 && j < rest.len() {
                added -= t(c, rest[j - 1], rest[j]);
            }
            let mut p = rest.clone();
            p.insert(j, x);
            out.push(Candidate::reorder(added, p, moves));
        }
    }
    out
}

/// Per joint, the whole turns (0 first) that keep every pose of
/// `path[lo..=hi]` within `limits` (only 0 for a joint without).
fn stretch_turns(
    c: &Checker<'_>,
    path: &[usize],
    lo: usize,
    hi: usize,
    limits: &[Option<[f64; 2]>],
) -> Vec<Vec<i32>> {
    limits
        .iter()
        .enumerate()
        .map(|(j, &lim)| {
            let mut ok = turns_within(c.node(path[lo])[j], lim);
            for &n in &path[lo + 1..=hi] {
                let here = turns_within(c.node(n)[j], lim);
                ok.retain(|t| here.contains(t));
            }
            ok
        })
        .collect()
}

/// Turned stretches: those starting at the move's destination (`i + 1 ..=
/// hi`: new moves `i → i+1` turned and `hi` turned `→ hi+1`) and those
/// ending at its start (`lo ..= i`: new moves `lo−1 → lo` turned and `i`
/// turned `→ i+1`), with every combination of whole turns that keeps their
/// poses within their limits.
fn stretches(
    c: &Checker<'_>,
    path: &[usize],
    i: usize,
    first: usize,
    limits: &[Option<[f64; 2]>],
) -> Vec<Candidate> {
    let n = path.len();
    let bounds = ((i + 1)..n)
        .map(|hi| (i + 1, hi))
        .chain((first..=i).map(|lo| (lo, i)));
    let mut out = Vec::new();
    for (lo, hi) in bounds {
        let mut all = product(&stretch_turns(c, path, lo, hi, limits));
        all.retain(|x| x.iter().any(|&t| t != 0));
        for turns in all {
            let at = |p: usize| End {
                node: path[p],
                turns: turns.clone(),
            };
            let mut moves = Vec::new();
            let mut added = 0.0;
            if lo > 0 {
                let e = (End::at(path[lo - 1]), at(lo));
                added += c.time(&e.0, &e.1) - t(c, path[lo - 1], path[lo]);
                moves.push(e);
            }
            if hi + 1 < n {
                let e = (at(hi), End::at(path[hi + 1]));
                added += c.time(&e.0, &e.1) - t(c, path[hi], path[hi + 1]);
                moves.push(e);
            }
            out.push(Candidate {
                added,
                path: None,
                turn: Some((lo, hi, turns)),
                moves,
            });
        }
    }
    out
}

//! What each pool filter removed: counts, and for a collision filter the
//! pairs of links (or link and obstacle) that removed the candidates, the
//! ten largest first, with a warning when a filter removes nearly all.

use super::FilterStat;
use crate::collision::{CollisionModel, ContactPair, TouchingPair};
use serde::Serialize;
use std::collections::BTreeMap;
use std::sync::Arc;

/// A verdict's contact when no collision filter removed the candidate.
pub const NO_CONTACT: usize = usize::MAX;

/// Fraction of the candidates reaching a filter above which its removals
/// are called out: a filter that leaves under a tenth of the poses is most
/// likely checking pairs that touch by design.
pub const MOST: f64 = 0.9;

/// Pairs listed per filter.
pub const TOP_PAIRS: usize = 10;

/// Candidates one pair removed.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct PairCount {
    /// The first link.
    pub link: String,
    /// The other link, or the obstacle (`box 1`, `floor`).
    pub other: String,
    /// Whether `other` is an obstacle.
    pub obstacle: bool,
    /// Candidates it removed (the first contact found in each).
    pub removed: usize,
}

/// Which contacts removed a collision filter's candidates.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ContactCounts {
    /// Removed by two links touching.
    pub self_collision: usize,
    /// Removed by a link touching an obstacle.
    pub obstacle: usize,
    /// Distinct pairs that removed any.
    pub distinct_pairs: usize,
    /// The [`TOP_PAIRS`] pairs that removed most, most first (ties by name).
    pub top: Vec<PairCount>,
    /// Link pairs not checked because they touch in nearly every sampled
    /// configuration ([`AlwaysTouching`](crate::collision::AlwaysTouching)).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub always_touching: Vec<TouchingPair>,
}

/// Counts the contacts of `verdict` (first failing filter, contact key) for
/// filter `f` with its model.
fn contact_counts(model: &CollisionModel, verdict: &[(usize, usize)], f: usize) -> ContactCounts {
    let mut by_key: BTreeMap<usize, usize> = BTreeMap::new();
    for &(g, key) in verdict {
        if g == f && key != NO_CONTACT {
            *by_key.entry(key).or_default() += 1;
        }
    }
    let mut by_pair: BTreeMap<ContactPair, usize> = BTreeMap::new();
    for (key, n) in by_key {
        *by_pair.entry(model.pair_of(key)).or_default() += n;
    }
    let (mut own, mut obstacle) = (0, 0);
    for (p, n) in &by_pair {
        if p.obstacle {
            obstacle += n;
        } else {
            own += n;
        }
    }
    let mut pairs: Vec<(ContactPair, usize)> = by_pair.into_iter().collect();
    let distinct_pairs = pairs.len();
    pairs.sort_by(|a, b| b.1.cmp(&a.1).then_with(|| a.0.cmp(&b.0)));
    ContactCounts {
        self_collision: own,
        obstacle,
        distinct_pairs,
        top: pairs
            .into_iter()
            .take(TOP_PAIRS)
            .map(|(p, removed)| PairCount {
                link: p.link,
                other: p.other,
                obstacle: p.obstacle,
                removed,
            })
            .collect(),
        always_touching: model.always_touching().to_vec(),
    }
}

/// The warning of a filter that removed more than [`MOST`] of what reached
/// it.
fn warning(s: &FilterStat) -> Option<String> {
    if s.seen == 0 || (s.removed as f64) <= MOST * s.seen as f64 {
        return None;
    }
    let mut w = format!(
        "the {} filter removed {} of {} candidates ({:.1} %)",
        s.filter,
        s.removed,
        s.seen,
        100.0 * s.removed as f64 / s.seen as f64
    );
    if let Some(p) = s.contacts.as_ref().and_then(|c| c.top.first()) {
        w += &format!(
            "; the pair that removed most is {} – {} ({} candidates)",
            p.link, p.other, p.removed
        );
        if !p.obstacle {
            w += ": links that touch by design (a hand on its flange, neighbours two joints apart) are listed in the robot's SRDF as disable_collisions, and pairs listed there are not checked";
        }
    }
    Some(w)
}

/// One [`FilterStat`] per filter (`names`, with the collision filters'
/// loaded `models`), from each candidate's verdict: the first filter that
/// removed it (`names.len()`: none) and the contact that did.
#[must_use]
pub fn filter_stats(
    names: &[String],
    models: &[Option<Arc<CollisionModel>>],
    verdict: &[(usize, usize)],
    candidates: usize,
) -> Vec<FilterStat> {
    let mut removed = vec![0usize; names.len()];
    for &(f, _) in verdict {
        if f < names.len() {
            removed[f] += 1;
        }
    }
    let mut seen = candidates;
    names
        .iter()
        .enumerate()
        .map(|(f, name)| {
            let mut s = FilterStat {
                filter: name.clone(),
                seen,
                removed: removed[f],
                contacts: models
                    .get(f)
                    .and_then(Option::as_ref)
                    .map(|m| contact_counts(m, verdict, f)),
                warning: None,
            };
            s.warning = warning(&s);
            seen -= removed[f];
            s
        })
        .collect()
}

/// The error of a pool its filters emptied: the filter that removed the
/// last candidates, and its warning (the pair that removed most).
#[must_use]
pub fn emptied(filters: &[FilterStat], candidates: usize) -> String {
    let Some(k) = filters.iter().rposition(|f| f.removed > 0) else {
        return "the pool has no candidates".into();
    };
    let f = &filters[k];
    let mut s = format!(
        "the {} filter removed every pose of the pool that reached it ({} of {}; the source had {})",
        f.filter, f.removed, f.seen, candidates
    );
    if let Some(p) = f.contacts.as_ref().and_then(|c| c.top.first()) {
        s += &format!(
            "; the pair that removed most is {} – {} ({} candidates)",
            p.link, p.other, p.removed
        );
        if !p.obstacle {
            s += ": links that touch by design are listed in the robot's SRDF as disable_collisions, and pairs listed there are not checked";
        }
    }
    s
}

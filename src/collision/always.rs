//! Link pairs that touch by design, found by sampling: the "always in
//! collision" rule of MoveIt's setup assistant, for a URDF that comes
//! without an SRDF. Robot descriptions often model neighbouring covers that
//! overlap in every configuration (TIAGo's torso and arm mount); checking
//! them would remove every candidate.

use super::model::{CollisionModel, too_close};
use super::spec::{AlwaysTouching, TouchingPair};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

/// `n` configurations drawn uniformly within `limits` (lower, upper per
/// value), from `seed`: the same draws whatever the thread count.
fn draws(limits: &[(f64, f64)], n: usize, seed: u64) -> Vec<Vec<f64>> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..n)
        .map(|_| {
            limits
                .iter()
                .map(|&(lo, hi)| {
                    if hi > lo {
                        rng.random_range(lo..hi)
                    } else {
                        lo
                    }
                })
                .collect()
        })
        .collect()
}

impl CollisionModel {
    /// The link pair of each checked geometry pair, as an index into the
    /// returned list of distinct link pairs (smaller link index first).
    fn link_pairs(&self) -> (Vec<usize>, Vec<(usize, usize)>) {
        let mut distinct: Vec<(usize, usize)> = Vec::new();
        let of_pair = self
            .pairs
            .iter()
            .map(|&(a, b)| {
                let (la, lb) = (self.geoms[a].link, self.geoms[b].link);
                let key = (la.min(lb), la.max(lb));
                distinct.iter().position(|&k| k == key).unwrap_or_else(|| {
                    distinct.push(key);
                    distinct.len() - 1
                })
            })
            .collect();
        (of_pair, distinct)
    }

    /// Whether each link pair touches at `q` (any of its geometry pairs
    /// intersects: touching, whatever the clearance).
    fn touching_at(&self, q: &[f64], of_pair: &[usize], n_links: usize) -> Vec<bool> {
        let poses = self.geometry_poses(q);
        let mut touching = vec![false; n_links];
        for (k, &(a, b)) in self.pairs.iter().enumerate() {
            if touching[of_pair[k]] {
                continue;
            }
            let (ga, gb) = (&self.geoms[a], &self.geoms[b]);
            let gap = (poses[a] * ga.center - poses[b] * gb.center).norm();
            if gap <= ga.radius + gb.radius
                && too_close(
                    &poses[a],
                    ga.shape.as_ref(),
                    &poses[b],
                    gb.shape.as_ref(),
                    0.0,
                )
            {
                touching[of_pair[k]] = true;
            }
        }
        touching
    }

    /// Stops checking the link pairs that touch in at least
    /// `rule.fraction` of `rule.samples` configurations drawn uniformly
    /// within `limits` (one (lower, upper) per configuration value), and
    /// returns them, most often touching first.
    pub(super) fn skip_always_touching(
        &mut self,
        rule: &AlwaysTouching,
        limits: &[(f64, f64)],
    ) -> Vec<TouchingPair> {
        let (of_pair, links) = self.link_pairs();
        let qs = draws(limits, rule.samples, rule.seed);
        let counts = qs
            .par_iter()
            .map(|q| self.touching_at(q, &of_pair, links.len()))
            .fold(
                || vec![0usize; links.len()],
                |mut c, t| {
                    c.iter_mut().zip(t).for_each(|(c, t)| *c += usize::from(t));
                    c
                },
            )
            .reduce(
                || vec![0usize; links.len()],
                |a, b| a.iter().zip(b).map(|(a, b)| a + b).collect(),
            );
        let fraction = |l: usize| counts[l] as f64 / rule.samples.max(1) as f64;
        let skipped: Vec<usize> = (0..links.len())
            .filter(|&l| rule.samples > 0 && fraction(l) >= rule.fraction)
            .collect();
        let mut k = 0;
        self.pairs.retain(|_| {
            let keep = !skipped.contains(&of_pair[k]);
            k += 1;
            keep
        });
        let mut out: Vec<TouchingPair> = skipped
            .iter()
            .map(|&l| TouchingPair {
                link: self.tree.links[links[l].0].clone(),
                other: self.tree.links[links[l].1].clone(),
                fraction: fraction(l),
            })
            .collect();
        out.sort_by(|a, b| b.fraction.total_cmp(&a.fraction).then(a.link.cmp(&b.link)));
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn draws_stay_within_limits_and_repeat_with_the_seed() {
        let limits = [(-1.0, 2.0), (0.5, 0.5), (-3.0, -2.0)];
        let a = draws(&limits, 200, 7);
        assert_eq!(a, draws(&limits, 200, 7));
        assert_ne!(a, draws(&limits, 200, 8));
        for q in &a {
            for (v, &(lo, hi)) in q.iter().zip(&limits) {
                assert!(*v >= lo && *v <= hi, "{v} outside {lo}..{hi}");
            }
        }
        // A fixed value (lower = upper) stays at it.
        assert!(a.iter().all(|q| q[1] == 0.5));
    }
}

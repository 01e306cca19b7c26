//! A straight joint-space move checked for contact by conservative
//! advancement.

use super::model::{CollisionModel, ContactPair};
use super::tree::Motion;

/// What [`CollisionModel::check_move`] found on a move.
#[derive(Clone, Debug, PartialEq)]
pub struct MoveCheck {
    /// Configurations checked.
    pub checks: usize,
    /// The first contact and where on the move (0..=1) it is.
    pub contact: Option<(ContactPair, f64)>,
}

/// The share of an item's free distance that a step may close: the rates
/// bound the closing for the whole move, so a share of 1 could not skip a
/// contact in exact arithmetic; the tenth left absorbs rounding and the
/// distance queries' tolerance.
const STEP_SHARE: f64 = 0.9;

impl CollisionModel {
    /// Checks the straight joint-space move from `a` to `b` by conservative
    /// advancement. Every checked item (a pair of geometries, or a geometry
    /// and an obstacle) gets a rate: how fast its gap can close per unit of
    /// the move, from the joints between its two sides only (joints above
    /// both move them together), each joint's rate bounded for the whole
    /// move ([`Self::reach_bounds`]). At each configuration every item's
    /// distance is bounded from below (its bounding spheres' gap, or the
    /// bound carried from the last step less what the step can have
    /// closed), parry's exact distance is taken for the items whose bound
    /// could limit the step (least bound-over-rate first), and the next
    /// step lets no item close more than [`STEP_SHARE`] of its free distance beyond
    /// the clearance — so no two geometries can meet between checks — and
    /// near contact moves no point of a geometry more than `resolution`
    /// metres. Returns the configurations checked and the first contact
    /// (closer than the clearance) with where it is on the move (0 = `a`,
    /// 1 = `b`).
    #[must_use]
    pub fn check_move(&self, a: &[f64], b: &[f64], resolution: f64) -> MoveCheck {
        let at = |s: f64| -> Vec<f64> { a.iter().zip(b).map(|(x, y)| x + s * (y - x)).collect() };
        let keys = self.item_keys();
        let reach = self.reach_bounds(a, b);
        let dq: Vec<f64> = a.iter().zip(b).map(|(x, y)| (y - x).abs()).collect();
        let rates: Vec<f64> = keys
            .iter()
            .map(|&k| self.item_rate(k, &reach, &dq))
            .collect();
        // The fastest point of any geometry, metres per unit of the move.
        let speed = reach
            .iter()
            .map(|r| r.iter().zip(&dq).map(|(x, d)| x * d).sum::<f64>())
            .fold(0.0f64, f64::max);
        let floor = if speed > 0.0 { resolution / speed } else { 1.0 };
        let mut carried = vec![f64::NEG_INFINITY; keys.len()];
        let c = self.clearance;
        let (mut s, mut checks) = (0.0f64, 0usize);
        loop {
            let q = at(s);
            checks += 1;
            let poses = self.geometry_poses(&q);
            let mut bound: Vec<f64> = keys
                .iter()
                .zip(&carried)
                .map(|(&k, &cb)| self.item(k, &poses).4.max(cb))
                .collect();
            // What each bound allows as a step; items that may touch first.
            let allowed = |bound: f64, rate: f64| -> f64 {
                if bound <= c {
                    0.0
                } else if rate > 0.0 {
                    STEP_SHARE * (bound - c) / rate
                } else {
                    f64::INFINITY
                }
            };
            let mut order: Vec<usize> = (0..keys.len()).collect();
            order.sort_by(|&i, &j| {
                allowed(bound[i], rates[i]).total_cmp(&allowed(bound[j], rates[j]))
            });
            let mut step = f64::INFINITY;
            for i in order {
                let cheap = allowed(bound[i], rates[i]);
                if cheap > 0.0 && cheap >= step.max(floor).min(1.0 - s) {
                    break;
                }
                // The hulls' distance first: when the hulls are apart by
                // more than the resolution, it bounds the step (a smaller
                // step than the meshes' distance would allow, for a query
                // far cheaper); the meshes' distance only where the hulls
                // touch.
                if let Some(h) = self.hull_distance(keys[i], &poses) {
                    if h > c + resolution {
                        bound[i] = bound[i].max(h);
                        step = step.min(allowed(bound[i], rates[i]));
                        continue;
                    }
                }
                // One query, 0 for shapes that touch or overlap (meshes as
                // triangle surfaces, as the intersection test treats them);
                // no farther than what would let this item's step reach the
                // move's end.
                let enough = c + (1.0 - s) * rates[i] / STEP_SHARE;
                let d = self.item_distance(keys[i], &poses, enough);
                if d <= 0.0 || (c > 0.0 && d < c) {
                    return MoveCheck {
                        checks,
                        contact: Some((self.pair_of(keys[i]), s)),
                    };
                }
                bound[i] = d;
                step = step.min(allowed(d, rates[i]));
            }
            if s >= 1.0 {
                return MoveCheck {
                    checks,
                    contact: None,
                };
            }
            let ds = step.max(floor).max(1e-9);
            for ((cb, bd), r) in carried.iter_mut().zip(&bound).zip(&rates) {
                *cb = bd - r * ds;
            }
            s = (s + ds).min(1.0);
        }
    }

    /// For each geometry and configuration value, a bound on how far any
    /// point of the geometry can move per unit change of that value,
    /// anywhere on the straight move from `a` to `b` (0 for a value that
    /// does not carry the geometry). For a revolute joint it is the
    /// distance from its axis point to the geometry bounded by the triangle
    /// inequality down the tree — the joint origins' offsets, a prismatic
    /// joint's largest extension on the move (its rest value when not
    /// driven), the geometry's offset to its bounding sphere's centre and
    /// the sphere's radius — which holds in every configuration of the
    /// move; for a prismatic joint it is 1.
    pub(super) fn reach_bounds(&self, a: &[f64], b: &[f64]) -> Vec<Vec<f64>> {
        let tree = &self.tree;
        let mut above = vec![None; tree.links.len()];
        for (k, j) in tree.joints.iter().enumerate() {
            above[j.child] = Some(k);
        }
        let drive_of = |j: usize| self.drives.iter().position(|&d| d == j);
        let extension = |j: usize| match drive_of(j) {
            Some(k) => a[k].abs().max(b[k].abs()),
            None => self.rest[j].abs(),
        };
        self.geoms
            .iter()
            .map(|g| {
                let mut rates = vec![0.0f64; self.drives.len()];
                let mut reach = (g.origin * g.center).coords.norm() + g.radius;
                let mut link = g.link;
                while let Some(j) = above[link] {
                    let joint = &tree.joints[j];
                    if joint.motion == Motion::Prismatic {
                        reach += extension(j);
                    }
                    if let Some(k) = drive_of(j) {
                        rates[k] = match joint.motion {
                            Motion::Revolute => reach,
                            Motion::Prismatic => 1.0,
                            Motion::Fixed => 0.0,
                        };
                    }
                    reach += joint.origin.translation.vector.norm();
                    link = joint.parent;
                }
                rates
            })
            .collect()
    }

    /// How fast an item's gap can close per unit of the move whose value
    /// changes are `dq`: the rates of the joints that carry one side and
    /// not the other (an obstacle is carried by none).
    fn item_rate(&self, key: usize, reach: &[Vec<f64>], dq: &[f64]) -> f64 {
        let side = |g: usize, other: Option<usize>| -> f64 {
            (0..dq.len())
                .filter(|&k| other.is_none_or(|o| reach[o][k] == 0.0))
                .map(|k| reach[g][k] * dq[k])
                .sum()
        };
        if key < self.pairs.len() {
            let (ga, gb) = self.pairs[key];
            side(ga, Some(gb)) + side(gb, Some(ga))
        } else {
            side((key - self.pairs.len()) % self.geoms.len(), None)
        }
    }
}

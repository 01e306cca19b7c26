//! A straight joint-space move checked for contact by conservative
//! advancement.

use super::model::{CollisionModel, ContactPair};

/// What [`CollisionModel::check_move`] found on a move.
#[derive(Clone, Debug, PartialEq)]
pub struct MoveCheck {
    /// Configurations checked.
    pub checks: usize,
    /// The first contact and where on the move (0..=1) it is.
    pub contact: Option<(ContactPair, f64)>,
}

impl CollisionModel {
    /// Checks the straight joint-space move from `a` to `b` by conservative
    /// advancement. At each configuration every pair's distance is bounded
    /// from below (its bounding spheres' gap, or the bound carried from the
    /// last step less twice that step's motion), parry's exact distance is
    /// taken for the pairs near enough to limit the step, and the next step
    /// moves no point of a geometry ([`Self::sweep_rates`], halved for their
    /// first-order growth) more than a quarter of the least free distance
    /// beyond the clearance — so no two geometries can meet between checks
    /// — and near contact no more than `resolution` metres. Returns the
    /// configurations checked and the first contact (closer than the
    /// clearance) with where it is on the move (0 = `a`, 1 = `b`).
    #[must_use]
    pub fn check_move(&self, a: &[f64], b: &[f64], resolution: f64) -> MoveCheck {
        let at = |s: f64| -> Vec<f64> { a.iter().zip(b).map(|(x, y)| x + s * (y - x)).collect() };
        let keys = self.item_keys();
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
            let least = bound.iter().copied().fold(f64::INFINITY, f64::min);
            // Exact distances where a bound could limit the step.
            let limit = 2.0 * least.max(0.0) + resolution + c;
            for (i, &k) in keys.iter().enumerate() {
                if bound[i] > limit {
                    continue;
                }
                let (pa, sa, pb, sb, _) = self.item(k, &poses);
                let touching = c == 0.0
                    && parry3d_f64::query::intersection_test(&pa, sa, &pb, sb).unwrap_or(true);
                let d = if touching {
                    0.0
                } else {
                    parry3d_f64::query::distance(&pa, sa, &pb, sb).unwrap_or(0.0)
                };
                if touching || (c > 0.0 && d < c) {
                    return MoveCheck {
                        checks,
                        contact: Some((self.pair_of(k), s)),
                    };
                }
                bound[i] = d;
            }
            if s >= 1.0 {
                return MoveCheck {
                    checks,
                    contact: None,
                };
            }
            let free = bound.iter().copied().fold(f64::INFINITY, f64::min) - c;
            let speed: f64 = self
                .sweep_rates(&q)
                .iter()
                .zip(a.iter().zip(b))
                .map(|(r, (x, y))| r * (y - x).abs())
                .sum();
            // Two geometries approach by at most twice a point's motion.
            let step = 0.5 * (0.5 * free).max(resolution);
            let ds = if speed > 0.0 { step / speed } else { 1.0 };
            for (cb, bd) in carried.iter_mut().zip(&bound) {
                *cb = bd - 2.0 * step;
            }
            s = (s + ds.max(1e-9)).min(1.0);
        }
    }
}

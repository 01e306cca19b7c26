//! The least distance at a configuration: which two links (or link and
//! obstacle) of the checked pairs are closest, and how far apart.

use super::model::{CollisionModel, ContactPair};
use serde::Serialize;

/// The closest checked pair at a configuration.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Closest {
    /// The two links, or the link and the obstacle.
    pub pair: ContactPair,
    /// Their least distance, metres (0 when they touch or cross).
    pub distance: f64,
}

impl CollisionModel {
    /// The least distance over every checked item at configuration `q` (a
    /// self-collision pair of geometries, or a geometry and an obstacle)
    /// and the pair it is between; `None` when nothing is checked. Exact
    /// (the distance queries' own tolerance aside), by branch and bound:
    /// the items in increasing order of their bounding spheres' gap, each
    /// item's distance taken only while that gap is below the least found
    /// (a mesh pair's walk stopping as soon as it cannot beat it).
    #[must_use]
    pub fn closest(&self, q: &[f64]) -> Option<Closest> {
        let poses = self.geometry_poses(q);
        let mut order: Vec<(f64, usize)> = self
            .item_keys()
            .into_iter()
            .map(|k| (self.item(k, &poses).4, k))
            .collect();
        order.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let mut best: Option<(f64, usize)> = None;
        for (gap, k) in order {
            let enough = best.map_or(f64::INFINITY, |b| b.0);
            if gap >= enough {
                break;
            }
            let d = self.item_distance(k, &poses, enough);
            if d < enough {
                best = Some((d, k));
            }
        }
        best.map(|(d, k)| Closest {
            pair: self.pair_of(k),
            distance: d.max(0.0),
        })
    }

    /// Every checked item's exact distance at `q` (item keys as
    /// [`CollisionModel::contact_key`]'s): what [`CollisionModel::closest`]
    /// prunes, for tests.
    #[must_use]
    pub fn distances(&self, q: &[f64]) -> Vec<(ContactPair, f64)> {
        let poses = self.geometry_poses(q);
        self.item_keys()
            .into_iter()
            .map(|k| {
                (
                    self.pair_of(k),
                    self.item_distance(k, &poses, f64::INFINITY).max(0.0),
                )
            })
            .collect()
    }
}

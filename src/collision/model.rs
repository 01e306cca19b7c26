//! The loaded model and its queries at a configuration: the first contact
//! (closer than the clearance) and which pair it is.

use super::mesh_tree;
use super::shapes::Geometry;
use super::spec::TouchingPair;
use super::tree::Tree;
use parry3d_f64::na::Isometry3;
use parry3d_f64::shape::{Ball, SharedShape};
use serde::Serialize;

/// What two geometries at `pa`, `pb` are to each other: closer than
/// `clearance` (touching when it is 0).
pub(super) fn too_close(
    pa: &Isometry3<f64>,
    a: &dyn parry3d_f64::shape::Shape,
    pb: &Isometry3<f64>,
    b: &dyn parry3d_f64::shape::Shape,
    clearance: f64,
) -> bool {
    if clearance > 0.0 {
        parry3d_f64::query::distance(pa, a, pb, b).is_ok_and(|d| d < clearance)
    } else {
        parry3d_f64::query::intersection_test(pa, a, pb, b).unwrap_or(false)
    }
}

/// Which pair a contact is: a self-collision pair, or a link and an
/// obstacle.
#[derive(Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
pub struct ContactPair {
    /// The first link.
    pub link: String,
    /// The other link, or the obstacle (`box 1`, `floor`).
    pub other: String,
    /// Whether `other` is an obstacle.
    pub obstacle: bool,
}

/// Two placed shapes and the gap of their bounding spheres.
pub(super) type Item<'s> = (
    Isometry3<f64>,
    &'s dyn parry3d_f64::shape::Shape,
    Isometry3<f64>,
    &'s dyn parry3d_f64::shape::Shape,
    f64,
);

/// The loaded geometry, pairs and obstacles of a [`CollisionSpec`](super::CollisionSpec).
pub struct CollisionModel {
    pub(super) tree: Tree,
    pub(super) geoms: Vec<Geometry>,
    pub(super) pairs: Vec<(usize, usize)>,
    /// Obstacle shapes with their placement in the root frame.
    pub(super) obstacles: Vec<(String, Isometry3<f64>, SharedShape)>,
    /// Geometries checked against obstacles.
    pub(super) exposed: Vec<usize>,
    /// For each configuration value `k`, the tree joint it drives.
    pub(super) drives: Vec<usize>,
    /// The chain's base link (the frame of obstacles and of line-of-sight
    /// rays).
    pub(super) base: usize,
    /// Least distance kept, metres ([`CollisionSpec::clearance`](super::CollisionSpec::clearance)).
    pub(super) clearance: f64,
    /// Joint values at a zero configuration (locks applied).
    pub(super) rest: Vec<f64>,
    /// Link pairs left unchecked because they touch in nearly every
    /// configuration ([`AlwaysTouching`](super::spec::AlwaysTouching)).
    pub(super) always_touching: Vec<TouchingPair>,
}

impl std::fmt::Debug for CollisionModel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "CollisionModel({} links, {} geometries, {} pairs, {} obstacles)",
            self.tree.links.len(),
            self.geoms.len(),
            self.pairs.len(),
            self.obstacles.len()
        )
    }
}

impl CollisionModel {
    /// Every link's placement at configuration `q` (the chain's joint
    /// values over the rest configuration, locks applied).
    pub(super) fn link_placements(&self, q: &[f64]) -> Vec<Isometry3<f64>> {
        let mut values = self.rest.clone();
        for (k, &j) in self.drives.iter().enumerate() {
            if let Some(v) = q.get(k) {
                values[j] = *v;
            }
        }
        let mut links = vec![Isometry3::identity(); self.tree.links.len()];
        self.tree.placements(&values, &mut links);
        links
    }

    /// The link pairs left unchecked because they touch in nearly every
    /// sampled configuration, most often touching first (empty unless the
    /// spec asks for [`AlwaysTouching`](super::spec::AlwaysTouching)).
    #[must_use]
    pub fn always_touching(&self) -> &[TouchingPair] {
        &self.always_touching
    }

    /// Geometry pairs checked for self-collision.
    #[must_use]
    pub fn pair_count(&self) -> usize {
        self.pairs.len()
    }

    /// The first contact at configuration `q` (the chain's joint values), as
    /// the two links (or link and obstacle) that touch (closer than the
    /// spec's clearance), or `None` when the configuration is free.
    #[must_use]
    pub fn contact(&self, q: &[f64]) -> Option<(String, String)> {
        self.contact_key(q).map(|k| {
            let p = self.pair_of(k);
            (p.link, p.other)
        })
    }

    /// The first contact at `q` as a number ([`pair_of`](Self::pair_of)
    /// names it): cheap to count per candidate.
    #[must_use]
    pub fn contact_key(&self, q: &[f64]) -> Option<usize> {
        let links = self.link_placements(q);
        let poses: Vec<Isometry3<f64>> = self
            .geoms
            .iter()
            .map(|g| links[g.link] * g.origin)
            .collect();
        let c = self.clearance;
        for (k, &(a, b)) in self.pairs.iter().enumerate() {
            let (ga, gb) = (&self.geoms[a], &self.geoms[b]);
            let d = (poses[a] * ga.center - poses[b] * gb.center).norm();
            if d > ga.radius + gb.radius + c || self.hull_distance(k, &poses).is_some_and(|h| h > c)
            {
                continue;
            }
            let close = match (&ga.tree, &gb.tree) {
                // With a clearance, two meshes' distance by their trees
                // (parry's mesh–mesh distance is far slower).
                (Some(ta), Some(tb)) if c > 0.0 => {
                    mesh_tree::distance(ta, &poses[a], tb, &poses[b], c) < c
                }
                _ => too_close(
                    &poses[a],
                    ga.shape.as_ref(),
                    &poses[b],
                    gb.shape.as_ref(),
                    c,
                ),
            };
            if close {
                return Some(k);
            }
        }
        for (o, (_, opose, oshape)) in self.obstacles.iter().enumerate() {
            for &g in &self.exposed {
                let geom = &self.geoms[g];
                let key = self.pairs.len() + o * self.geoms.len() + g;
                if self.hull_distance(key, &poses).is_some_and(|h| h > c) {
                    continue;
                }
                if too_close(&poses[g], geom.shape.as_ref(), opose, oshape.as_ref(), c) {
                    return Some(key);
                }
            }
        }
        None
    }

    /// Every geometry's placement in the root frame at `q`.
    pub(super) fn geometry_poses(&self, q: &[f64]) -> Vec<Isometry3<f64>> {
        let links = self.link_placements(q);
        self.geoms
            .iter()
            .map(|g| links[g.link] * g.origin)
            .collect()
    }

    /// The checked items (geometry pairs, then geometry–obstacle pairs) as
    /// their [`contact_key`](Self::contact_key)s.
    pub(super) fn item_keys(&self) -> Vec<usize> {
        let mut keys: Vec<usize> = (0..self.pairs.len()).collect();
        for o in 0..self.obstacles.len() {
            keys.extend(
                self.exposed
                    .iter()
                    .map(|&g| self.pairs.len() + o * self.geoms.len() + g),
            );
        }
        keys
    }

    /// The placements and shapes of an item key, and a lower bound on its
    /// distance: the gap of the two bounding spheres, or of the geometry's
    /// bounding sphere and the obstacle (a distance below 0 means that the
    /// sphere overlaps it).
    pub(super) fn item<'s>(&'s self, key: usize, poses: &[Isometry3<f64>]) -> Item<'s> {
        if key < self.pairs.len() {
            let (a, b) = self.pairs[key];
            let (ga, gb) = (&self.geoms[a], &self.geoms[b]);
            let gap = (poses[a] * ga.center - poses[b] * gb.center).norm() - ga.radius - gb.radius;
            return (
                poses[a],
                ga.shape.as_ref(),
                poses[b],
                gb.shape.as_ref(),
                gap,
            );
        }
        let k = key - self.pairs.len();
        let (o, g) = (k / self.geoms.len(), k % self.geoms.len());
        let (_, opose, oshape) = &self.obstacles[o];
        let geom = &self.geoms[g];
        // The bounding sphere against the obstacle: an analytic query
        // (ball against box or half-space), far cheaper than the mesh's.
        let centre = poses[g] * geom.center;
        let gap = parry3d_f64::query::distance(
            &Isometry3::translation(centre.x, centre.y, centre.z),
            &Ball::new(geom.radius),
            opose,
            oshape.as_ref(),
        )
        .map_or(f64::NEG_INFINITY, |d| d);
        (poses[g], geom.shape.as_ref(), *opose, oshape.as_ref(), gap)
    }

    /// An item's distance (0 when its shapes touch or cross), exact below
    /// `enough` and a lower bound of at least `enough` above it: two meshes
    /// by walking their box trees together ([`mesh_tree::distance`]), any
    /// other pair by parry's query.
    pub(super) fn item_distance(&self, key: usize, poses: &[Isometry3<f64>], enough: f64) -> f64 {
        if key < self.pairs.len() {
            let (a, b) = self.pairs[key];
            if let (Some(ta), Some(tb)) = (&self.geoms[a].tree, &self.geoms[b].tree) {
                return mesh_tree::distance(ta, &poses[a], tb, &poses[b], enough);
            }
        }
        let (pa, sa, pb, sb, _) = self.item(key, poses);
        parry3d_f64::query::distance(&pa, sa, &pb, sb).unwrap_or(0.0)
    }

    /// A lower bound on an item's distance from the convex hulls of its
    /// meshes (a primitive stands for itself; an obstacle is a box or a
    /// half-space): `None` when neither side has a hull, where the bound
    /// would be the exact distance.
    pub(super) fn hull_distance(&self, key: usize, poses: &[Isometry3<f64>]) -> Option<f64> {
        let own = |g: usize| {
            let geom = &self.geoms[g];
            geom.hull
                .as_ref()
                .map_or(geom.shape.as_ref(), |h| h.as_ref())
        };
        if key < self.pairs.len() {
            let (a, b) = self.pairs[key];
            if self.geoms[a].hull.is_none() && self.geoms[b].hull.is_none() {
                return None;
            }
            return parry3d_f64::query::distance(&poses[a], own(a), &poses[b], own(b)).ok();
        }
        let k = key - self.pairs.len();
        let (o, g) = (k / self.geoms.len(), k % self.geoms.len());
        self.geoms[g].hull.as_ref()?;
        let (_, opose, oshape) = &self.obstacles[o];
        parry3d_f64::query::distance(&poses[g], own(g), opose, oshape.as_ref()).ok()
    }

    /// The links (or link and obstacle) of a [`contact_key`](Self::contact_key).
    #[must_use]
    pub fn pair_of(&self, key: usize) -> ContactPair {
        let name = |g: usize| self.tree.links[self.geoms[g].link].clone();
        if key < self.pairs.len() {
            let (a, b) = self.pairs[key];
            let (x, y) = (name(a), name(b));
            let (link, other) = if x <= y { (x, y) } else { (y, x) };
            return ContactPair {
                link,
                other,
                obstacle: false,
            };
        }
        let k = key - self.pairs.len();
        let (o, g) = (k / self.geoms.len(), k % self.geoms.len());
        ContactPair {
            link: name(g),
            other: self.obstacles[o].0.clone(),
            obstacle: true,
        }
    }
}

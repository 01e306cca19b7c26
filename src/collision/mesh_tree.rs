//! The distance between two triangle meshes by a best-first walk of both
//! meshes' box trees at once.
//!
//! parry's distance between two `TriMesh`es walks the first mesh's tree
//! and, for every triangle it cannot prune, queries the whole second mesh;
//! its pruning compares the first mesh's boxes with the second mesh's
//! *whole* box, so two meshes a few millimetres apart (a wrist folded over
//! the base) cost 0.1–0.3 s a query — nearly all of `select`'s time on a
//! meshed arm. This walk pairs the two trees' nodes (the bounding-volume
//! test tree), visits the pair with the least lower bound first and stops
//! when no pair left can beat the best triangle pair found (or the caller's
//! `enough`), so near meshes cost a few hundred triangle pairs.
//!
//! A node's bound in the other mesh's frame is its box turned and then boxed
//! again (larger, so the distance between boxes stays a lower bound); the
//! triangle pairs' distances are parry's (GJK on two triangles, 0 when they
//! touch or cross).

use parry3d_f64::na::{Isometry3, Matrix3, Point3, Vector3};
use parry3d_f64::shape::Triangle;
use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// Triangles per leaf: a leaf pair costs up to its square of triangle
/// distances, a smaller leaf more nodes.
const LEAF: usize = 4;

/// A node of a [`MeshTree`]: an axis-aligned box and either two children
/// or a run of triangles.
#[derive(Clone, Debug)]
struct Node {
    center: Point3<f64>,
    half: Vector3<f64>,
    /// A leaf's first triangle and count, or an inner node's children.
    kind: Kind,
}

#[derive(Clone, Copy, Debug)]
enum Kind {
    Leaf { first: usize, count: usize },
    Inner { left: usize, right: usize },
}

/// A mesh's triangles (in the mesh's frame) ordered along a binary tree of
/// boxes, for [`distance`].
#[derive(Clone, Debug)]
pub struct MeshTree {
    nodes: Vec<Node>,
    triangles: Vec<Triangle>,
    /// Each triangle's bounding sphere: centroid and radius.
    spheres: Vec<(Point3<f64>, f64)>,
}

impl MeshTree {
    /// The tree of `triangles` (at least one): split at the median centroid
    /// along the longest side of the centroids' box until a node holds at
    /// most [`LEAF`] triangles.
    #[must_use]
    pub fn new(mut triangles: Vec<Triangle>) -> Self {
        let mut nodes = Vec::with_capacity(2 * triangles.len().div_ceil(LEAF));
        let n = triangles.len();
        build(&mut triangles, 0, n, &mut nodes);
        let spheres = triangles
            .iter()
            .map(|t| {
                let c = Point3::from((t.a.coords + t.b.coords + t.c.coords) / 3.0);
                let r = [t.a, t.b, t.c]
                    .iter()
                    .map(|v| (v - c).norm())
                    .fold(0.0, f64::max);
                (c, r)
            })
            .collect();
        Self {
            nodes,
            triangles,
            spheres,
        }
    }

    /// Whether the tree holds no triangle.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.triangles.is_empty()
    }
}

/// The box of some points: centre and half extents.
fn boxed<'a>(points: impl Iterator<Item = &'a Point3<f64>>) -> (Point3<f64>, Vector3<f64>) {
    let mut lo = Vector3::repeat(f64::INFINITY);
    let mut hi = Vector3::repeat(f64::NEG_INFINITY);
    for p in points {
        lo = lo.inf(&p.coords);
        hi = hi.sup(&p.coords);
    }
    (Point3::from((lo + hi) / 2.0), (hi - lo) / 2.0)
}

/// Builds the node of `tris[start..end]` and its subtree; returns its index.
fn build(tris: &mut [Triangle], start: usize, end: usize, nodes: &mut Vec<Node>) -> usize {
    let (center, half) = boxed(tris[start..end].iter().flat_map(|t| [&t.a, &t.b, &t.c]));
    let at = nodes.len();
    nodes.push(Node {
        center,
        half,
        kind: Kind::Leaf {
            first: start,
            count: end - start,
        },
    });
    if end - start <= LEAF {
        return at;
    }
    let centroid = |t: &Triangle| (t.a.coords + t.b.coords + t.c.coords) / 3.0;
    let (_, spread) = boxed(
        tris[start..end]
            .iter()
            .map(|t| Point3::from(centroid(t)))
            .collect::<Vec<_>>()
            .iter(),
    );
    let axis = spread.imax();
    let mid = (end - start) / 2;
    tris[start..end]
        .select_nth_unstable_by(mid, |x, y| centroid(x)[axis].total_cmp(&centroid(y)[axis]));
    let left = build(tris, start, start + mid, nodes);
    let right = build(tris, start + mid, end, nodes);
    nodes[at].kind = Kind::Inner { left, right };
    at
}

/// A pair of nodes waiting in the walk, least lower bound first.
#[derive(PartialEq)]
struct Pending(f64, usize, usize);

impl Eq for Pending {}

impl PartialOrd for Pending {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Pending {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.0.total_cmp(&other.0)
    }
}

/// `b` placed in `a`'s frame: the pose, its inverse and the turn's
/// entries' magnitudes (to box a turned box).
struct Relative {
    pose: Isometry3<f64>,
    inverse: Isometry3<f64>,
    abs: Matrix3<f64>,
}

impl Relative {
    /// `b`'s placement in `a`'s frame.
    fn new(pose: Isometry3<f64>) -> Self {
        Self {
            abs: pose.rotation.to_rotation_matrix().matrix().abs(),
            inverse: pose.inverse(),
            pose,
        }
    }

    /// A lower bound on the distance between `a`'s node and `b`'s: the
    /// larger of two box gaps, each node's box against the box around the
    /// other's turned box (in the first node's frame, then the second's).
    fn gap(&self, a: &Node, b: &Node) -> f64 {
        let in_a = (self.pose * b.center - a.center).abs() - a.half - self.abs * b.half;
        let in_b = (self.inverse * a.center - b.center).abs() - b.half - self.abs.tr_mul(&a.half);
        let zero = Vector3::zeros();
        in_a.sup(&zero).norm().max(in_b.sup(&zero).norm())
    }
}

/// The least distance between `a` placed at `pa` and `b` at `pb` (0 when
/// they touch or cross), exact up to `enough`; above it the walk may stop
/// early and the value returned is a lower bound greater than `enough`
/// (pass `f64::INFINITY` for the exact distance, 0 to learn only whether
/// they touch).
#[must_use]
pub fn distance(
    a: &MeshTree,
    pa: &Isometry3<f64>,
    b: &MeshTree,
    pb: &Isometry3<f64>,
    enough: f64,
) -> f64 {
    if a.is_empty() || b.is_empty() {
        return f64::INFINITY;
    }
    let rel = Relative::new(pa.inv_mul(pb));
    let mut best = f64::INFINITY;
    let mut heap = BinaryHeap::new();
    heap.push(Reverse(Pending(rel.gap(&a.nodes[0], &b.nodes[0]), 0, 0)));
    while let Some(Reverse(Pending(bound, i, j))) = heap.pop() {
        if bound >= best || bound > enough {
            return best.min(bound);
        }
        let (na, nb) = (&a.nodes[i], &b.nodes[j]);
        match (na.kind, nb.kind) {
            (
                Kind::Leaf {
                    first: fa,
                    count: ca,
                },
                Kind::Leaf {
                    first: fb,
                    count: cb,
                },
            ) => {
                best = leaf_distance(a, fa..fa + ca, b, fb..fb + cb, &rel.pose, best);
                if best <= 0.0 {
                    return 0.0;
                }
            }
            (Kind::Inner { left, right }, Kind::Leaf { .. }) => {
                for c in [left, right] {
                    heap.push(Reverse(Pending(rel.gap(&a.nodes[c], nb), c, j)));
                }
            }
            (Kind::Leaf { .. }, Kind::Inner { left, right }) => {
                for c in [left, right] {
                    heap.push(Reverse(Pending(rel.gap(na, &b.nodes[c]), i, c)));
                }
            }
            (
                Kind::Inner {
                    left: al,
                    right: ar,
                },
                Kind::Inner {
                    left: bl,
                    right: br,
                },
            ) => {
                // Split the larger box: the bounds tighten fastest.
                if na.half.norm_squared() >= nb.half.norm_squared() {
                    for c in [al, ar] {
                        heap.push(Reverse(Pending(rel.gap(&a.nodes[c], nb), c, j)));
                    }
                } else {
                    for c in [bl, br] {
                        heap.push(Reverse(Pending(rel.gap(na, &b.nodes[c]), i, c)));
                    }
                }
            }
        }
    }
    best
}

/// The least of `best` and the distances between `a`'s triangles `ra` and
/// `b`'s `rb`, `b` placed by `pose` in `a`'s frame: a pair whose bounding
/// spheres are `best` or more apart is skipped.
fn leaf_distance(
    a: &MeshTree,
    ra: std::ops::Range<usize>,
    b: &MeshTree,
    rb: std::ops::Range<usize>,
    pose: &Isometry3<f64>,
    mut best: f64,
) -> f64 {
    let id = Isometry3::identity();
    for j in rb {
        let tb = &b.triangles[j];
        let (cb, rad_b) = b.spheres[j];
        let cb = pose * cb;
        let mut placed = None;
        for i in ra.clone() {
            let (ca, rad_a) = a.spheres[i];
            if (ca - cb).norm() - rad_a - rad_b >= best {
                continue;
            }
            let tb =
                placed.get_or_insert_with(|| Triangle::new(pose * tb.a, pose * tb.b, pose * tb.c));
            let d = parry3d_f64::query::distance(&id, &a.triangles[i], &id, &*tb).unwrap_or(0.0);
            best = best.min(d);
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use parry3d_f64::shape::TriMesh;

    /// A fixture mesh as a parry mesh and a tree.
    fn mesh(name: &str) -> (TriMesh, MeshTree) {
        let path = format!(
            "{}/fixtures/example-robot-data/robots/panda_description/meshes/collision/{name}.stl",
            env!("CARGO_MANIFEST_DIR")
        );
        let tris = crate::collision::mesh::load(std::path::Path::new(&path)).unwrap();
        let vertices: Vec<Point3<f64>> = tris
            .iter()
            .flat_map(|t| t.iter().map(|v| Point3::new(v[0], v[1], v[2])))
            .collect();
        let indices = (0..tris.len() as u32)
            .map(|k| [3 * k, 3 * k + 1, 3 * k + 2])
            .collect();
        let m = TriMesh::new(vertices, indices).unwrap();
        let tree = MeshTree::new(m.triangles().collect());
        (m, tree)
    }

    /// Placements of the second mesh near the first: turned about a
    /// skewed axis and shifted so that the meshes go from crossing to tens
    /// of centimetres apart.
    fn placements() -> Vec<Isometry3<f64>> {
        (0..24)
            .map(|k| {
                let t = f64::from(k);
                Isometry3::new(
                    Vector3::new(0.02 * t - 0.1, 0.05 * (0.7 * t).sin(), 0.004 * t),
                    Vector3::new(0.3, -0.5, 0.8) * (0.37 * t),
                )
            })
            .collect()
    }

    /// Equal to parry's own mesh–mesh distance (both are GJK on the same
    /// triangle pairs, so the minimum is the same number up to rounding in
    /// the placement of `b`'s vertices: 1e-12 m), crossing placements 0 in
    /// both.
    #[test]
    fn equals_parrys_distance() {
        let (ma, ta) = mesh("link3");
        let (mb, tb) = mesh("link5");
        let pa = Isometry3::new(Vector3::new(0.01, 0.0, 0.02), Vector3::new(0.1, 0.2, 0.0));
        let mut touching = 0;
        for pb in placements() {
            let want = parry3d_f64::query::distance(&pa, &ma, &pb, &mb).unwrap();
            let got = distance(&ta, &pa, &tb, &pb, f64::INFINITY);
            assert!((got - want).abs() < 1e-12, "{got} vs parry {want}");
            touching += usize::from(want == 0.0);
        }
        // Both kinds of placement are exercised.
        assert!(touching > 0 && touching < 24, "{touching} of 24 touch");
    }

    /// With `enough`, a distance up to it is exact and one above it is
    /// reported as a lower bound greater than `enough` (never above the
    /// truth); with `enough` 0, meshes apart are never reported touching.
    #[test]
    fn enough_bounds_from_below() {
        let (_, ta) = mesh("link3");
        let (_, tb) = mesh("link5");
        let pa = Isometry3::identity();
        let (mut exact_seen, mut bounded_seen) = (0, 0);
        for pb in placements() {
            let exact = distance(&ta, &pa, &tb, &pb, f64::INFINITY);
            for enough in [0.0, 0.03] {
                let got = distance(&ta, &pa, &tb, &pb, enough);
                if exact <= enough {
                    assert_eq!(got, exact);
                    exact_seen += 1;
                } else {
                    assert!(got > enough && got <= exact, "{got} vs {exact}");
                    bounded_seen += usize::from(got < exact);
                }
            }
        }
        assert!(
            exact_seen > 0 && bounded_seen > 0,
            "{exact_seen} {bounded_seen}"
        );
    }
}

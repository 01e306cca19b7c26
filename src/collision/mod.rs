//! Self-collision and obstacles: the pool filter that removes the poses a
//! real arm cannot take.
//!
//! A [`CollisionModel`] is read from a URDF's `<collision>` elements (boxes,
//! cylinders, spheres, capsules and STL meshes, the meshes found through
//! `package://` or a path relative to the URDF, [`stl`]) on every link of
//! the tree — gripper fingers and other links outside the measured chain
//! included, at joint value 0 (locked joints at their lock value). Placements
//! come from the URDF's own joint origins and axes ([`tree`]). Meshes are
//! triangle surfaces, as Coal (hpp-fcl) treats them for Pinocchio, so the two
//! agree on what touches; the queries are `parry3d`'s (the nalgebra authors'
//! collision library), after a bounding-sphere test per pair.
//!
//! Pairs checked: every two geometries on different rigid bodies (links
//! joined by fixed joints are one body) that are not adjacent (bodies joined
//! by one joint touch by design) and not listed in an SRDF's
//! `disable_collisions` ([`srdf`]). Obstacles — boxes and a floor plane in
//! the frame of the chain's base link — are checked against every geometry
//! not on the base's rigid body.
//!
//! The filter ([`CollisionFilter`]) stores only its [`CollisionSpec`] (paths
//! and numbers; a design file keeps it) and loads the model once per
//! process, on first use or in [`CollisionFilter::load`], which pool
//! building calls before any candidate is checked.

pub mod mesh;
pub mod srdf;
pub mod stl;
mod tree;

use parry3d_f64::na::{Isometry3, Point3, Vector3};
use parry3d_f64::shape::{Ball, Capsule, Cuboid, Cylinder, HalfSpace, SharedShape, TriMesh};
use serde::{Deserialize, Serialize};
use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::sync::{Arc, OnceLock};
use tree::{Motion, Tree};

/// An obstacle in the base link's frame (metres).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", tag = "kind")]
pub enum Obstacle {
    /// An axis-aligned box: centre and full sizes.
    Box {
        /// Centre.
        center: [f64; 3],
        /// Full sizes along x, y, z (> 0).
        size: [f64; 3],
    },
}

impl Obstacle {
    /// Parses `box:cx,cy,cz,sx,sy,sz` (centre and full sizes, metres).
    pub fn parse(text: &str) -> Result<Obstacle, String> {
        let Some(rest) = text.strip_prefix("box:") else {
            return Err(format!(
                "obstacle '{text}': expected box:cx,cy,cz,sx,sy,sz (centre and full sizes in metres, base frame)"
            ));
        };
        let v: Vec<f64> = rest
            .split(',')
            .map(|s| s.trim().parse::<f64>())
            .collect::<Result<_, _>>()
            .map_err(|e| format!("obstacle '{text}': {e}"))?;
        if v.len() != 6 {
            return Err(format!(
                "obstacle '{text}': {} numbers, expected 6 (cx,cy,cz,sx,sy,sz)",
                v.len()
            ));
        }
        if let Some(x) = v.iter().find(|x| !x.is_finite()) {
            return Err(format!("obstacle '{text}': {x} is not finite"));
        }
        if let Some(s) = v[3..].iter().find(|s| **s <= 0.0) {
            return Err(format!("obstacle '{text}': size {s} must be > 0"));
        }
        Ok(Obstacle::Box {
            center: [v[0], v[1], v[2]],
            size: [v[3], v[4], v[5]],
        })
    }
}

/// What a collision filter checks, as stored in a pool spec.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct CollisionSpec {
    /// The URDF file.
    pub urdf: String,
    /// The URDF's text as the robot was imported from it, so that the file
    /// is read once per process; read from `urdf` when absent (a pool spec
    /// loaded from a design file).
    #[serde(skip)]
    pub text: Option<std::sync::Arc<str>>,
    /// The chain's moving joints, in the order of a configuration's values.
    pub joints: Vec<String>,
    /// Joints held at a value (`--lock`).
    #[serde(default)]
    pub lock: Vec<(String, f64)>,
    /// The frame of obstacles: the chain's base link (default: the root).
    #[serde(default)]
    pub base: Option<String>,
    /// Check the links against each other.
    #[serde(default)]
    pub self_collision: bool,
    /// SRDF whose `disable_collisions` pairs are not checked.
    #[serde(default)]
    pub srdf: Option<String>,
    /// Directories searched for `package://` meshes.
    #[serde(default)]
    pub package_dirs: Vec<String>,
    /// Boxes in the base frame.
    #[serde(default)]
    pub obstacles: Vec<Obstacle>,
    /// A floor: the half-space `z < floor` of the base frame.
    #[serde(default)]
    pub floor: Option<f64>,
    /// Least distance kept between checked geometries (and to obstacles),
    /// metres: a configuration closer than this counts as a contact. 0:
    /// touching only.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub clearance: f64,
}

#[allow(clippy::trivially_copy_pass_by_ref)]
fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

/// What two geometries at `pa`, `pb` are to each other: closer than
/// `clearance` (touching when it is 0).
fn too_close(
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
type Item<'s> = (
    Isometry3<f64>,
    &'s dyn parry3d_f64::shape::Shape,
    Isometry3<f64>,
    &'s dyn parry3d_f64::shape::Shape,
    f64,
);

/// What [`CollisionModel::check_move`] found on a move.
#[derive(Clone, Debug, PartialEq)]
pub struct MoveCheck {
    /// Configurations checked.
    pub checks: usize,
    /// The first contact and where on the move (0..=1) it is.
    pub contact: Option<(ContactPair, f64)>,
}

/// One collision geometry on a link.
struct Geometry {
    link: usize,
    /// Placement in the link frame.
    origin: Isometry3<f64>,
    shape: SharedShape,
    /// Bounding sphere in the geometry frame: centre and radius.
    center: Point3<f64>,
    radius: f64,
}

/// The loaded geometry, pairs and obstacles of a [`CollisionSpec`].
pub struct CollisionModel {
    tree: Tree,
    geoms: Vec<Geometry>,
    pairs: Vec<(usize, usize)>,
    /// Obstacle shapes with their placement in the root frame.
    obstacles: Vec<(String, Isometry3<f64>, SharedShape)>,
    /// Geometries checked against obstacles.
    exposed: Vec<usize>,
    /// For each configuration value `k`, the tree joint it drives.
    drives: Vec<usize>,
    /// Least distance kept, metres ([`CollisionSpec::clearance`]).
    clearance: f64,
    /// Joint values at a zero configuration (locks applied).
    rest: Vec<f64>,
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

/// Where a `package://PKG/rest` or relative mesh file is: the package
/// directories given, then the URDF's directory and its ancestors (a
/// directory named PKG, or one holding PKG).
fn resolve(file: &str, urdf_dir: &Path, package_dirs: &[String]) -> Option<PathBuf> {
    if let Some(rest) = file.strip_prefix("package://") {
        let (pkg, sub) = rest.split_once('/').unwrap_or((rest, ""));
        let mut roots: Vec<PathBuf> = package_dirs.iter().map(PathBuf::from).collect();
        roots.extend(urdf_dir.ancestors().map(Path::to_path_buf));
        for r in roots {
            for cand in [r.join(pkg).join(sub), r.join(sub)] {
                let named = r.file_name().is_some_and(|n| n == pkg);
                if (named || cand.starts_with(r.join(pkg))) && cand.is_file() {
                    return Some(cand);
                }
            }
        }
        return None;
    }
    let p = file.strip_prefix("file://").unwrap_or(file);
    let p = if Path::new(p).is_absolute() {
        PathBuf::from(p)
    } else {
        urdf_dir.join(p)
    };
    p.is_file().then_some(p)
}

fn shape_of(
    g: &urdf_rs::Geometry,
    link: &str,
    urdf_dir: &Path,
    spec: &CollisionSpec,
) -> Result<SharedShape, String> {
    let positive = |what: &str, v: f64| -> Result<f64, String> {
        if v.is_finite() && v > 0.0 {
            Ok(v)
        } else {
            Err(format!(
                "link '{link}': collision {what} {v} must be finite and > 0"
            ))
        }
    };
    Ok(match g {
        urdf_rs::Geometry::Box { size } => SharedShape::new(Cuboid::new(Vector3::new(
            positive("box size", size[0])? / 2.0,
            positive("box size", size[1])? / 2.0,
            positive("box size", size[2])? / 2.0,
        ))),
        urdf_rs::Geometry::Sphere { radius } => {
            SharedShape::new(Ball::new(positive("sphere radius", *radius)?))
        }
        // URDF cylinders and capsules run along z; parry's along y.
        urdf_rs::Geometry::Cylinder { radius, length } => SharedShape::new(Cylinder::new(
            positive("cylinder length", *length)? / 2.0,
            positive("cylinder radius", *radius)?,
        )),
        urdf_rs::Geometry::Capsule { radius, length } => SharedShape::new(Capsule::new_z(
            positive("capsule length", *length)? / 2.0,
            positive("capsule radius", *radius)?,
        )),
        urdf_rs::Geometry::Mesh { filename, scale } => {
            let path = resolve(filename, urdf_dir, &spec.package_dirs).ok_or_else(|| {
                format!(
                    "link '{link}': mesh '{filename}' not found (searched {}the URDF's directory {} and its ancestors; name the package directory that holds it)",
                    spec.package_dirs.iter().map(|d| format!("{d}, ")).collect::<String>(),
                    if urdf_dir.as_os_str().is_empty() {
                        Path::new(".").display()
                    } else {
                        urdf_dir.display()
                    }
                )
            })?;
            let tris = mesh::load(&path).map_err(|e| format!("link '{link}': {e}"))?;
            let s = scale.as_ref().map_or([1.0; 3], |v| [v[0], v[1], v[2]]);
            let mut vertices = Vec::with_capacity(3 * tris.len());
            for t in &tris {
                for v in t {
                    vertices.push(Point3::new(v[0] * s[0], v[1] * s[1], v[2] * s[2]));
                }
            }
            let indices = (0..tris.len() as u32)
                .map(|k| [3 * k, 3 * k + 1, 3 * k + 2])
                .collect();
            SharedShape::new(
                TriMesh::new(vertices, indices).map_err(|e| {
                    format!("{}: not a usable triangle mesh: {e:?}", path.display())
                })?,
            )
        }
    })
}

/// Every collision element of every link, with its shape loaded (meshes
/// found beside the URDF or in the package directories) and its bounding
/// sphere.
fn geometries(
    urdf: &urdf_rs::Robot,
    tree: &Tree,
    spec: &CollisionSpec,
) -> Result<Vec<Geometry>, String> {
    let urdf_dir = Path::new(&spec.urdf).parent().unwrap_or(Path::new("."));
    let mut geoms = Vec::new();
    for l in &urdf.links {
        let link = tree.index[&l.name];
        for c in &l.collision {
            let shape = shape_of(&c.geometry, &l.name, urdf_dir, spec)
                .map_err(|e| format!("{}: {e}", spec.urdf))?;
            let aabb = shape.compute_local_aabb();
            let center = aabb.center();
            let radius = aabb.half_extents().norm();
            geoms.push(Geometry {
                link,
                origin: tree::pose(&c.origin),
                shape,
                center,
                radius,
            });
        }
    }
    Ok(geoms)
}

/// The SRDF's `disable_collisions` pairs, as link indices (smaller first).
fn disabled_pairs(tree: &Tree, spec: &CollisionSpec) -> Result<HashSet<(usize, usize)>, String> {
    let mut disabled: HashSet<(usize, usize)> = HashSet::new();
    if let Some(s) = &spec.srdf {
        let t = std::fs::read_to_string(s).map_err(|e| format!("SRDF file {s}: {e}"))?;
        for p in srdf::disabled_pairs(&t, s)? {
            let find = |name: &str| {
                tree.index.get(name).copied().ok_or_else(|| {
                    format!(
                        "{s}:{}: disable_collisions names link '{name}', which {} does not have",
                        p.line, spec.urdf
                    )
                })
            };
            let (a, b) = (find(&p.link1)?, find(&p.link2)?);
            disabled.insert((a.min(b), a.max(b)));
        }
    }
    Ok(disabled)
}

/// The geometry pairs checked for self-collision: on different, not
/// adjacent bodies, and not disabled.
fn checked_pairs(
    tree: &Tree,
    geoms: &[Geometry],
    disabled: &HashSet<(usize, usize)>,
) -> Vec<(usize, usize)> {
    let mut pairs = Vec::new();
    {
        for a in 0..geoms.len() {
            for b in a + 1..geoms.len() {
                let (la, lb) = (geoms[a].link, geoms[b].link);
                let (ba, bb) = (tree.body[la], tree.body[lb]);
                if ba == bb
                    || tree.adjacent_bodies(ba, bb)
                    || disabled.contains(&(la.min(lb), la.max(lb)))
                {
                    continue;
                }
                pairs.push((a, b));
            }
        }
    }
    pairs
}

/// The boxes and the floor, placed in the base link's frame `base_pose`.
fn obstacles(
    spec: &CollisionSpec,
    base_pose: &Isometry3<f64>,
) -> Result<Vec<(String, Isometry3<f64>, SharedShape)>, String> {
    let base_pose = *base_pose;
    let mut obstacles = Vec::new();
    for (k, o) in spec.obstacles.iter().enumerate() {
        let Obstacle::Box { center, size } = o;
        if size.iter().any(|s| !(s.is_finite() && *s > 0.0))
            || center.iter().any(|c| !c.is_finite())
        {
            return Err(format!(
                "obstacle {}: needs a finite centre and sizes > 0",
                k + 1
            ));
        }
        obstacles.push((
            format!("box {}", k + 1),
            base_pose * Isometry3::translation(center[0], center[1], center[2]),
            SharedShape::new(Cuboid::new(Vector3::new(
                size[0] / 2.0,
                size[1] / 2.0,
                size[2] / 2.0,
            ))),
        ));
    }
    if let Some(z) = spec.floor {
        if !z.is_finite() {
            return Err(format!("floor height {z}: not finite"));
        }
        obstacles.push((
            "floor".to_string(),
            base_pose * Isometry3::translation(0.0, 0.0, z),
            SharedShape::new(HalfSpace::new(Vector3::z_axis())),
        ));
    }
    Ok(obstacles)
}

impl CollisionModel {
    /// Loads the model of `spec`: errors name the URDF, a missing or broken
    /// mesh file and its link, an SRDF line naming an unknown link, a chain
    /// joint or lock the URDF does not have.
    pub fn load(spec: &CollisionSpec) -> Result<CollisionModel, String> {
        let urdf_path = Path::new(&spec.urdf);
        let text = match &spec.text {
            Some(t) => t.to_string(),
            None => {
                std::fs::read_to_string(urdf_path).map_err(|e| format!("{}: {e}", spec.urdf))?
            }
        };
        let urdf = urdf_rs::read_from_string(&text)
            .map_err(|e| format!("{}: not a valid URDF: {e}", spec.urdf))?;
        let tree = Tree::new(&urdf).map_err(|e| format!("{}: {e}", spec.urdf))?;
        let joint_index = |name: &str| tree.joints.iter().position(|j| j.name == name);
        let drives = spec
            .joints
            .iter()
            .map(|n| joint_index(n).ok_or_else(|| format!("{}: no joint '{n}'", spec.urdf)))
            .collect::<Result<Vec<_>, _>>()?;
        let mut rest = vec![0.0; tree.joints.len()];
        for (n, v) in &spec.lock {
            let k =
                joint_index(n).ok_or_else(|| format!("{}: no joint '{n}' to lock", spec.urdf))?;
            rest[k] = *v;
        }
        let geoms = geometries(&urdf, &tree, spec)?;
        let pairs = if spec.self_collision {
            let disabled = disabled_pairs(&tree, spec)?;
            checked_pairs(&tree, &geoms, &disabled)
        } else {
            Vec::new()
        };
        // Obstacles live in the base link's frame; placements are in the root's.
        let base = match &spec.base {
            Some(b) => *tree
                .index
                .get(b)
                .ok_or_else(|| format!("{}: no link '{b}'", spec.urdf))?,
            None => tree.root,
        };
        let mut at_rest = vec![Isometry3::identity(); tree.links.len()];
        tree.placements(&rest, &mut at_rest);
        // The base link's placement moves only if a joint above it moves;
        // obstacles are fixed to it at the rest configuration of the joints
        // above the chain (locks applied).
        let obstacles = obstacles(spec, &at_rest[base])?;
        // The half-space's normal points out of the solid: z < floor is
        // inside when the normal is +z.
        let base_body = tree.body[base];
        let exposed = (0..geoms.len())
            .filter(|&g| tree.body[geoms[g].link] != base_body)
            .collect();
        if !(spec.clearance.is_finite() && spec.clearance >= 0.0) {
            return Err(format!(
                "a clearance of {} m: it must be a finite distance >= 0",
                spec.clearance
            ));
        }
        Ok(CollisionModel {
            tree,
            geoms,
            pairs,
            obstacles,
            exposed,
            drives,
            clearance: spec.clearance,
            rest,
        })
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
        let mut values = self.rest.clone();
        for (k, &j) in self.drives.iter().enumerate() {
            if let Some(v) = q.get(k) {
                values[j] = *v;
            }
        }
        let mut links = vec![Isometry3::identity(); self.tree.links.len()];
        self.tree.placements(&values, &mut links);
        let poses: Vec<Isometry3<f64>> = self
            .geoms
            .iter()
            .map(|g| links[g.link] * g.origin)
            .collect();
        let c = self.clearance;
        for (k, &(a, b)) in self.pairs.iter().enumerate() {
            let (ga, gb) = (&self.geoms[a], &self.geoms[b]);
            let d = (poses[a] * ga.center - poses[b] * gb.center).norm();
            if d > ga.radius + gb.radius + c {
                continue;
            }
            if too_close(
                &poses[a],
                ga.shape.as_ref(),
                &poses[b],
                gb.shape.as_ref(),
                c,
            ) {
                return Some(k);
            }
        }
        for (o, (_, opose, oshape)) in self.obstacles.iter().enumerate() {
            for &g in &self.exposed {
                let geom = &self.geoms[g];
                if too_close(&poses[g], geom.shape.as_ref(), opose, oshape.as_ref(), c) {
                    return Some(self.pairs.len() + o * self.geoms.len() + g);
                }
            }
        }
        None
    }

    /// How far any point of a checked geometry can move per unit change of
    /// each configuration value at `q`, metres per radian (or per metre):
    /// for a revolute joint the largest distance from its axis point of a
    /// geometry it carries (`|centre − axis point| + radius`, which bounds
    /// the distance to the axis), for a prismatic joint 1, for a value
    /// that moves no geometry 0.
    #[must_use]
    pub fn sweep_rates(&self, q: &[f64]) -> Vec<f64> {
        let mut values = self.rest.clone();
        for (k, &j) in self.drives.iter().enumerate() {
            if let Some(v) = q.get(k) {
                values[j] = *v;
            }
        }
        let mut links = vec![Isometry3::identity(); self.tree.links.len()];
        self.tree.placements(&values, &mut links);
        // The tree joint above each link (None at the root).
        let mut above = vec![None; self.tree.links.len()];
        for (k, j) in self.tree.joints.iter().enumerate() {
            above[j.child] = Some(k);
        }
        let mut rates = vec![0.0f64; self.drives.len()];
        for g in &self.geoms {
            let centre = links[g.link] * g.origin * g.center;
            let mut link = g.link;
            while let Some(j) = above[link] {
                let joint = &self.tree.joints[j];
                if let Some(k) = self.drives.iter().position(|&d| d == j) {
                    let r = match joint.motion {
                        Motion::Prismatic => 1.0,
                        Motion::Fixed => 0.0,
                        Motion::Revolute => {
                            let axis_point =
                                (links[joint.parent] * joint.origin).translation.vector;
                            (centre.coords - axis_point).norm() + g.radius
                        }
                    };
                    rates[k] = rates[k].max(r);
                }
                link = joint.parent;
            }
        }
        rates
    }

    /// Every geometry's placement in the root frame at `q`.
    fn geometry_poses(&self, q: &[f64]) -> Vec<Isometry3<f64>> {
        let mut values = self.rest.clone();
        for (k, &j) in self.drives.iter().enumerate() {
            if let Some(v) = q.get(k) {
                values[j] = *v;
            }
        }
        let mut links = vec![Isometry3::identity(); self.tree.links.len()];
        self.tree.placements(&values, &mut links);
        self.geoms
            .iter()
            .map(|g| links[g.link] * g.origin)
            .collect()
    }

    /// The checked items (geometry pairs, then geometry–obstacle pairs) as
    /// their [`contact_key`](Self::contact_key)s.
    fn item_keys(&self) -> Vec<usize> {
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

    /// The placements and shapes of an item key, and the gap of its
    /// bounding spheres (−∞ against an obstacle, which has none).
    fn item<'s>(&'s self, key: usize, poses: &[Isometry3<f64>]) -> Item<'s> {
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
        (
            poses[g],
            self.geoms[g].shape.as_ref(),
            *opose,
            oshape.as_ref(),
            f64::NEG_INFINITY,
        )
    }

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

/// The pool filter: a [`CollisionSpec`] and its model, loaded once.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct CollisionFilter {
    /// What is checked.
    #[serde(flatten)]
    pub spec: CollisionSpec,
    #[serde(skip)]
    model: Arc<OnceLock<Result<Arc<CollisionModel>, String>>>,
}

impl CollisionFilter {
    /// A filter for `spec` (nothing loaded yet).
    #[must_use]
    pub fn new(spec: CollisionSpec) -> Self {
        Self {
            spec,
            model: Arc::default(),
        }
    }

    /// The loaded model (loading it on first call), or the load error.
    pub fn load(&self) -> Result<Arc<CollisionModel>, String> {
        self.model
            .get_or_init(|| CollisionModel::load(&self.spec).map(Arc::new))
            .clone()
    }

    /// As [`CollisionFilter::load`], taking the URDF's text from `source`
    /// (a file's path and the text a robot was imported from) when the spec
    /// holds none and names the same file: the file is not read again.
    pub fn load_sharing(
        &self,
        source: Option<(&str, &str)>,
    ) -> Result<Arc<CollisionModel>, String> {
        self.model
            .get_or_init(|| {
                let shared = source.filter(|(path, _)| *path == self.spec.urdf);
                match (&self.spec.text, shared) {
                    (None, Some((_, text))) => CollisionModel::load(&CollisionSpec {
                        text: Some(text.into()),
                        ..self.spec.clone()
                    }),
                    _ => CollisionModel::load(&self.spec),
                }
                .map(Arc::new)
            })
            .clone()
    }

    /// Whether `q` is free; `false` when the model cannot be loaded (pool
    /// building loads it first and reports the error).
    #[must_use]
    pub fn keeps(&self, q: &[f64]) -> bool {
        self.load().is_ok_and(|m| m.contact_key(q).is_none())
    }

    /// The contact that removes `q` ([`CollisionModel::contact_key`]), or
    /// `None` when it is free or the model cannot be loaded.
    #[must_use]
    pub fn contact_key(&self, q: &[f64]) -> Option<usize> {
        self.load().ok().and_then(|m| m.contact_key(q))
    }

    /// `self-collision`, `obstacles`, or `collision` (both).
    #[must_use]
    pub fn kind(&self) -> &'static str {
        let obstacles = !self.spec.obstacles.is_empty() || self.spec.floor.is_some();
        match (self.spec.self_collision, obstacles) {
            (true, false) => "self-collision",
            (false, true) => "obstacles",
            _ => "collision",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn obstacles_parse_and_refuse_bad_numbers() {
        assert_eq!(
            Obstacle::parse("box:0.5,0,0.1,0.2,0.2,0.2").unwrap(),
            Obstacle::Box {
                center: [0.5, 0.0, 0.1],
                size: [0.2, 0.2, 0.2]
            }
        );
        for (bad, why) in [
            ("sphere:1", "expected box"),
            ("box:1,2,3", "3 numbers"),
            ("box:0,0,0,1,1,-1", "must be > 0"),
            ("box:0,0,0,1,1,0", "must be > 0"),
            ("box:0,0,x,1,1,1", "invalid float"),
            ("box:0,0,inf,1,1,1", "not finite"),
        ] {
            let e = Obstacle::parse(bad).unwrap_err();
            assert!(e.contains(why) && e.contains(bad), "{bad}: {e}");
        }
    }
}

//! The model built from its spec: the URDF's tree, the geometries, the pairs
//! checked for self-collision (SRDF exclusions applied) and the obstacles
//! placed in the base link's frame.

use super::model::{CollisionModel, too_close};
use super::shapes::{Geometry, geometries};
use super::spec::{CollisionSpec, Obstacle};
use super::srdf;
use super::tree::Tree;
use parry3d_f64::na::{Isometry3, Vector3};
use parry3d_f64::shape::{Cuboid, HalfSpace, SharedShape};
use std::collections::HashSet;
use std::path::Path;

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

/// The URDF limits (lower, upper) of each driven joint; a continuous joint,
/// or one whose limits are missing, turns through [−π, π].
fn drive_limits(urdf: &urdf_rs::Robot, tree: &Tree, drives: &[usize]) -> Vec<(f64, f64)> {
    drives
        .iter()
        .map(|&k| {
            let name = &tree.joints[k].name;
            let joint = urdf.joints.iter().find(|j| &j.name == name);
            match joint {
                Some(j)
                    if j.joint_type != urdf_rs::JointType::Continuous
                        && j.limit.lower < j.limit.upper =>
                {
                    (j.limit.lower, j.limit.upper)
                }
                _ => (-std::f64::consts::PI, std::f64::consts::PI),
            }
        })
        .collect()
}

/// The moving joints on the tree path from link `a` to link `b` (up from
/// each to their common ancestor): whether any of them is driven. When none
/// is, the two links keep their relative placement in every configuration.
fn moved_apart_by(tree: &Tree, drives: &[usize], a: usize, b: usize) -> bool {
    let up = |l: usize| {
        let mut joints = Vec::new();
        let mut body = tree.body[l];
        while body != 0 {
            joints.push(body - 1);
            body = tree.body[tree.joints[body - 1].parent];
        }
        joints
    };
    let (ua, ub) = (up(a), up(b));
    let shared = ua
        .iter()
        .rev()
        .zip(ub.iter().rev())
        .take_while(|(x, y)| x == y)
        .count();
    ua[..ua.len() - shared]
        .iter()
        .chain(&ub[..ub.len() - shared])
        .any(|j| drives.contains(j))
}

/// Drops the pairs that no driven joint moves apart and that are free at
/// rest: their distance is the same in every configuration, so they never
/// touch (a hand's fingers and palm while the arm moves). Those touching at
/// rest touch everywhere and stay checked, to be reported, or skipped as
/// always touching. Besides time, this keeps a move's check from crawling
/// at the pace of a gap that never closes.
fn drop_rigid_free_pairs(model: &mut CollisionModel) {
    let q: Vec<f64> = model.drives.iter().map(|&j| model.rest[j]).collect();
    let poses = model.geometry_poses(&q);
    let keep: Vec<bool> = model
        .pairs
        .iter()
        .map(|&(a, b)| {
            let (ga, gb) = (&model.geoms[a], &model.geoms[b]);
            moved_apart_by(&model.tree, &model.drives, ga.link, gb.link)
                || too_close(
                    &poses[a],
                    ga.shape.as_ref(),
                    &poses[b],
                    gb.shape.as_ref(),
                    model.clearance,
                )
        })
        .collect();
    let mut k = 0;
    model.pairs.retain(|_| {
        k += 1;
        keep[k - 1]
    });
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
        let limits = drive_limits(&urdf, &tree, &drives);
        let mut model = CollisionModel {
            tree,
            geoms,
            pairs,
            obstacles,
            exposed,
            drives,
            base,
            clearance: spec.clearance,
            rest,
            always_touching: Vec::new(),
        };
        drop_rigid_free_pairs(&mut model);
        if let Some(rule) = spec
            .always_touching
            .as_ref()
            .filter(|_| spec.self_collision)
        {
            model.always_touching = model.skip_always_touching(rule, &limits);
        }
        Ok(model)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// base –j1 (driven)→ l1 –j2 (revolute, not driven)→ l2, and
    /// l1 –j3 (fixed)→ l3, and base –j4 (driven)→ l4.
    fn tree() -> Tree {
        let joint = |name: &str, kind: &str, parent: &str, child: &str| {
            format!(
                r#"<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>"#
            )
        };
        let text = format!(
            r#"<robot name="t"><link name="base"/><link name="l1"/><link name="l2"/><link name="l3"/><link name="l4"/>{}{}{}{}</robot>"#,
            joint("j1", "revolute", "base", "l1"),
            joint("j2", "revolute", "l1", "l2"),
            joint("j3", "fixed", "l1", "l3"),
            joint("j4", "revolute", "base", "l4"),
        );
        Tree::new(&urdf_rs::read_from_string(&text).unwrap()).unwrap()
    }

    #[test]
    fn only_a_driven_joint_between_two_links_moves_them_apart() {
        let t = tree();
        let link = |n: &str| t.index[n];
        let joint = |n: &str| t.joints.iter().position(|j| j.name == n).unwrap();
        let drives = [joint("j1"), joint("j4")];
        let apart = |a: &str, b: &str| moved_apart_by(&t, &drives, link(a), link(b));
        // j2 is not driven: l1, l2 and l3 keep their relative placements.
        assert!(!apart("l1", "l2"));
        assert!(!apart("l2", "l3"));
        assert!(!apart("l3", "l1"));
        // j1 lies between the base and l1, l2, l3; j1 and j4 between l1 and l4.
        assert!(apart("base", "l2"));
        assert!(apart("l3", "base"));
        assert!(apart("l1", "l4"));
        assert!(apart("base", "l4"));
        // With j2 driven too, l1 and l2 move apart but l1 and l3 do not.
        let drives = [joint("j1"), joint("j2"), joint("j4")];
        assert!(moved_apart_by(&t, &drives, link("l1"), link("l2")));
        assert!(!moved_apart_by(&t, &drives, link("l1"), link("l3")));
    }
}

//! Where the page draws each link: every link of the URDF's tree placed by
//! activecal's own kinematics. A link on the chain (the child of a driven
//! joint) is the model's joint frame after its motion, `F_k(q) = P_0 M_0(q_0)
//! … P_k M_k(q_k)` ([`crate::kinematics::joint_chain`]), times the constant
//! `C_k` from the model's frame to the URDF's ([`model_to_urdf`]): the URDF
//! frame of any table, nominal or calibrated, as [`crate::frames`] reads it.
//! Every other link hangs from its nearest chain ancestor (else from the base
//! link) by the URDF's own origins ([`Tree`]). Placements are in the URDF's
//! root frame (the base link's for a chain from the root, the frame of the
//! floor and obstacles). A robot without a
//! URDF (built-in, TOML) is drawn as its model frames: one per joint and the
//! measured frame.

use crate::collision::tree::Tree;
use crate::frames::chain::{UrdfFrames, model_to_urdf};
use crate::kinematics::joint_chain;
use crate::model::{JointKind, ParamTable, Robot};
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};

/// The URDF part of a [`LinkPlacer`].
#[derive(Debug)]
struct UrdfPart {
    tree: Tree,
    /// Per tree joint: the index in `q` of a driven joint, else the value
    /// the joint is held at (locked joints; 0 for the others).
    values: Vec<Result<usize, f64>>,
    /// Per tree link: the chain joint whose child it is.
    anchor: Vec<Option<usize>>,
    /// Per tree link: the nearest ancestor (itself included) that is a
    /// chain link, else `None` (hang from the base).
    hang: Vec<Option<usize>>,
    /// The base link's index in the tree.
    base: usize,
    /// `C_k` per chain joint; empty when the chain is walked against the
    /// file's tree (every link then hangs from the base).
    c: Vec<Isometry3<f64>>,
    /// Measurement frame → base link.
    mount: Isometry3<f64>,
}

/// Places a robot's links at joint values.
#[derive(Debug)]
pub(crate) struct LinkPlacer {
    /// Names of the links, in the order of [`LinkPlacer::place`]'s output.
    pub names: Vec<String>,
    urdf: Option<UrdfPart>,
}

impl LinkPlacer {
    /// The placer of `robot`: its URDF's tree, or its model frames.
    pub fn new(robot: &Robot, urdf: Option<&urdf_rs::Robot>) -> Self {
        match (robot.source.as_deref(), urdf) {
            (Some(src), Some(u)) => match urdf_part(robot, src, u) {
                Some(part) => Self {
                    names: part.tree.links.clone(),
                    urdf: Some(part),
                },
                None => Self::frames_only(robot),
            },
            _ => Self::frames_only(robot),
        }
    }

    fn frames_only(robot: &Robot) -> Self {
        let mut names: Vec<String> = robot
            .frames
            .iter()
            .filter(|f| f.joint.is_some())
            .map(|f| format!("frame {}", f.label))
            .collect();
        names.push("measured frame".into());
        Self { names, urdf: None }
    }

    /// Whether the links are a URDF's (else the model's frames).
    pub fn is_urdf(&self) -> bool {
        self.urdf.is_some()
    }

    /// Each link's parent link (index), `None` for the root.
    pub fn parents(&self) -> Vec<Option<usize>> {
        match &self.urdf {
            Some(u) => {
                let mut p = vec![None; u.tree.links.len()];
                for j in &u.tree.joints {
                    p[j.child] = Some(j.parent);
                }
                p
            }
            None => (0..self.names.len()).map(|k| k.checked_sub(1)).collect(),
        }
    }

    /// The base link's pose in the measurement frame the placer was made
    /// with (identity for a robot without a URDF).
    pub fn mount(&self) -> Isometry3<f64> {
        self.urdf
            .as_ref()
            .map_or(Isometry3::identity(), |u| u.mount)
    }

    /// Each link's placement at `q` with `table`'s parameters, in the
    /// URDF's root frame (the measurement frame for a robot without a URDF).
    pub fn place(&self, robot: &Robot, table: &ParamTable, q: &[f64]) -> Vec<Isometry3<f64>> {
        self.place_mounted(robot, table, q, self.mount())
    }

    /// The URDF tree's link placements (root frame) at `q`.
    fn tree_at(u: &UrdfPart, q: &[f64]) -> Vec<Isometry3<f64>> {
        let vals: Vec<f64> = u
            .values
            .iter()
            .map(|v| match v {
                Ok(i) => q[*i],
                Err(x) => *x,
            })
            .collect();
        let mut tree = vec![Isometry3::identity(); u.tree.links.len()];
        u.tree.placements(&vals, &mut tree);
        tree
    }

    /// From the measurement frame (the base link at `mount` in it) to the
    /// page's frame at `q`: the URDF's root frame (the chain's base link
    /// moves in it when the chain is walked against the tree, as a head
    /// camera's is); identity without a URDF.
    pub fn measurement_to_page(&self, q: &[f64], mount: Isometry3<f64>) -> Isometry3<f64> {
        self.urdf.as_ref().map_or(Isometry3::identity(), |u| {
            Self::tree_at(u, q)[u.base] * mount.inverse()
        })
    }

    /// As [`LinkPlacer::place`], the base link taken at `mount` in the
    /// measurement frame (a calibrated model's own measurement frame, so
    /// that its base coincides with the nominal one's).
    pub fn place_mounted(
        &self,
        robot: &Robot,
        table: &ParamTable,
        q: &[f64],
        mount: Isometry3<f64>,
    ) -> Vec<Isometry3<f64>> {
        let frames = joint_frames(robot, table, q);
        let Some(u) = &self.urdf else {
            return frames;
        };
        let tree = Self::tree_at(u, q);
        let to_root = tree[u.base] * mount.inverse();
        let anchored = |l: usize| -> Isometry3<f64> {
            match u.anchor[l] {
                Some(k) if !u.c.is_empty() => to_root * frames[k] * u.c[k],
                _ => tree[l],
            }
        };
        (0..tree.len())
            .map(|l| match u.hang[l] {
                Some(a) if a == l => anchored(l),
                Some(a) => anchored(a) * (tree[a].inverse() * tree[l]),
                None => tree[l],
            })
            .collect()
    }
}

/// Each driven joint's frame after its motion, `F_k(q)`, then the measured
/// frame, in the measurement frame.
fn joint_frames(robot: &Robot, table: &ParamTable, q: &[f64]) -> Vec<Isometry3<f64>> {
    let ch = joint_chain(robot, table);
    let mut at = Isometry3::identity();
    let mut out = Vec::with_capacity(ch.placements.len() + 1);
    for (k, (p, kind)) in ch.placements.iter().zip(&ch.kinds).enumerate() {
        let m = match kind {
            JointKind::Revolute => Isometry3::from_parts(
                Translation3::identity(),
                UnitQuaternion::from_axis_angle(&Vector3::z_axis(), q[k]),
            ),
            JointKind::Prismatic => Isometry3::translation(0.0, 0.0, q[k]),
        };
        at = at * p * m;
        out.push(at);
    }
    out.push(at * ch.tool);
    out
}

/// The tree, values and anchors of a URDF-imported robot; `None` when the
/// file's tree does not hold the chain's joints.
fn urdf_part(
    robot: &Robot,
    src: &crate::model::source::UrdfSource,
    u: &urdf_rs::Robot,
) -> Option<UrdfPart> {
    let tree = Tree::new(u).ok()?;
    let driven = src.driven_names();
    let values = tree
        .joints
        .iter()
        .map(|j| match driven.iter().position(|d| *d == j.name) {
            Some(i) => Ok(i),
            None => Err(src
                .joints
                .iter()
                .find(|s| s.name == j.name)
                .and_then(|s| s.locked)
                .unwrap_or(0.0)),
        })
        .collect();
    let base = *tree.index.get(&src.base)?;
    let mut anchor = vec![None; tree.links.len()];
    let c = if src.reversed.is_empty() {
        model_to_urdf(robot, &UrdfFrames::of(src)).unwrap_or_default()
    } else {
        Vec::new()
    };
    for (k, name) in driven.iter().enumerate() {
        let j = tree.joints.iter().find(|j| &j.name == name)?;
        anchor[j.child] = Some(k);
    }
    // Joints run from the root down: a parent's hang is known first.
    let mut hang: Vec<Option<usize>> = vec![None; tree.links.len()];
    for j in &tree.joints {
        hang[j.child] = if anchor[j.child].is_some() {
            Some(j.child)
        } else {
            hang[j.parent]
        };
    }
    Some(UrdfPart {
        tree,
        values,
        anchor,
        hang,
        base,
        c,
        mount: src.mount,
    })
}

//! The link tree of a URDF for collision checking: every link's placement
//! from joint values (its own walk over the URDF's joint origins and axes,
//! independent of the DH/Hayati conversion of [`crate::io`]), and which
//! links move together.

use parry3d_f64::na::{Isometry3, Translation3, UnitQuaternion, Vector3};
use std::collections::HashMap;

/// How a URDF joint moves its child.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Motion {
    /// Rotation about the axis (revolute, continuous).
    Revolute,
    /// Translation along the axis.
    Prismatic,
    /// None (fixed; floating, planar and spherical joints sit at their zero).
    Fixed,
}

/// One joint of the tree.
#[derive(Clone, Debug)]
pub(crate) struct TreeJoint {
    pub name: String,
    pub parent: usize,
    pub child: usize,
    pub origin: Isometry3<f64>,
    pub axis: Vector3<f64>,
    pub motion: Motion,
}

/// Links, joints in an order where a parent link's placement is known before
/// its children's, and the rigid body of every link.
#[derive(Clone, Debug)]
pub(crate) struct Tree {
    pub links: Vec<String>,
    pub index: HashMap<String, usize>,
    pub joints: Vec<TreeJoint>,
    pub root: usize,
    /// The rigid body of a link: the nearest moving joint at or above it
    /// (`0` for the root's body, `j + 1` for moving joint `j`).
    pub body: Vec<usize>,
}

/// A URDF pose as an isometry (`R = Rz(yaw)·Ry(pitch)·Rx(roll)`).
pub(crate) fn pose(p: &urdf_rs::Pose) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::new(p.xyz[0], p.xyz[1], p.xyz[2]),
        UnitQuaternion::from_euler_angles(p.rpy[0], p.rpy[1], p.rpy[2]),
    )
}

impl Tree {
    /// The tree of a parsed URDF; errors name a link with two parents, a
    /// missing link or a loop.
    pub fn new(urdf: &urdf_rs::Robot) -> Result<Tree, String> {
        let mut links: Vec<String> = urdf.links.iter().map(|l| l.name.clone()).collect();
        let mut index: HashMap<String, usize> = HashMap::new();
        for (i, l) in links.iter().enumerate() {
            index.insert(l.clone(), i);
        }
        for j in &urdf.joints {
            for l in [&j.parent.link, &j.child.link] {
                if !index.contains_key(l.as_str()) {
                    index.insert(l.clone(), links.len());
                    links.push(l.clone());
                }
            }
        }
        let n = links.len();
        let mut parent_joint = vec![None; n];
        let mut joints = Vec::with_capacity(urdf.joints.len());
        for (k, j) in urdf.joints.iter().enumerate() {
            let (p, c) = (index[&j.parent.link], index[&j.child.link]);
            if let Some(other) = parent_joint[c] {
                let o: &TreeJoint = &joints[other];
                return Err(format!(
                    "link '{}' is the child of two joints ('{}' and '{}')",
                    links[c], o.name, j.name
                ));
            }
            parent_joint[c] = Some(k);
            let motion = match j.joint_type {
                urdf_rs::JointType::Revolute | urdf_rs::JointType::Continuous => Motion::Revolute,
                urdf_rs::JointType::Prismatic => Motion::Prismatic,
                _ => Motion::Fixed,
            };
            let a = Vector3::new(j.axis.xyz[0], j.axis.xyz[1], j.axis.xyz[2]);
            let axis = if a.norm() > 0.0 {
                a.normalize()
            } else {
                Vector3::x()
            };
            joints.push(TreeJoint {
                name: j.name.clone(),
                parent: p,
                child: c,
                origin: pose(&j.origin),
                axis,
                motion,
            });
        }
        let roots: Vec<usize> = (0..n).filter(|&l| parent_joint[l].is_none()).collect();
        if roots.len() != 1 {
            return Err(format!(
                "the URDF's links form {} trees (roots {}), not one",
                roots.len(),
                roots
                    .iter()
                    .map(|&r| links[r].as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            ));
        }
        // Joints from the root down (breadth first).
        let mut order = Vec::with_capacity(joints.len());
        let mut frontier = vec![roots[0]];
        while let Some(l) = frontier.pop() {
            for (k, j) in joints.iter().enumerate() {
                if j.parent == l {
                    order.push(k);
                    frontier.push(j.child);
                }
            }
        }
        if order.len() != joints.len() {
            return Err("the URDF's joints form a loop".into());
        }
        let joints: Vec<TreeJoint> = order.iter().map(|&k| joints[k].clone()).collect();
        let mut body = vec![0; n];
        for (k, j) in joints.iter().enumerate() {
            body[j.child] = if j.motion == Motion::Fixed {
                body[j.parent]
            } else {
                k + 1
            };
        }
        Ok(Tree {
            links,
            index,
            joints,
            root: roots[0],
            body,
        })
    }

    /// Placement of every link in the root frame, for joint values `values`
    /// (one per joint of `self.joints`, in that order; fixed joints ignore
    /// theirs).
    pub fn placements(&self, values: &[f64], out: &mut [Isometry3<f64>]) {
        out[self.root] = Isometry3::identity();
        for (j, v) in self.joints.iter().zip(values) {
            let motion = match j.motion {
                Motion::Revolute => Isometry3::from_parts(
                    Translation3::identity(),
                    UnitQuaternion::from_scaled_axis(j.axis * *v),
                ),
                Motion::Prismatic => Isometry3::from_parts(
                    Translation3::from(j.axis * *v),
                    UnitQuaternion::identity(),
                ),
                Motion::Fixed => Isometry3::identity(),
            };
            out[j.child] = out[j.parent] * j.origin * motion;
        }
    }

    /// Whether two bodies are joined by one joint (adjacent links).
    pub fn adjacent_bodies(&self, a: usize, b: usize) -> bool {
        let parent_body = |body: usize| -> Option<usize> {
            (body > 0).then(|| self.body[self.joints[body - 1].parent])
        };
        parent_body(a) == Some(b) || parent_body(b) == Some(a)
    }
}

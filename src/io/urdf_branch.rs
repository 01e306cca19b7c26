//! A camera on the robot's own link: the chain from the camera's link to
//! the arm's tip through the branch point of one URDF tree.
//!
//! A head camera (TIAGo's, PR2's, Fetch's) and a target on the arm's tip
//! hang from one tree: `A → head joints → camera link` and `A → arm joints
//! → tip`, `A` the links' nearest common ancestor (TIAGo: `torso_lift_link`).
//! The camera sees `T_{A,cam}⁻¹ T_{A,tip}`: everything below `A` (the
//! torso's lift, the base) cancels, and the head chain enters inverted.
//! [`camera_branch`] builds that one serial chain: rooted at the camera's
//! link, down the head chain against the file's tree, then up the arm.
//! A joint `j` walked backwards (`O_j M_j(q)` from parent to child, `O` its
//! `<origin>`, `M` its motion) contributes `M_j(q)⁻¹ O_j⁻¹`: a joint of
//! the same name and value whose axis is the file's negated (a turn by
//! `−q` is a turn by `q` about `−a`), whose origin is the inverse of the
//! previous (camera-side) joint's origin. The chain's first joint keeps
//! the fixed joints between it and the camera's link as its origin, the
//! last head joint's origin becomes a fixed joint into `A`, and the arm's
//! joints follow as the file gives them.
//!
//! The chain is then imported as any chain ([`super::urdf`]: DH/Hayati
//! frames, its unknowns chosen by the one rule), and keeps the file's text:
//! its calibrated origins are written into the file's joints
//! ([`crate::model::source::Reversed`]): a head joint's change into the
//! origin of the head joint on its camera side, the arm's into the arm's.
//! The base's pose relative to `A` and the head's and arm's placements
//! relative to each other below their first joints are seen only together:
//! the last head joint's `<origin>` stays as the file has it and the arm's
//! first origin takes the change, the split's rule for a chain's origins
//! ([`crate::frames::gauge`]).

use super::urdf::{UrdfOptions, from_parsed, parsed};
use crate::error::{Error, Result};
use crate::model::source::{Reversed, SourceJoint, UrdfSource, rpy};
use crate::model::{JointKind, Robot};
use nalgebra::{Isometry3, Rotation3, Translation3, UnitQuaternion, Vector3};
use std::collections::HashMap;

/// The joints from `link` up to the root, child first.
fn up_path<'u>(
    by_child: &HashMap<&str, &'u urdf_rs::Joint>,
    link: &str,
) -> Vec<&'u urdf_rs::Joint> {
    let mut out = Vec::new();
    let mut at = link;
    while let Some(j) = by_child.get(at) {
        out.push(*j);
        at = &j.parent.link;
        if out.len() > by_child.len() {
            break; // a loop: the importer refuses the tree
        }
    }
    out
}

fn iso(p: &urdf_rs::Pose) -> Isometry3<f64> {
    let (x, r) = (p.xyz.0, p.rpy.0);
    Isometry3::from_parts(
        Translation3::new(x[0], x[1], x[2]),
        UnitQuaternion::from_rotation_matrix(&Rotation3::from_euler_angles(r[0], r[1], r[2])),
    )
}

fn pose(t: &Isometry3<f64>) -> urdf_rs::Pose {
    let v = t.translation.vector;
    urdf_rs::Pose {
        xyz: urdf_rs::Vec3([v.x, v.y, v.z]),
        rpy: urdf_rs::Vec3(rpy(&t.rotation.to_rotation_matrix())),
    }
}

fn moving(j: &urdf_rs::Joint) -> Option<JointKind> {
    use urdf_rs::JointType as T;
    match j.joint_type {
        T::Revolute | T::Continuous => Some(JointKind::Revolute),
        T::Prismatic => Some(JointKind::Prismatic),
        _ => None,
    }
}

fn source_joint(j: &urdf_rs::Joint) -> SourceJoint {
    SourceJoint {
        name: j.name.clone(),
        kind: moving(j),
        origin: iso(&j.origin),
        axis: Vector3::from(j.axis.xyz.0),
        locked: None,
    }
}

/// The head chain walked backwards (`up`: camera link first, up to the
/// branch point `a`): its joints and their [`Reversed`] records.
fn reversed_joints(
    up: &[&urdf_rs::Joint],
    camera_link: &str,
    a: &str,
) -> std::result::Result<(Vec<urdf_rs::Joint>, Vec<Reversed>), String> {
    let mut joints = Vec::new();
    let mut records = Vec::new();
    // The fixed transform since the last moving joint (camera side first),
    // and that joint.
    let mut pending = Isometry3::identity();
    let mut prev: Option<&urdf_rs::Joint> = None;
    let mut fixed_since = false;
    let mut link = camera_link.to_string();
    for j in up {
        if j.mimic.is_some() {
            return Err(format!(
                "joint '{}' of the camera's chain is a mimic joint",
                j.name
            ));
        }
        if moving(j).is_none() {
            pending *= iso(&j.origin).inverse();
            fixed_since |= prev.is_some();
            continue;
        }
        if let (Some(p), true) = (prev, fixed_since) {
            return Err(format!(
                "fixed joints lie between the moving joints '{}' and '{}' of the camera's chain: a calibrated origin could not be written into one joint",
                p.name, j.name
            ));
        }
        let child = format!("{}~reversed", j.name);
        let mut r = (*j).clone();
        r.parent.link = link.clone();
        r.child.link = child.clone();
        r.origin = pose(&pending);
        r.axis.xyz = urdf_rs::Vec3((-Vector3::from(j.axis.xyz.0)).into());
        joints.push(r);
        records.push(Reversed {
            joint: j.name.clone(),
            neighbour: prev.map(source_joint),
        });
        pending = iso(&j.origin).inverse();
        prev = Some(j);
        fixed_since = false;
        link = child;
    }
    let mut last = (*up.last().expect("a camera link below the branch point")).clone();
    last.name = format!("{}~origin", last.name);
    last.joint_type = urdf_rs::JointType::Fixed;
    last.parent.link = link;
    last.child.link = a.to_string();
    last.origin = pose(&pending);
    last.mimic = None;
    joints.push(last);
    Ok((joints, records))
}

/// The robot of a camera on link `camera_link` of `robot`'s URDF seeing a
/// target on `robot`'s tip (see the module documentation): the chain from
/// the camera's link to the tip, its measurement frame the camera's link.
/// Joints of `robot` locked and on the new chain stay locked. Errors when
/// the robot is not from a URDF, the link is not in it, the camera's link
/// is on the arm's own chain (or the tip on the camera's), or the chain
/// cannot be imported.
pub fn camera_branch(robot: &Robot, camera_link: &str) -> Result<Robot> {
    let src = robot.source.as_ref().ok_or_else(|| {
        Error::Invalid(format!(
            "robot '{}' was not imported from a URDF: a camera on its own link needs the URDF tree",
            robot.name
        ))
    })?;
    let bad = |message: String| Error::Parse {
        path: src.path.clone(),
        message,
    };
    let urdf = parsed(&src.text).map_err(bad)?;
    let by_child: HashMap<&str, &urdf_rs::Joint> = urdf
        .joints
        .iter()
        .map(|j| (j.child.link.as_str(), j))
        .collect();
    let known =
        urdf.links.iter().any(|l| l.name == camera_link) || by_child.contains_key(camera_link);
    if !known {
        return Err(bad(format!(
            "the camera's link '{camera_link}' is not a link of the URDF"
        )));
    }
    let cam_up = up_path(&by_child, camera_link);
    let tip_up = up_path(&by_child, &src.tip);
    let tip_links: Vec<&str> = std::iter::once(src.tip.as_str())
        .chain(tip_up.iter().map(|j| j.parent.link.as_str()))
        .collect();
    let Some(k) = std::iter::once(camera_link)
        .chain(cam_up.iter().map(|j| j.parent.link.as_str()))
        .position(|l| tip_links.contains(&l))
    else {
        return Err(bad(format!(
            "the camera's link '{camera_link}' and the tip '{}' are not in one tree",
            src.tip
        )));
    };
    if k == 0 {
        return Err(bad(format!(
            "the camera's link '{camera_link}' is on the chain to the tip '{}': a camera that moves with the arm is eye-in-hand",
            src.tip
        )));
    }
    let a = cam_up[k - 1].parent.link.clone();
    if a == src.tip {
        return Err(bad(format!(
            "the tip '{}' is on the camera's chain",
            src.tip
        )));
    }
    let (mut joints, reversed) = reversed_joints(&cam_up[..k], camera_link, &a).map_err(bad)?;
    let down = tip_up
        .iter()
        .position(|j| j.parent.link == a)
        .expect("A is on the tip's path");
    joints.extend(tip_up[..=down].iter().rev().map(|j| (*j).clone()));
    let mut tree = urdf.clone();
    tree.links.clear();
    tree.joints = joints;
    let names: Vec<&str> = tree.joints.iter().map(|j| j.name.as_str()).collect();
    let opts = UrdfOptions {
        base: Some(camera_link.to_string()),
        tip: Some(src.tip.clone()),
        lock: src
            .joints
            .iter()
            .filter_map(|j| j.locked.map(|v| (j.name.clone(), v)))
            .filter(|(n, _)| names.contains(&n.as_str()))
            .collect(),
        ..UrdfOptions::default()
    };
    let mut out = from_parsed(&tree, &src.text, &src.path, &opts)?;
    let mut source: UrdfSource = out.source.as_deref().expect("an imported chain").clone();
    source.reversed = reversed;
    out.source = Some(std::sync::Arc::new(source));
    Ok(out)
}

/// The root link of the URDF tree a camera chain ([`camera_branch`]) was
/// built from: the frame its collision model places obstacles and a floor
/// in (the camera chain's own base is the camera's link, which moves).
pub fn tree_root(robot: &Robot) -> Result<String> {
    let src = robot.source.as_ref().ok_or_else(|| {
        Error::Invalid(format!(
            "robot '{}' was not imported from a URDF",
            robot.name
        ))
    })?;
    let urdf = parsed(&src.text).map_err(|message| Error::Parse {
        path: src.path.clone(),
        message,
    })?;
    urdf.links
        .iter()
        .find(|l| !urdf.joints.iter().any(|j| j.child.link == l.name))
        .map(|l| l.name.clone())
        .ok_or_else(|| Error::Parse {
            path: src.path.clone(),
            message: "the URDF has no root link (every link is a joint's child)".into(),
        })
}

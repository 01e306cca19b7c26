//! The chain of a URDF tree: the tree of its joints and links (checked:
//! one parent per link, no loop, one root), the path from a base link to a
//! tip link, held joints folded into fixed ones, and each joint's axis and
//! limits checked. [`super::urdf`] turns the chain into DH/Hayati frames.

use crate::error::Compact;
use crate::model::JointKind;
use crate::model::source::SourceJoint;
use nalgebra::{Isometry3, Rotation3, Translation3, UnitQuaternion, Vector3};
use std::collections::HashMap;
use std::f64::consts::PI;

/// Range given to a continuous joint (and to a revolute joint whose URDF
/// limits are infinite): ±170°. A lattice over ±180° would repeat its end
/// poses (−180° and 180° are one pose), and with 3 levels see only two
/// angles of the joint.
pub const CONTINUOUS_RANGE: [f64; 2] = [-170.0 * PI / 180.0, 170.0 * PI / 180.0];

/// One URDF joint of the chain, fixed ones included.
#[derive(Clone, Debug)]
pub(super) struct ChainJoint {
    pub(super) name: String,
    /// `None` for a fixed joint.
    pub(super) kind: Option<JointKind>,
    /// The joint's origin (for a locked joint, with its motion folded in).
    pub(super) origin: Isometry3<f64>,
    /// Unit axis in the joint frame.
    pub(super) axis: Vector3<f64>,
    /// Lower and upper limits.
    pub(super) limits: [f64; 2],
    /// The joint as the file gives it (origin and axis unfolded).
    pub(super) source: SourceJoint,
}

/// The isometry of a URDF `<origin>`; `None` when a value is not finite.
pub(super) fn iso_from_pose(p: &urdf_rs::Pose) -> Option<Isometry3<f64>> {
    let (x, r) = (p.xyz.0, p.rpy.0);
    if !x.iter().chain(&r).all(|v| v.is_finite()) {
        return None;
    }
    let rot = Rotation3::from_euler_angles(r[0], r[1], r[2]);
    Some(Isometry3::from_parts(
        Translation3::new(x[0], x[1], x[2]),
        UnitQuaternion::from_rotation_matrix(&rot),
    ))
}

/// Largest magnitude of a joint origin's value (metres or radians), as for
/// a description's parameters: larger values are typing errors and would
/// overflow the kinematics (a 1e300 origin leaves no parameter
/// identifiable).
pub const MAX_ORIGIN: f64 = 1e6;

/// Most moving joints an imported chain may have (as many as a TOML
/// description's frames, [`crate::io::robot_toml::MAX_FRAMES`]): the choice of
/// unknowns grows with the cube of the chain's length.
pub const MAX_CHAIN_JOINTS: usize = 100;

/// Links listed at most in an error message.
const LIST_AT_MOST: usize = 12;

/// Up to [`LIST_AT_MOST`] names, comma-separated, `…` when there are more.
fn list_names<S: AsRef<str>>(names: &[S]) -> String {
    let mut v: Vec<&str> = names.iter().map(AsRef::as_ref).take(LIST_AT_MOST).collect();
    if names.len() > LIST_AT_MOST {
        v.push("…");
    }
    v.join(", ")
}

/// Whether a moving joint looks like a gripper's: a finger, jaw or gripper
/// joint or child link, or a short prismatic joint (stroke below 0.1 m).
fn gripper_reason(j: &urdf_rs::Joint) -> Option<String> {
    let words = [
        "finger", "jaw", "gripper", "claw", "grip", "hand_l", "hand_r", "knuckle",
    ];
    let lower = |x: &str| x.to_ascii_lowercase();
    for name in [&j.name, &j.child.link] {
        if let Some(w) = words.iter().find(|w| lower(name).contains(*w)) {
            return Some(format!(
                "'{name}' names a {}",
                w.trim_end_matches("_l").trim_end_matches("_r")
            ));
        }
    }
    if j.joint_type == urdf_rs::JointType::Prismatic && (j.limit.upper - j.limit.lower).abs() < 0.1
    {
        return Some(format!(
            "it is a short prismatic joint ({:.3} m of stroke)",
            (j.limit.upper - j.limit.lower).abs()
        ));
    }
    None
}

/// Whether a URDF joint moves (revolute, continuous or prismatic).
fn is_moving(j: &urdf_rs::Joint) -> bool {
    use urdf_rs::JointType as T;
    matches!(j.joint_type, T::Revolute | T::Continuous | T::Prismatic)
}

/// The joints and links of a URDF as a tree: each link's parent joint and
/// child joints, every link name, and the root. Built once per import;
/// [`Tree::new`] refuses a link with two parents, a loop and a forest.
struct Tree<'u> {
    joints: &'u [urdf_rs::Joint],
    by_child: HashMap<&'u str, usize>,
    children: HashMap<&'u str, Vec<usize>>,
    links: Vec<&'u str>,
    root: &'u str,
}

impl<'u> Tree<'u> {
    fn new(urdf: &'u urdf_rs::Robot) -> std::result::Result<Self, String> {
        let joints = urdf.joints.as_slice();
        let mut by_child: HashMap<&str, usize> = HashMap::new();
        let mut children: HashMap<&str, Vec<usize>> = HashMap::new();
        for (i, j) in joints.iter().enumerate() {
            if let Some(&k) = by_child.get(j.child.link.as_str()) {
                return Err(format!(
                    "link '{}' is the child of two joints ('{}' and '{}')",
                    j.child.link, joints[k].name, j.name
                ));
            }
            by_child.insert(&j.child.link, i);
            children.entry(&j.parent.link).or_default().push(i);
        }
        let mut links: Vec<&str> = urdf.links.iter().map(|l| l.name.as_str()).collect();
        for j in joints {
            links.push(&j.parent.link);
            links.push(&j.child.link);
        }
        links.sort_unstable();
        links.dedup();
        let mut tree = Tree {
            joints,
            by_child,
            children,
            links,
            root: "",
        };
        tree.refuse_loops()?;
        tree.root = tree.the_root()?;
        Ok(tree)
    }

    /// A loop: walking up from some link comes back to it. Names its joints.
    fn refuse_loops(&self) -> std::result::Result<(), String> {
        for &start in &self.links {
            let mut at = start;
            let mut seen: Vec<usize> = Vec::new();
            while let Some(&j) = self.by_child.get(at) {
                if let Some(k) = seen.iter().position(|&s| s == j) {
                    let mut cycle: Vec<&str> = seen[k..]
                        .iter()
                        .rev()
                        .map(|&s| self.joints[s].name.as_str())
                        .collect();
                    cycle.push(cycle[0]);
                    return Err(format!(
                        "the joints form a loop ({}): a URDF must be a tree",
                        cycle.join(" → ")
                    ));
                }
                seen.push(j);
                at = &self.joints[j].parent.link;
            }
        }
        Ok(())
    }

    /// The one link without a parent joint.
    fn the_root(&self) -> std::result::Result<&'u str, String> {
        let roots: Vec<&str> = self
            .links
            .iter()
            .copied()
            .filter(|l| !self.by_child.contains_key(l))
            .collect();
        match roots.as_slice() {
            [r] => Ok(*r),
            [] => Err("the joints form a loop: no link is the root".into()),
            many => Err(format!(
                "{} root links ({}): the URDF must be one tree",
                many.len(),
                list_names(many)
            )),
        }
    }

    /// `name` as a link of the tree; an error names the role (`base`,
    /// `tip`), the closest names and the links.
    fn link<'a>(&self, what: &str, name: &'a str) -> std::result::Result<&'a str, String> {
        if self.links.contains(&name) {
            return Ok(name);
        }
        Err(format!(
            "the {what} link '{name}' is not in the URDF{} (its links: {})",
            crate::names::did_you_mean(name, &self.links),
            list_names(&self.links)
        ))
    }

    /// The joints from `base` down to `link`, if `link` is below it.
    fn path(&self, base: &str, link: &str) -> Option<Vec<usize>> {
        let mut path = Vec::new();
        let mut at = link;
        while at != base {
            let &j = self.by_child.get(at)?;
            path.push(j);
            at = &self.joints[j].parent.link;
        }
        path.reverse();
        Some(path)
    }

    /// The tip when none is named: the one leaf below `base` with a joint
    /// above it; several are refused, listing them with their moving-joint
    /// counts.
    fn only_leaf(&self, base: &str) -> std::result::Result<&'u str, String> {
        let mut leaves: Vec<(&str, usize)> = Vec::new();
        let mut stack = vec![base];
        while let Some(l) = stack.pop() {
            match self.children.get(l) {
                None => {
                    // Every leaf with a joint above it; one without a
                    // moving joint is refused later with its reason.
                    if let Some(p) = self.path(base, l).filter(|p| !p.is_empty()) {
                        let moving = p.iter().filter(|&&j| is_moving(&self.joints[j])).count();
                        let leaf = self.joints[p[p.len() - 1]].child.link.as_str();
                        leaves.push((leaf, moving));
                    }
                }
                Some(js) => stack.extend(js.iter().map(|&j| self.joints[j].child.link.as_str())),
            }
        }
        leaves.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(b.0)));
        match leaves.as_slice() {
            [] => Err(format!(
                "no revolute or prismatic joint below the base link '{base}'"
            )),
            [(l, _)] => Ok(l),
            many => {
                let c: Vec<String> = many
                    .iter()
                    .map(|(l, n)| format!("{l} ({n} joint{})", if *n == 1 { "" } else { "s" }))
                    .collect();
                Err(format!(
                    "the URDF is a tree with {} branches below '{base}': choose the measured link as the chain's tip; candidate tips: {}",
                    many.len(),
                    list_names(&c)
                ))
            }
        }
    }

    /// Checks every held joint: in the URDF, on the chain `path`, moving,
    /// held at a finite value.
    fn check_locks(
        &self,
        path: &[usize],
        lock: &[(String, f64)],
        (base, tip): (&str, &str),
    ) -> std::result::Result<(), String> {
        let joints = self.joints;
        for (name, value) in lock {
            let Some(j) = joints.iter().find(|j| &j.name == name) else {
                return Err(format!(
                    "locked joint '{name}': there is no joint '{name}' in the URDF"
                ));
            };
            if !path.iter().any(|&i| joints[i].name == *name) {
                let on: Vec<&str> = path
                    .iter()
                    .filter(|&&i| is_moving(&joints[i]))
                    .map(|&i| joints[i].name.as_str())
                    .collect();
                return Err(format!(
                    "locked joint '{name}': the joint is not on the chain from '{base}' to '{tip}' (its joints: {})",
                    list_names(&on)
                ));
            }
            if !is_moving(j) {
                return Err(format!("locked joint '{name}': the joint is fixed already"));
            }
            if !value.is_finite() {
                return Err(format!(
                    "locked joint '{name}' = {value}: not a finite number"
                ));
            }
        }
        Ok(())
    }

    /// Checks the chain's driven joints `moving`: not too many, and the last
    /// neither a mimic joint nor (unless the tip was named) a gripper's.
    fn check_driven(
        &self,
        moving: &[usize],
        (base, tip): (&str, &str),
        explicit_tip: bool,
    ) -> std::result::Result<(), String> {
        let joints = self.joints;
        if moving.len() > MAX_CHAIN_JOINTS {
            return Err(format!(
                "the chain from '{base}' to '{tip}' has {} moving joints ('{}' … '{}'), more than {MAX_CHAIN_JOINTS}: choose a shorter chain (the chain's base and tip) or locked joints",
                moving.len(),
                joints[moving[0]].name,
                joints[moving[moving.len() - 1]].name
            ));
        }
        let Some(&last) = moving.last() else {
            return Ok(());
        };
        let j = &joints[last];
        let parent = &j.parent.link;
        if j.mimic.is_some() {
            return Err(format!(
                "joint '{}' mimics another joint (a gripper's, usually): end the chain before it (the chain's tip '{parent}'), or hold it still (locked joint '{}' = 0)",
                j.name, j.name
            ));
        }
        if let Some(why) = gripper_reason(j).filter(|_| !explicit_tip) {
            return Err(format!(
                "the chain's last moving joint '{}' looks like a gripper's ({why}): measure the arm's flange (the chain's tip '{parent}'), or keep the joint still (locked joint '{}' = a value), or name this tip explicitly (the chain's tip '{tip}')",
                j.name, j.name
            ));
        }
        Ok(())
    }
}

/// The joints from the base link (default: the URDF's root) to the tip, in
/// order, with the locked joints made fixed at their values.
pub(super) fn extract_chain(
    urdf: &urdf_rs::Robot,
    base: Option<&str>,
    tip: Option<&str>,
    lock: &[(String, f64)],
) -> std::result::Result<Vec<ChainJoint>, String> {
    let tree = Tree::new(urdf)?;
    let explicit_tip = tip.is_some();
    let base = match base {
        Some(b) => tree.link("base", b)?,
        None => tree.root,
    };
    let tip = match tip {
        Some(t) => tree.link("tip", t)?,
        None => tree.only_leaf(base)?,
    };
    let Some(path) = tree.path(base, tip) else {
        return Err(format!(
            "the tip link '{tip}' is not below the base link '{base}'"
        ));
    };
    tree.check_locks(&path, lock, (base, tip))?;
    let locked = |name: &str| lock.iter().find(|(n, _)| n == name).map(|&(_, v)| v);
    let joints = tree.joints;
    let moving: Vec<usize> = path
        .iter()
        .copied()
        .filter(|&i| is_moving(&joints[i]) && locked(&joints[i].name).is_none())
        .collect();
    tree.check_driven(&moving, (base, tip), explicit_tip)?;
    let out = path
        .iter()
        .map(|&i| match locked(&joints[i].name) {
            Some(v) => locked_joint(&joints[i], v),
            None => chain_joint(&joints[i]),
        })
        .collect::<std::result::Result<Vec<_>, String>>()?;
    if out.iter().all(|j| j.kind.is_none()) {
        return Err(format!(
            "no revolute or prismatic joint between the base '{base}' and the tip '{tip}'"
        ));
    }
    Ok(out)
}

/// A held joint: a fixed one at its value, its motion folded into the
/// origin; its source keeps the file's origin and axis.
fn locked_joint(j: &urdf_rs::Joint, v: f64) -> std::result::Result<ChainJoint, String> {
    use urdf_rs::JointType as T;
    let file_origin = iso_from_pose(&j.origin)
        .ok_or_else(|| format!("joint '{}': the origin is not finite", j.name))?;
    let axis = Vector3::from(j.axis.xyz.0);
    let n = axis.norm();
    if !(n.is_finite() && n > 1e-9) {
        return Err(format!(
            "joint '{}': the axis is zero or not finite",
            j.name
        ));
    }
    let u = nalgebra::Unit::new_normalize(axis);
    let motion = match j.joint_type {
        T::Prismatic => Isometry3::from_parts(
            Translation3::from(u.into_inner() * v),
            UnitQuaternion::identity(),
        ),
        _ => Isometry3::from_parts(
            Translation3::identity(),
            UnitQuaternion::from_axis_angle(&u, v),
        ),
    };
    Ok(ChainJoint {
        name: j.name.clone(),
        kind: None,
        origin: file_origin * motion,
        axis: Vector3::z(),
        limits: [0.0; 2],
        source: SourceJoint {
            name: j.name.clone(),
            kind: Some(match j.joint_type {
                T::Prismatic => JointKind::Prismatic,
                _ => JointKind::Revolute,
            }),
            origin: file_origin,
            axis: u.into_inner(),
            locked: Some(v),
        },
    })
}

/// A joint of the chain as the file gives it: fixed, revolute (continuous
/// included) or prismatic, with a unit axis and checked limits.
fn chain_joint(j: &urdf_rs::Joint) -> std::result::Result<ChainJoint, String> {
    use urdf_rs::JointType as T;
    let origin = iso_from_pose(&j.origin)
        .ok_or_else(|| format!("joint '{}': the origin is not finite", j.name))?;
    for (what, v) in [("xyz", j.origin.xyz.0), ("rpy", j.origin.rpy.0)] {
        if v.iter().any(|x| x.abs() > MAX_ORIGIN) {
            let shown: Vec<String> = v
                .iter()
                .map(|x| crate::error::Compact(*x).to_string())
                .collect();
            return Err(format!(
                "joint '{}': origin {what}=\"{}\" is out of range (|value| <= {MAX_ORIGIN:e}, metres or radians)",
                j.name,
                shown.join(" ")
            ));
        }
    }
    let kind = match j.joint_type {
        T::Fixed => None,
        T::Revolute | T::Continuous => Some(JointKind::Revolute),
        T::Prismatic => Some(JointKind::Prismatic),
        ref other => {
            return Err(format!(
                "joint '{}' is {other:?}: a serial chain has only revolute, continuous, prismatic and fixed joints",
                j.name
            ));
        }
    };
    let mut axis = Vector3::from(j.axis.xyz.0);
    let mut limits = [0.0; 2];
    if let Some(kind) = kind {
        if j.mimic.is_some() {
            return Err(format!(
                "joint '{}' mimics another joint: it is not an independent joint (hold it still as a locked joint '{}' = a value, or end the chain before it: the chain's tip)",
                j.name, j.name
            ));
        }
        let norm = axis.norm();
        if !(norm.is_finite() && norm > 1e-9) {
            return Err(format!(
                "joint '{}': the axis {:?} is zero or not finite",
                j.name, j.axis.xyz.0
            ));
        }
        axis /= norm;
        limits = joint_limits(j, kind)?;
    }
    Ok(ChainJoint {
        name: j.name.clone(),
        kind,
        origin,
        axis,
        limits,
        source: SourceJoint {
            name: j.name.clone(),
            kind,
            origin,
            axis,
            locked: None,
        },
    })
}

/// A moving joint's limits: a continuous joint (or a revolute one without
/// limits) gets [`CONTINUOUS_RANGE`]; limits must be finite, ordered and
/// not empty.
fn joint_limits(j: &urdf_rs::Joint, kind: JointKind) -> std::result::Result<[f64; 2], String> {
    use urdf_rs::JointType as T;
    let (lo, hi) = (j.limit.lower, j.limit.upper);
    let [lo, hi] = match (j.joint_type.clone(), kind) {
        (T::Continuous, _) => CONTINUOUS_RANGE,
        (_, JointKind::Revolute) if lo == f64::NEG_INFINITY && hi == f64::INFINITY => {
            CONTINUOUS_RANGE
        }
        _ => [lo, hi],
    };
    if lo.is_nan() || hi.is_nan() || !lo.is_finite() || !hi.is_finite() {
        return Err(format!(
            "joint '{}': limits [{}, {}] are not finite",
            j.name,
            Compact(lo),
            Compact(hi)
        ));
    }
    let (l, h) = (Compact(lo), Compact(hi));
    if lo > hi {
        return Err(format!(
            "joint '{}': inverted limits [{l}, {h}] (need lower <= upper)",
            j.name
        ));
    }
    if lo == hi {
        return Err(format!(
            "joint '{}': empty range [{l}, {h}] (is <limit lower=… upper=…> missing?)",
            j.name
        ));
    }
    Ok([lo, hi])
}

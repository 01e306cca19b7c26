//! URDF import and export: a serial chain of a URDF file converted into the
//! DH/Hayati frames of a [`Robot`], and a robot written as URDF.
//!
//! **Import.** The chain runs from the URDF's root link (the measurement
//! frame) to a tip link (the measured point, or frame for full poses).
//! Revolute and continuous joints become revolute joints (a continuous joint
//! gets the range [`CONTINUOUS_RANGE`]), prismatic joints prismatic ones,
//! fixed joints are folded into their neighbours; floating,
//! planar, spherical and mimic joints are refused. Only links (their names)
//! and joints are read: visual, collision, inertial and other elements are
//! ignored, incomplete ones included. With every joint at 0,
//! each joint axis is a line in the root frame; the frames map one axis line
//! to the next:
//!
//! * a fixed `base` frame maps the root frame to joint 1's axis (DH). When
//!   the root z axis is nearly parallel to that axis — where a single DH or
//!   Hayati frame would be singular if the two coincide — a fixed DH frame
//!   `m` = `Rx(−π/2)` with no unknowns first turns z into the root's y axis;
//! * the frame driven by joint k maps its axis to the axis of joint k + 1:
//!   a DH frame (its x axis along the cross product of the two axes, so
//!   that a short common normal loses no precision), or a Hayati frame
//!   (d = 0) when the two axes are nearly
//!   parallel, i.e. the angle between them (or their negatives) is below
//!   [`UrdfOptions::parallel_threshold`], default [`PARALLEL_THRESHOLD`] =
//!   10°. Below 10°, DH's d and γ are more than 1/sin 10° ≈ 5.8 times as
//!   sensitive to an axis misalignment as the misalignment itself, and grow
//!   without bound as the axes become parallel; above it, Hayati's
//!   sensitivity 1/cos of the angle is below 1.02, so 10° keeps both well
//!   conditioned;
//! * the last joint frame maps its axis to a line through the tip: the tip's
//!   z axis, or its x axis when z is nearly parallel to the last joint axis
//!   (so that this frame is always DH and non-singular), and a fixed Hayati
//!   frame `tool` rotates about and slides along that line and turns to the
//!   tip's orientation.
//!
//! Each joint frame is labelled with its (sanitised) URDF joint name. The
//! transforms are computed in closed form from the axis lines and then
//! composed with exactly the kinematics of [`crate::kinematics`], so the
//! imported nominal model reproduces the URDF's forward kinematics to
//! rounding (tests/robots.rs checks it against a direct URDF evaluation).
//!
//! The unknowns are chosen by [`Robot::choose_unknowns`] (the `m` frame last,
//! so it keeps none) and checked by [`Robot::check_identifiable`]: for a
//! generic chain `4R + 2P + 3` for points and `4R + 2P + 6` for poses. The
//! nominal table is the URDF; the real one is the nominal one with
//! [`crate::model::catalogue::perturbation`] added to every unknown (unless
//! [`UrdfOptions::perturb_real`] is false), so that calibration has something
//! to find.
//!
//! Special geometries have fewer identifiable unknowns, and the chooser
//! simply finds the smaller set: a tip on the last joint axis (the last
//! joint's offset does not move it), or two consecutive revolute joints on
//! one axis line (none of our frame types translates along y, so the second
//! axis's lateral offset has no parameter).
//!
//! **Export.** [`to_urdf`] writes the chain of [`crate::kinematics::joint_chain`]:
//! one URDF joint per robot joint about (or along) z of its placement, and a
//! fixed joint `tool` to the link `tip`. `fixtures/puma560.urdf` is the
//! paper's nominal PUMA written this way.

use crate::error::{Compact, Error, Result};
use crate::kinematics::joint_chain;
use crate::model::catalogue::perturbed;
use crate::model::source::{SourceJoint, UrdfSource};
use crate::model::{
    Convention, Frame, JointKind, MeasurementKind, ParamId, ParamTable, Robot, frame_transform,
};
use nalgebra::{Isometry3, Rotation3, Translation3, UnitQuaternion, Vector3};
use std::collections::HashMap;
use std::f64::consts::{FRAC_PI_2, PI};
use std::path::Path;

/// Default angle (radians) below which two consecutive joint axes count as
/// nearly parallel and get a Hayati frame: 10°.
pub const PARALLEL_THRESHOLD: f64 = 10.0 * PI / 180.0;

/// Range given to a continuous joint (and to a revolute joint whose URDF
/// limits are infinite): ±170°. A lattice over ±180° would repeat its end
/// poses (−180° and 180° are one pose), and with 3 levels see only two
/// angles of the joint.
pub const CONTINUOUS_RANGE: [f64; 2] = [-170.0 * PI / 180.0, 170.0 * PI / 180.0];

/// How to import a URDF.
#[derive(Clone, Debug, PartialEq)]
pub struct UrdfOptions {
    /// The base link: the measurement frame's end of the chain (the sensor
    /// measures in the base's frame up to the unknown base transform).
    /// Default: the URDF's root link.
    pub base: Option<String>,
    /// The tip link (measured point or frame). Default: the end of the chain
    /// when the tree below the base has a single leaf; required when it
    /// branches (the error lists the candidate tips). A chain whose last
    /// moving joint looks like a gripper's (mimic, finger or jaw, a short
    /// prismatic end joint) is refused unless the tip is named.
    pub tip: Option<String>,
    /// Joints made fixed at a value (radians or metres): `(name, value)`.
    /// Each must be a moving joint of the chain.
    pub lock: Vec<(String, f64)>,
    /// Point (default) or full-pose measurements.
    pub measurement: MeasurementKind,
    /// Angle in radians below which consecutive axes are nearly parallel
    /// (Hayati frame). Default [`PARALLEL_THRESHOLD`].
    pub parallel_threshold: f64,
    /// The measurement frame to mount the chain in: measurement frame → base
    /// link (identity: the base link is the measurement frame). A frames
    /// file's `measurement_frame`.
    pub mount: Isometry3<f64>,
    /// The tool: tip link → measured frame (identity: the tip link's origin
    /// and axes are measured). A frames file's `tool`.
    pub tool: Isometry3<f64>,
    /// Make the real table the nominal one plus the built-in arms'
    /// deterministic perturbation of every unknown (default true); if false
    /// the real robot is the URDF.
    pub perturb_real: bool,
}

impl Default for UrdfOptions {
    fn default() -> Self {
        Self {
            base: None,
            tip: None,
            lock: Vec::new(),
            measurement: MeasurementKind::Point,
            parallel_threshold: PARALLEL_THRESHOLD,
            mount: Isometry3::identity(),
            tool: Isometry3::identity(),
            perturb_real: true,
        }
    }
}

/// Reads a URDF file and converts its chain (see the module docs).
pub fn load(path: &Path, opts: &UrdfOptions) -> Result<Robot> {
    let text = std::fs::read_to_string(path).map_err(|cause| Error::Io {
        path: path.display().to_string(),
        cause,
    })?;
    parse(&text, &path.display().to_string(), opts)
}

/// The moving joints of the chain `opts` chooses in a URDF file, in the
/// order of a configuration's values (locked joints left out), and the
/// chain's base link.
pub fn chain_joints(path: &Path, opts: &UrdfOptions) -> Result<(Vec<String>, String)> {
    let origin = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|cause| Error::Io {
        path: origin.clone(),
        cause,
    })?;
    let bad = |message: String| Error::Parse {
        path: origin.clone(),
        message,
    };
    let urdf = kinematic_part(&text)
        .and_then(|k| urdf_rs::read_from_string(&k).map_err(|e| e.to_string()))
        .map_err(|e| bad(format!("not a valid URDF: {e}")))?;
    let chain =
        extract_chain(&urdf, opts.base.as_deref(), opts.tip.as_deref(), &opts.lock).map_err(bad)?;
    let names = chain
        .iter()
        .filter(|j| j.kind.is_some())
        .map(|j| j.name.clone())
        .collect();
    // The base link: the parent of the chain's first joint.
    let base = chain
        .first()
        .and_then(|j| urdf.joints.iter().find(|u| u.name == j.name))
        .map(|u| u.parent.link.clone())
        .unwrap_or_default();
    Ok((names, base))
}

/// Parses URDF text and converts its chain; `origin` names it in errors and
/// gives the robot's name when the URDF has none.
pub fn parse(text: &str, origin: &str, opts: &UrdfOptions) -> Result<Robot> {
    let bad = |message: String| Error::Parse {
        path: origin.to_string(),
        message,
    };
    if !(opts.parallel_threshold > 0.0 && opts.parallel_threshold < FRAC_PI_2) {
        return Err(Error::Invalid(format!(
            "parallel_threshold must be in (0, π/2), got {}",
            opts.parallel_threshold
        )));
    }
    let urdf = kinematic_part(text)
        .and_then(|k| urdf_rs::read_from_string(&k).map_err(|e| e.to_string()))
        .map_err(|e| bad(format!("not a valid URDF: {e}")))?;
    let chain =
        extract_chain(&urdf, opts.base.as_deref(), opts.tip.as_deref(), &opts.lock).map_err(bad)?;
    let name = if urdf.name.is_empty() {
        Path::new(origin)
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or("urdf")
            .to_string()
    } else {
        urdf.name.clone()
    };
    let mut robot = convert(&chain, &name, opts);
    // The aux frame `m` (if any) is frame 0 and goes last in the preference.
    let preferred: Vec<ParamId> = robot
        .candidate_unknowns()
        .into_iter()
        .filter(|u| robot.frames[u.frame].label != "m" || u.frame != 0)
        .collect();
    robot.unknowns = robot
        .choose_unknowns(&preferred)
        .map_err(|e| bad(e.to_string()))?;
    if robot.unknowns.is_empty() {
        return Err(bad("no parameter of the chain is identifiable".into()));
    }
    if opts.perturb_real {
        robot.real = perturbed(&robot.nominal, &robot.unknowns);
    }
    robot.validate().map_err(|e| bad(e.to_string()))?;
    robot.check_identifiable().map_err(|e| bad(e.to_string()))?;
    robot.source = Some(std::sync::Arc::new(source_of(
        &urdf, &chain, text, origin, opts,
    )));
    Ok(robot)
}

/// The chain as the file gives it, kept beside the model.
fn source_of(
    urdf: &urdf_rs::Robot,
    chain: &[ChainJoint],
    text: &str,
    origin: &str,
    opts: &UrdfOptions,
) -> UrdfSource {
    let link = |name: &str, parent: bool| {
        urdf.joints
            .iter()
            .find(|u| u.name == name)
            .map(|u| {
                if parent {
                    u.parent.link.clone()
                } else {
                    u.child.link.clone()
                }
            })
            .unwrap_or_default()
    };
    UrdfSource {
        path: origin.to_string(),
        text: text.to_string(),
        base: chain
            .first()
            .map_or_else(String::new, |j| link(&j.name, true)),
        tip: chain
            .last()
            .map_or_else(String::new, |j| link(&j.name, false)),
        joints: chain.iter().map(|j| j.source.clone()).collect(),
        mount: opts.mount,
        tool: opts.tool,
    }
}

/// The kinematic part of a URDF document, as text: the `<robot>` element
/// with its attributes, its `<link>` elements reduced to their names, and its
/// `<joint>` elements whole. Everything else — a link's visual, collision and
/// inertial elements, materials, Gazebo, transmission and xacro elements —
/// the chain never reads, and is dropped before `urdf_rs` checks the document
/// against its schema, so that an incomplete appearance element (iCub's and
/// Romeo's URDFs have `<texture/>` without a file name) does not make the
/// kinematics unreadable.
fn kinematic_part(text: &str) -> std::result::Result<String, String> {
    let mut robot: xml::Element = text.parse().map_err(|e| format!("{e}"))?;
    if robot.name != "robot" {
        return Err(format!("the root element is <{}>, not <robot>", robot.name));
    }
    robot.children = std::mem::take(&mut robot.children)
        .into_iter()
        .filter_map(|node| match node {
            xml::Xml::ElementNode(mut e) if e.name == "link" => {
                e.children.clear();
                Some(xml::Xml::ElementNode(e))
            }
            xml::Xml::ElementNode(e) if e.name == "joint" => Some(xml::Xml::ElementNode(e)),
            _ => None,
        })
        .collect();
    Ok(robot.to_string())
}

/// One URDF joint of the chain, fixed ones included.
#[derive(Clone, Debug)]
struct ChainJoint {
    name: String,
    /// `None` for a fixed joint.
    kind: Option<JointKind>,
    origin: Isometry3<f64>,
    /// Unit axis in the joint frame.
    axis: Vector3<f64>,
    limits: [f64; 2],
    /// The joint as the file gives it (origin and axis unfolded).
    source: SourceJoint,
}

fn iso_from_pose(p: &urdf_rs::Pose) -> Option<Isometry3<f64>> {
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

/// Most moving joints an imported chain may have (as many as a TOML
/// description's frames, [`super::robot_toml::MAX_FRAMES`]): the choice of
/// unknowns grows with the cube of the chain's length.
pub const MAX_CHAIN_JOINTS: usize = 100;

/// Links listed at most in an error message.
const LIST_AT_MOST: usize = 12;

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

fn is_moving(j: &urdf_rs::Joint) -> bool {
    use urdf_rs::JointType as T;
    matches!(j.joint_type, T::Revolute | T::Continuous | T::Prismatic)
}

/// The joints from the base link (default: the URDF's root) to the tip, in
/// order, with the locked joints made fixed at their values.
fn extract_chain(
    urdf: &urdf_rs::Robot,
    base: Option<&str>,
    tip: Option<&str>,
    lock: &[(String, f64)],
) -> std::result::Result<Vec<ChainJoint>, String> {
    let joints = &urdf.joints;
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
    // A loop: walking up from some link comes back to it. Name its joints.
    for &start in &links {
        let mut at = start;
        let mut seen: Vec<usize> = Vec::new();
        while let Some(&j) = by_child.get(at) {
            if let Some(k) = seen.iter().position(|&s| s == j) {
                let mut cycle: Vec<&str> = seen[k..]
                    .iter()
                    .rev()
                    .map(|&s| joints[s].name.as_str())
                    .collect();
                cycle.push(cycle[0]);
                return Err(format!(
                    "the joints form a loop ({}): a URDF must be a tree",
                    cycle.join(" → ")
                ));
            }
            seen.push(j);
            at = &joints[j].parent.link;
        }
    }
    let roots: Vec<&str> = links
        .iter()
        .copied()
        .filter(|l| !by_child.contains_key(l))
        .collect();
    let root = match roots.as_slice() {
        [r] => *r,
        [] => return Err("the joints form a loop: no link is the root".into()),
        many => {
            return Err(format!(
                "{} root links ({}): the URDF must be one tree",
                many.len(),
                list_names(many)
            ));
        }
    };
    let unknown_link = |what: &str, l: &str| {
        format!(
            "the {what} link '{l}' is not in the URDF{} (its links: {})",
            crate::names::did_you_mean(l, &links),
            list_names(&links)
        )
    };
    let base = match base {
        Some(b) if !links.contains(&b) => return Err(unknown_link("base", b)),
        Some(b) => b,
        None => root,
    };
    // The moving joints from `base` down to `link`, if `link` is below it.
    let path_from_base = |link: &str| -> Option<Vec<usize>> {
        let mut path = Vec::new();
        let mut at = link;
        while at != base {
            let &j = by_child.get(at)?;
            path.push(j);
            at = &joints[j].parent.link;
        }
        path.reverse();
        Some(path)
    };
    let explicit_tip = tip.is_some();
    let tip: &str = match tip {
        Some(t) if !links.contains(&t) => return Err(unknown_link("tip", t)),
        Some(t) => t,
        None => {
            // The leaves below the base, with their moving-joint counts.
            let mut leaves: Vec<(&str, usize)> = Vec::new();
            let mut stack = vec![base];
            while let Some(l) = stack.pop() {
                match children.get(l) {
                    None => {
                        // Every leaf with a joint above it; one without a
                        // moving joint is refused later with its reason.
                        if let Some(p) = path_from_base(l).filter(|p| !p.is_empty()) {
                            leaves.push((l, p.iter().filter(|&&j| is_moving(&joints[j])).count()));
                        }
                    }
                    Some(js) => stack.extend(js.iter().map(|&j| joints[j].child.link.as_str())),
                }
            }
            leaves.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(b.0)));
            match leaves.as_slice() {
                [] => {
                    return Err(format!(
                        "no revolute or prismatic joint below the base link '{base}'"
                    ));
                }
                [(l, _)] => l,
                many => {
                    let c: Vec<String> = many
                        .iter()
                        .map(|(l, n)| format!("{l} ({n} joint{})", if *n == 1 { "" } else { "s" }))
                        .collect();
                    return Err(format!(
                        "the URDF is a tree with {} branches below '{base}': choose the measured link with --tip (or `tip = \"…\"` in a description); candidate tips: {}",
                        many.len(),
                        list_names(&c)
                    ));
                }
            }
        }
    };
    let Some(path) = path_from_base(tip) else {
        return Err(format!(
            "the tip link '{tip}' is not below the base link '{base}'"
        ));
    };
    for (name, value) in lock {
        let Some(j) = joints.iter().find(|j| &j.name == name) else {
            return Err(format!(
                "--lock {name}: there is no joint '{name}' in the URDF"
            ));
        };
        if !path.iter().any(|&i| joints[i].name == *name) {
            let on: Vec<&str> = path
                .iter()
                .filter(|&&i| is_moving(&joints[i]))
                .map(|&i| joints[i].name.as_str())
                .collect();
            return Err(format!(
                "--lock {name}: the joint is not on the chain from '{base}' to '{tip}' (its joints: {})",
                list_names(&on)
            ));
        }
        if !is_moving(j) {
            return Err(format!("--lock {name}: the joint is fixed already"));
        }
        if !value.is_finite() {
            return Err(format!("--lock {name}={value}: not a finite number"));
        }
    }
    let locked = |name: &str| lock.iter().find(|(n, _)| n == name).map(|&(_, v)| v);
    let moving: Vec<usize> = path
        .iter()
        .copied()
        .filter(|&i| is_moving(&joints[i]) && locked(&joints[i].name).is_none())
        .collect();
    if moving.len() > MAX_CHAIN_JOINTS {
        return Err(format!(
            "the chain from '{base}' to '{tip}' has {} moving joints ('{}' … '{}'), more than {MAX_CHAIN_JOINTS}: choose a shorter chain with --base/--tip or lock joints",
            moving.len(),
            joints[moving[0]].name,
            joints[moving[moving.len() - 1]].name
        ));
    }
    if let Some(&last) = moving.last() {
        let j = &joints[last];
        let parent = &j.parent.link;
        if j.mimic.is_some() {
            return Err(format!(
                "joint '{}' mimics another joint (a gripper's, usually): end the chain before it with --tip {parent}, or lock it with --lock {}=0",
                j.name, j.name
            ));
        }
        if let Some(why) = gripper_reason(j).filter(|_| !explicit_tip) {
            return Err(format!(
                "the chain's last moving joint '{}' looks like a gripper's ({why}): measure the arm's flange with --tip {parent}, or keep the joint still with --lock {}=VALUE, or name this tip explicitly with --tip {tip}",
                j.name, j.name
            ));
        }
    }
    let mut out = Vec::with_capacity(path.len());
    for &i in &path {
        let j = &joints[i];
        let mut origin = iso_from_pose(&j.origin)
            .ok_or_else(|| format!("joint '{}': the origin is not finite", j.name))?;
        use urdf_rs::JointType as T;
        if let Some(v) = locked(&j.name) {
            // A locked joint is a fixed one at its value: its motion folds
            // into the origin.
            let axis = Vector3::from(j.axis.xyz.0);
            let n = axis.norm();
            if !(n.is_finite() && n > 1e-9) {
                return Err(format!(
                    "joint '{}': the axis is zero or not finite",
                    j.name
                ));
            }
            let u = nalgebra::Unit::new_normalize(axis);
            origin *= match j.joint_type {
                T::Prismatic => Isometry3::from_parts(
                    Translation3::from(u.into_inner() * v),
                    UnitQuaternion::identity(),
                ),
                _ => Isometry3::from_parts(
                    Translation3::identity(),
                    UnitQuaternion::from_axis_angle(&u, v),
                ),
            };
            out.push(ChainJoint {
                name: j.name.clone(),
                kind: None,
                origin,
                axis: Vector3::z(),
                limits: [0.0; 2],
                source: SourceJoint {
                    name: j.name.clone(),
                    kind: Some(match j.joint_type {
                        T::Prismatic => JointKind::Prismatic,
                        _ => JointKind::Revolute,
                    }),
                    origin: iso_from_pose(&j.origin).unwrap_or(origin),
                    axis: u.into_inner(),
                    locked: Some(v),
                },
            });
            continue;
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
                    "joint '{}' mimics another joint: it is not an independent joint (lock it with --lock {}=VALUE, or end the chain before it with --tip)",
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
            let (lo, hi) = (j.limit.lower, j.limit.upper);
            limits = match (j.joint_type.clone(), kind) {
                (T::Continuous, _) => CONTINUOUS_RANGE,
                (_, JointKind::Revolute) if lo == f64::NEG_INFINITY && hi == f64::INFINITY => {
                    CONTINUOUS_RANGE
                }
                _ => [lo, hi],
            };
            let [lo, hi] = limits;
            if lo.is_nan() || hi.is_nan() || !lo.is_finite() || !hi.is_finite() {
                return Err(format!(
                    "joint '{}': limits [{}, {}] are not finite",
                    j.name,
                    Compact(lo),
                    Compact(hi)
                ));
            }
            if lo > hi {
                return Err(format!(
                    "joint '{}': inverted limits [{}, {}] (need lower <= upper)",
                    j.name,
                    Compact(lo),
                    Compact(hi)
                ));
            }
            if lo == hi {
                return Err(format!(
                    "joint '{}': empty range [{}, {}] (is <limit lower=… upper=…> missing?)",
                    j.name,
                    Compact(lo),
                    Compact(hi)
                ));
            }
        }
        out.push(ChainJoint {
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
        });
    }
    if out.iter().all(|j| j.kind.is_none()) {
        return Err(format!(
            "no revolute or prismatic joint between the base '{base}' and the tip '{tip}'"
        ));
    }
    Ok(out)
}

/// The frame (convention and `[γ, α, a, d, β]`) from frame `z` (whose z axis
/// is a joint axis, or the root's) to the line through `p` along unit `u`,
/// and the frame it ends in (on the line, z along `u`).
fn to_line(
    z: &Isometry3<f64>,
    p: &Vector3<f64>,
    u: &Vector3<f64>,
    threshold: f64,
) -> (Convention, [f64; 5], Isometry3<f64>) {
    let ez = z.rotation * Vector3::z();
    let ex = z.rotation * Vector3::x();
    let o = z.translation.vector;
    let cross = ez.cross(u);
    let angle_of = |xn: &Vector3<f64>| ex.cross(xn).dot(&ez).atan2(ex.dot(xn));
    // Lengths below this (relative to the geometry's size) are zero.
    let tiny = 1e-12 * (1.0 + o.norm() + p.norm());
    let (conv, row) = if cross.norm() > threshold.sin() {
        // DH: the common normal from the z axis to the line.
        let w = o - p;
        let b = ez.dot(u);
        let (d1, e) = (ez.dot(&w), u.dot(&w));
        let den = 1.0 - b * b;
        let s1 = (b * e - d1) / den;
        let s2 = (e - b * d1) / den;
        let n = (p + u * s2) - (o + ez * s1);
        let n = n - ez * ez.dot(&n);
        // The common normal is along ez × u: its direction is taken from the
        // axes (exact to rounding, |cross| > sin threshold), its length and
        // sign from the feet. Taking the direction from `n` itself would
        // carry the rounding of the feet's coordinates divided by a short
        // normal's length (1e-16 · 1 m / 1e-7 m = 1e-9 rad for a normal of
        // 0.1 µm) into an x axis not quite perpendicular to u, and the next
        // frame's z axis would miss the joint axis by as much. A normal at
        // rounding level (axes that intersect, up to `tiny`) keeps x along
        // ez × u and its signed length, which may be negative: its absolute
        // value along x would put the foot on the wrong side, off by twice
        // the normal.
        let c = cross.normalize();
        let (xn, a) = if n.norm() > tiny {
            let xn = if n.dot(&c) >= 0.0 { c } else { -c };
            (xn, n.dot(&xn))
        } else {
            (c, n.dot(&c))
        };
        let alpha = cross.dot(&xn).atan2(ez.dot(u));
        (Convention::Dh, [angle_of(&xn), alpha, a, s1, 0.0])
    } else {
        // Hayati: through the line's intersection with the plane ⟂ z at o.
        let s2 = (o - p).dot(&ez) / u.dot(&ez);
        let n = p + u * s2 - o;
        let n = n - ez * ez.dot(&n);
        let a = n.norm();
        let xn = if a > tiny { n / a } else { ex };
        let yn = ez.cross(&xn);
        let (ux, uy, uz) = (u.dot(&xn), u.dot(&yn), u.dot(&ez));
        let beta = ux.atan2((uy * uy + uz * uz).sqrt());
        let alpha = (-uy).atan2(uz);
        (Convention::Hayati, [angle_of(&xn), alpha, a, 0.0, beta])
    };
    let next = z * frame_transform(conv, &row);
    (conv, row, next)
}

/// `R = Rz(γ) Rx(α) Ry(β)` → `(γ, α, β)`.
fn zxy_angles(r: &Rotation3<f64>) -> (f64, f64, f64) {
    let m = r.matrix();
    let alpha = m[(2, 1)].atan2((m[(2, 0)].powi(2) + m[(2, 2)].powi(2)).sqrt());
    let gamma = (-m[(0, 1)]).atan2(m[(1, 1)]);
    let beta = (-m[(2, 0)]).atan2(m[(2, 2)]);
    (gamma, alpha, beta)
}

/// A frame label from a URDF joint name: characters other than ASCII
/// letters, digits, `_`, `-` and `.` become `_`; unique among `used`.
fn label_for(name: &str, k: usize, used: &[String]) -> String {
    let mut l: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.') {
                c
            } else {
                '_'
            }
        })
        .collect();
    if l.is_empty() {
        l = format!("j{}", k + 1);
    }
    while used.contains(&l) {
        l.push('_');
    }
    l
}

/// Converts the chain into frames (nominal = URDF; real = nominal, unknowns
/// empty: the caller fills them).
fn convert(chain: &[ChainJoint], name: &str, opts: &UrdfOptions) -> Robot {
    let thr = opts.parallel_threshold;
    // Axis lines and the tip at q = 0, in the measurement frame.
    let mut t = opts.mount;
    let mut lines = Vec::new();
    for j in chain {
        t *= j.origin;
        if let Some(kind) = j.kind {
            lines.push((t.translation.vector, t.rotation * j.axis, kind, j));
        }
    }
    let tip = t * opts.tool;
    let mut frames: Vec<Frame> = Vec::new();
    let mut rows: Vec<[f64; 5]> = Vec::new();
    let mut limits = Vec::new();
    let mut labels: Vec<String> = Vec::new();
    let mut z = Isometry3::identity();
    let (p1, u1) = (lines[0].0, lines[0].1);
    if Vector3::z().cross(&u1).norm() <= thr.sin() {
        let row = [0.0, -FRAC_PI_2, 0.0, 0.0, 0.0];
        z *= frame_transform(Convention::Dh, &row);
        frames.push(Frame::fixed("m", Convention::Dh));
        rows.push(row);
        labels.push("m".into());
    }
    let (conv, row, next) = to_line(&z, &p1, &u1, thr);
    frames.push(Frame::fixed("base", conv));
    rows.push(row);
    labels.push("base".into());
    z = next;
    let n = lines.len();
    for (k, &(_, _, kind, j)) in lines.iter().enumerate() {
        let (p, u) = if k + 1 < n {
            (lines[k + 1].0, lines[k + 1].1)
        } else {
            let tz = tip.rotation * Vector3::z();
            let dir = if lines[k].1.cross(&tz).norm() > thr.sin() {
                tz
            } else {
                tip.rotation * Vector3::x()
            };
            (tip.translation.vector, dir)
        };
        let (conv, row, next) = to_line(&z, &p, &u, thr);
        let label = label_for(&j.name, k, &labels);
        frames.push(Frame::driven(&label, conv, k, kind));
        rows.push(row);
        labels.push(label);
        limits.push(j.limits);
        z = next;
    }
    // The tool: from the last frame (z along a line through the tip) to the tip.
    let rel = z.inverse() * tip;
    let (gamma, alpha, beta) = zxy_angles(&rel.rotation.to_rotation_matrix());
    let label = label_for("tool", n, &labels);
    frames.push(Frame::fixed(&label, Convention::Hayati));
    rows.push([gamma, alpha, 0.0, rel.translation.vector.z, beta]);
    let nominal = ParamTable::from_rows(rows);
    Robot {
        name: name.to_string(),
        frames,
        real: nominal.clone(),
        nominal,
        unknowns: Vec::new(),
        limits,
        measurement: opts.measurement,
        orientation_scale: crate::model::DEFAULT_ORIENTATION_SCALE,
        source: None,
        gravity: None,
    }
}

pub use crate::model::source::rpy;

/// Writes the robot with parameter table `table` as URDF: root link
/// `measurement`, links `link1…linkN`, joints `q1…qN` (revolute or prismatic
/// about z of their origin, limits from [`Robot::limits`]) and a fixed joint
/// `tool` to the link `tip`. Numbers are the shortest decimals that
/// round-trip. Errors if the joints do not drive frames in increasing order.
pub fn to_urdf(robot: &Robot, table: &ParamTable) -> Result<String> {
    let order: Vec<usize> = robot.frames.iter().filter_map(|f| f.joint).collect();
    if order.iter().enumerate().any(|(k, &j)| k != j) {
        return Err(Error::Invalid(format!(
            "robot {}: joints must drive frames in increasing order to be written as URDF",
            robot.name
        )));
    }
    let ch = joint_chain(robot, table);
    let origin = |t: &Isometry3<f64>| {
        let v = t.translation.vector;
        let r = rpy(&t.rotation.to_rotation_matrix());
        format!(
            "<origin xyz=\"{:?} {:?} {:?}\" rpy=\"{:?} {:?} {:?}\"/>",
            v.x, v.y, v.z, r[0], r[1], r[2]
        )
    };
    let n = robot.dof();
    let link = |k: usize| {
        if k == 0 {
            "measurement".to_string()
        } else {
            format!("link{k}")
        }
    };
    let mut s = String::new();
    s += "<?xml version=\"1.0\"?>\n";
    s += &format!(
        "<!-- {} ({:?} parameters) written by activecal::urdf::to_urdf -->\n",
        robot.name,
        if std::ptr::eq(table, &robot.nominal) {
            "nominal"
        } else if std::ptr::eq(table, &robot.real) {
            "real"
        } else {
            "given"
        }
    );
    s += &format!("<robot name=\"{}\">\n", xml_escape(&robot.name));
    for k in 0..=n {
        s += &format!("  <link name=\"{}\"/>\n", link(k));
    }
    s += "  <link name=\"tip\"/>\n";
    for k in 0..n {
        let kind = match ch.kinds[k] {
            JointKind::Revolute => "revolute",
            JointKind::Prismatic => "prismatic",
        };
        let [lo, hi] = robot.limits[k];
        s += &format!("  <joint name=\"q{}\" type=\"{kind}\">\n", k + 1);
        s += &format!("    <parent link=\"{}\"/>\n", link(k));
        s += &format!("    <child link=\"{}\"/>\n", link(k + 1));
        s += &format!("    {}\n", origin(&ch.placements[k]));
        s += "    <axis xyz=\"0 0 1\"/>\n";
        s += &format!(
            "    <limit lower=\"{lo:?}\" upper=\"{hi:?}\" effort=\"0\" velocity=\"0\"/>\n"
        );
        s += "  </joint>\n";
    }
    s += "  <joint name=\"tool\" type=\"fixed\">\n";
    s += &format!("    <parent link=\"{}\"/>\n", link(n));
    s += "    <child link=\"tip\"/>\n";
    s += &format!("    {}\n", origin(&ch.tool));
    s += "  </joint>\n";
    s += "</robot>\n";
    Ok(s)
}

fn xml_escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// `robot` (imported from a URDF) imported again from the same text and
/// chain, mounted with measurement frame `mount` and tool `tool`: its
/// frames, tables and unknowns follow the new mount; its name, sensor and
/// marker offsets are kept. Errors for a robot without a URDF source.
pub fn remount(robot: &Robot, mount: Isometry3<f64>, tool: Isometry3<f64>) -> Result<Robot> {
    let src = robot.source.as_ref().ok_or_else(|| {
        Error::Invalid(format!(
            "robot '{}' was not imported from a URDF: it cannot be mounted in another frame",
            robot.name
        ))
    })?;
    let lock = src
        .joints
        .iter()
        .filter_map(|j| j.locked.map(|v| (j.name.clone(), v)))
        .collect();
    let kind = match robot.measurement {
        MeasurementKind::Markers(_) => MeasurementKind::Point,
        k => k,
    };
    let opts = UrdfOptions {
        base: Some(src.base.clone()),
        tip: Some(src.tip.clone()),
        lock,
        measurement: kind,
        mount,
        tool,
        ..UrdfOptions::default()
    };
    let mut r = parse(&src.text, &src.path, &opts)?;
    r.name = robot.name.clone();
    r.orientation_scale = robot.orientation_scale;
    if let MeasurementKind::Markers(_) = robot.measurement {
        r = r.with_markers(&robot.nominal.markers)?;
    }
    Ok(r)
}

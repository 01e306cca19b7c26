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

pub use super::urdf_chain::{CONTINUOUS_RANGE, MAX_CHAIN_JOINTS};
use super::urdf_chain::{ChainJoint, extract_chain};
use crate::error::{Error, Result};
use crate::kinematics::joint_chain;
use crate::model::catalogue::perturbed;
use crate::model::source::UrdfSource;
use crate::model::{
    Convention, Frame, JointKind, MeasurementKind, ParamId, ParamTable, Robot, frame_transform,
};
use nalgebra::{Isometry3, Rotation3, Vector3};
use std::f64::consts::{FRAC_PI_2, PI};
use std::path::Path;

/// Default angle (radians) below which two consecutive joint axes count as
/// nearly parallel and get a Hayati frame: 10°.
pub const PARALLEL_THRESHOLD: f64 = 10.0 * PI / 180.0;

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
    let text = crate::io::read::read_text(path)?;
    parse(&text, &path.display().to_string(), opts)
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
    let urdf = parsed(text).map_err(bad)?;
    from_parsed(&urdf, text, origin, opts)
}

/// The kinematic part of URDF text parsed (see [`kinematic_part`]).
pub(super) fn parsed(text: &str) -> std::result::Result<urdf_rs::Robot, String> {
    kinematic_part(text)
        .and_then(|k| urdf_rs::read_from_string(&k).map_err(|e| e.to_string()))
        .map_err(|e| format!("not a valid URDF: {e}"))
}

/// [`parse`] of a parsed URDF `urdf`, whose file text `text` the robot
/// keeps as its source (the text a calibrated URDF edits).
pub(super) fn from_parsed(
    urdf: &urdf_rs::Robot,
    text: &str,
    origin: &str,
    opts: &UrdfOptions,
) -> Result<Robot> {
    let bad = |message: String| Error::Parse {
        path: origin.to_string(),
        message,
    };
    let chain =
        extract_chain(urdf, opts.base.as_deref(), opts.tip.as_deref(), &opts.lock).map_err(bad)?;
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
        urdf, &chain, text, origin, opts,
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
        reversed: Vec::new(),
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
    // Markers are the tool point's chain with their offsets added after
    // parsing: what the sensor records of the tool says which.
    let markers =
        crate::measure::sensor_for(robot).tool_record() == crate::measure::ToolRecord::Markers;
    let kind = if markers {
        MeasurementKind::Point
    } else {
        robot.measurement
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
    if markers {
        r = r.with_markers(&robot.nominal.markers)?;
    }
    Ok(r)
}

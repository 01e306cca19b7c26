//! Joint origins as the YAML files that xacro descriptions read:
//!
//! * **Universal Robots' `default_kinematics.yaml`** (read by
//!   `ur_description`'s `ur_common.xacro` with `xacro.load_yaml`, written
//!   by `ur_calibration` from a robot's factory data): under `kinematics:`,
//!   one block per joint — `shoulder` (`shoulder_pan_joint`), `upper_arm`
//!   (`shoulder_lift_joint`), `forearm` (`elbow_joint`), `wrist_1`,
//!   `wrist_2`, `wrist_3` (`wrist_K_joint`) — with `x y z` (metres) and
//!   `roll pitch yaw` (radians) of the joint's `<origin>`, and a `hash`;
//! * **per-joint origins** (any robot): `JOINT: {xyz: [x, y, z], rpy: [r,
//!   p, y]}` for each driven joint of the chain, metres and radians.
//!
//! Both hold exactly the URDF joint `<origin>`s (rpy as URDF reads them:
//! `R = Rz(yaw) Ry(pitch) Rx(roll)`), numbers as the shortest decimals
//! that read back to the same `f64`. Read back ([`read`], [`with_file`]),
//! a file's origins replace those of the URDF it was written for, so a user
//! can start from a factory file.

use crate::error::{Error, Result};
use crate::model::source::rpy;
use nalgebra::{Isometry3, Translation3, UnitQuaternion};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

/// Universal Robots' keys and the joints they hold, in chain order.
pub const UR_KEYS: [(&str, &str); 6] = [
    ("shoulder", "shoulder_pan_joint"),
    ("upper_arm", "shoulder_lift_joint"),
    ("forearm", "elbow_joint"),
    ("wrist_1", "wrist_1_joint"),
    ("wrist_2", "wrist_2_joint"),
    ("wrist_3", "wrist_3_joint"),
];

/// A file's origin of a joint this far (radians) from the URDF's is taken
/// as a file written for another description, not a calibration of this
/// one: a calibration turns an origin by a fraction of a degree (a factory
/// file's zero offsets included), while the two UR conventions
/// (ROS-Industrial's joint axes along y, Universal Robots' along z) differ
/// by a quarter turn or more at `shoulder_lift_joint`.
pub const FOREIGN_TURN_RAD: f64 = 0.5;

/// The two layouts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Layout {
    /// Universal Robots' `kinematics:` file.
    UrKinematics,
    /// `JOINT: {xyz, rpy}` per joint.
    JointOrigins,
}

/// Joint origins read from a file.
#[derive(Clone, Debug)]
pub struct KinematicsFile {
    /// Its path, for messages.
    pub path: String,
    /// Its layout.
    pub layout: Layout,
    /// Each joint's origin, by the name the file gives (for a UR file, the
    /// joint a key holds, without a prefix).
    pub origins: Vec<(String, Isometry3<f64>)>,
    /// A UR file's `hash`.
    pub hash: Option<String>,
}

/// A number as the shortest decimal that reads back to the same `f64`
/// (never in exponent form, which YAML 1.1 readers such as PyYAML would
/// take for a string).
fn num(v: f64) -> String {
    if v == 0.0 { "0".into() } else { format!("{v}") }
}

/// The joint of `origins` that UR key `joint` names: the one of that name,
/// or the only one ending in `_NAME`/`NAME` after a prefix (`tf_prefix`).
fn ur_joint<'a>(
    origins: &'a [(String, Isometry3<f64>)],
    joint: &str,
) -> Option<&'a (String, Isometry3<f64>)> {
    if let Some(o) = origins.iter().find(|(n, _)| n == joint) {
        return Some(o);
    }
    let mut hits = origins.iter().filter(|(n, _)| n.ends_with(joint));
    match (hits.next(), hits.next()) {
        (Some(o), None) => Some(o),
        _ => None,
    }
}

/// A hash for a written UR file: `activecal_` and 16 hex digits of the
/// FNV-1a hash of its values. Universal Robots' driver compares the file's
/// hash with the controller's calibration checksum and logs when they
/// differ — as they must: the file is not the controller's own model.
fn content_hash(values: &str) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in values.bytes() {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    format!("activecal_{h:016x}")
}

/// Universal Robots' `default_kinematics.yaml` of the driven joints'
/// `origins` (metres, radians; the URDF's joint names, a `tf_prefix`
/// allowed). `robot` names the robot in the header. Errors when a UR joint
/// is missing or the chain drives a joint the file cannot hold.
pub fn ur_kinematics(robot: &str, origins: &[(String, Isometry3<f64>)]) -> Result<String> {
    let mut body = String::new();
    let mut used = Vec::new();
    for (key, joint) in UR_KEYS {
        let Some((name, t)) = ur_joint(origins, joint) else {
            let names: Vec<&str> = origins.iter().map(|(n, _)| n.as_str()).collect();
            return Err(Error::Invalid(format!(
                "robot '{robot}': Universal Robots' kinematics file holds the origins of shoulder_pan_joint, shoulder_lift_joint, elbow_joint and wrist_1/2/3_joint; the chain has no joint '{joint}' (its driven joints: {}); write the per-joint origins file instead",
                names.join(", ")
            )));
        };
        used.push(name.as_str());
        let v = t.translation.vector;
        let r = rpy(&t.rotation.to_rotation_matrix());
        let _ = write!(
            body,
            "  {key}:\n    x: {}\n    y: {}\n    z: {}\n    roll: {}\n    pitch: {}\n    yaw: {}\n",
            num(v.x),
            num(v.y),
            num(v.z),
            num(r[0]),
            num(r[1]),
            num(r[2])
        );
    }
    if let Some((extra, _)) = origins.iter().find(|(n, _)| !used.contains(&n.as_str())) {
        return Err(Error::Invalid(format!(
            "robot '{robot}': the chain drives joint '{extra}', which Universal Robots' kinematics file cannot hold; write the per-joint origins file instead"
        )));
    }
    let hash = content_hash(&body);
    Ok(format!(
        "# Calibrated joint origins of robot '{robot}' written by activecal, in the\n# layout of Universal Robots' default_kinematics.yaml (ur_description reads it\n# with xacro.load_yaml). Units: metres (x, y, z) and radians (roll, pitch, yaw),\n# each joint's URDF <origin>, R = Rz(yaw) Ry(pitch) Rx(roll). The measurement\n# frame and the tool are not in this file (see the frames file).\n# hash: made from these values; the driver logs that it differs from the\n# controller's factory checksum, as it does: this is not the factory model.\nkinematics:\n{body}  hash: {hash}\n"
    ))
}

/// The per-joint origins file of `origins` (metres, radians), headed by
/// the robot's name.
#[must_use]
pub fn joint_origins(robot: &str, origins: &[(String, Isometry3<f64>)]) -> String {
    let mut out = format!(
        "# Calibrated joint origins of robot '{robot}' written by activecal: each\n# driven joint's URDF <origin>, xyz in metres, rpy in radians\n# (R = Rz(yaw) Ry(pitch) Rx(roll)). A xacro description reads them with\n# ${{xacro.load_yaml(FILE)['JOINT']['xyz'][0]}} and so on.\n"
    );
    for (name, t) in origins {
        let v = t.translation.vector;
        let r = rpy(&t.rotation.to_rotation_matrix());
        let _ = writeln!(
            out,
            "{name}:\n  xyz: [{}, {}, {}]\n  rpy: [{}, {}, {}]",
            num(v.x),
            num(v.y),
            num(v.z),
            num(r[0]),
            num(r[1]),
            num(r[2])
        );
    }
    out
}

/// How a driver takes joint zero offsets: in degrees or radians, added to
/// the encoder's reading or subtracted from it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct OffsetConvention {
    /// Revolute offsets in degrees (else radians; prismatic ones are
    /// always metres).
    pub degrees: bool,
    /// The driver subtracts its offset from the reading (`q = q_encoder −
    /// offset`); else it adds it (`q = q_encoder + offset`).
    pub subtract: bool,
}

/// The joint zero offsets of a calibration, `(joint, offset, revolute)` in
/// radians or metres with the sign `q = q_encoder + offset` (the
/// calibrated model at reading `q_encoder` is the file's at `q`), as a
/// driver named by `c` takes them.
#[must_use]
pub fn joint_offsets(robot: &str, joints: &[(String, f64, bool)], c: OffsetConvention) -> String {
    let unit = if c.degrees { "deg" } else { "rad" };
    let (sign, rule) = if c.subtract {
        ("subtract", "q = q_encoder - offset")
    } else {
        ("add", "q = q_encoder + offset")
    };
    let mut out = format!(
        "# Joint zero offsets of robot '{robot}' written by activecal, for a driver that\n# takes them as {rule} (q: the joint value of the robot's description).\n# Revolute joints in {}, prismatic ones in metres. The first and the last\n# joint's offsets are not told apart from the measurement frame and the tool:\n# they are in the frames file, and read 0 here.\nunit: {unit}\nsign: {sign}\noffsets:\n",
        if c.degrees { "degrees" } else { "radians" }
    );
    for (name, v, revolute) in joints {
        let mut v = if c.subtract { -v } else { *v };
        if *revolute && c.degrees {
            v = v.to_degrees();
        }
        let _ = writeln!(out, "  {name}: {}", num(v));
    }
    out
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct UrOrigin {
    x: f64,
    y: f64,
    z: f64,
    roll: f64,
    pitch: f64,
    yaw: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct UrBlock {
    shoulder: UrOrigin,
    upper_arm: UrOrigin,
    forearm: UrOrigin,
    wrist_1: UrOrigin,
    wrist_2: UrOrigin,
    wrist_3: UrOrigin,
    hash: Option<String>,
}

#[derive(Deserialize)]
struct UrFile {
    kinematics: UrBlock,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct OriginEntry {
    xyz: [f64; 3],
    rpy: [f64; 3],
}

fn iso(xyz: [f64; 3], rpy: [f64; 3]) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::new(xyz[0], xyz[1], xyz[2]),
        UnitQuaternion::from_euler_angles(rpy[0], rpy[1], rpy[2]),
    )
}

/// A YAML or schema error as `line L, column C: what`.
fn yaml_error(layout: &str, e: &serde_saphyr::Error) -> String {
    let what = e.without_snippet().to_string();
    let what = what.trim_start_matches("error: ").to_string();
    match e.location() {
        Some(l) if !what.contains("line ") => format!(
            "not {layout} (line {}, column {}): {what}",
            l.line(),
            l.column()
        ),
        _ => format!("not {layout}: {what}"),
    }
}

/// Reads a kinematics file of either layout: a top-level `kinematics:`
/// block is Universal Robots', anything else per-joint origins.
pub fn read(path: &Path) -> Result<KinematicsFile> {
    let text = crate::io::read::read_text(path)?;
    parse(&text, &path.display().to_string())
}

/// Parses a kinematics file's text (`origin` names it in errors).
pub fn parse(text: &str, origin: &str) -> Result<KinematicsFile> {
    let bad = |message: String| Error::Parse {
        path: origin.to_string(),
        message,
    };
    let top: BTreeMap<String, serde::de::IgnoredAny> = serde_saphyr::from_str(text)
        .map_err(|e| bad(yaml_error("a kinematics file (YAML mapping)", &e)))?;
    if top.is_empty() {
        return Err(bad(
            "no joint origins: expected Universal Robots' 'kinematics:' block or 'JOINT: {xyz: [..], rpy: [..]}' entries".into(),
        ));
    }
    let finite = |origins: &[(String, Isometry3<f64>)]| -> Result<()> {
        match origins
            .iter()
            .find(|(_, t)| !t.to_homogeneous().iter().all(|v| v.is_finite()))
        {
            Some((n, _)) => Err(bad(format!("{n}: a value is not a finite number"))),
            None => Ok(()),
        }
    };
    if top.contains_key("kinematics") {
        let f: UrFile = serde_saphyr::from_str(text).map_err(|e| {
            bad(yaml_error(
                "Universal Robots' kinematics file (kinematics: shoulder, upper_arm, forearm, wrist_1, wrist_2, wrist_3 with x y z roll pitch yaw, and hash)",
                &e,
            ))
        })?;
        let k = f.kinematics;
        let blocks = [
            &k.shoulder,
            &k.upper_arm,
            &k.forearm,
            &k.wrist_1,
            &k.wrist_2,
            &k.wrist_3,
        ];
        let origins: Vec<(String, Isometry3<f64>)> = UR_KEYS
            .iter()
            .zip(blocks)
            .map(|((_, j), o)| {
                (
                    (*j).to_string(),
                    iso([o.x, o.y, o.z], [o.roll, o.pitch, o.yaw]),
                )
            })
            .collect();
        finite(&origins)?;
        return Ok(KinematicsFile {
            path: origin.to_string(),
            layout: Layout::UrKinematics,
            origins,
            hash: k.hash,
        });
    }
    let entries: Vec<(String, OriginEntry)> =
        serde_saphyr::from_str::<BTreeMap<String, OriginEntry>>(text)
            .map_err(|e| {
                bad(yaml_error(
                    "a per-joint origins file (JOINT: {xyz: [x, y, z], rpy: [roll, pitch, yaw]})",
                    &e,
                ))
            })?
            .into_iter()
            .collect();
    let origins: Vec<(String, Isometry3<f64>)> = entries
        .into_iter()
        .map(|(n, e)| (n, iso(e.xyz, e.rpy)))
        .collect();
    finite(&origins)?;
    Ok(KinematicsFile {
        path: origin.to_string(),
        layout: Layout::JointOrigins,
        origins,
        hash: None,
    })
}

/// The joints of URDF `text` (by name) and their origins (identity when
/// the joint has none).
fn urdf_origins(text: &str, path: &str) -> Result<Vec<(String, Isometry3<f64>)>> {
    let opts = roxmltree::ParsingOptions {
        allow_dtd: true,
        ..roxmltree::ParsingOptions::default()
    };
    let doc = roxmltree::Document::parse_with_options(text, opts).map_err(|e| Error::Parse {
        path: path.to_string(),
        message: format!("not XML: {e}"),
    })?;
    let three = |o: Option<roxmltree::Node<'_, '_>>, a: &str| -> [f64; 3] {
        let mut v = [0.0; 3];
        if let Some(s) = o.and_then(|o| o.attribute(a)) {
            for (x, t) in v.iter_mut().zip(s.split_whitespace()) {
                *x = t.parse().unwrap_or(f64::NAN);
            }
        }
        v
    };
    Ok(doc
        .root_element()
        .children()
        .filter(|c| c.is_element() && c.tag_name().name() == "joint")
        .filter_map(|j| {
            let o = j
                .children()
                .find(|c| c.is_element() && c.tag_name().name() == "origin");
            j.attribute("name")
                .map(|n| (n.to_string(), iso(three(o, "xyz"), three(o, "rpy"))))
        })
        .collect())
}

/// URDF `text` (from `urdf_path`) with the origins of kinematics file
/// `file` in place of its joints' (see [`super::urdf_edit`]). A UR file's
/// joints may carry a prefix (`tf_prefix`). Errors name the file and the
/// joint when a joint is not in the URDF, or when a file's origin turns
/// more than [`FOREIGN_TURN_RAD`] from the URDF's (a file written for
/// another description).
pub fn with_file(text: &str, urdf_path: &str, file: &KinematicsFile) -> Result<String> {
    let have = urdf_origins(text, urdf_path)?;
    let mut edits = Vec::new();
    for (joint, t) in &file.origins {
        let found = match file.layout {
            Layout::UrKinematics => ur_joint(&have, joint),
            Layout::JointOrigins => have.iter().find(|(n, _)| n == joint),
        };
        let Some((name, nominal)) = found else {
            return Err(Error::Parse {
                path: file.path.clone(),
                message: format!("joint '{joint}' is not a joint of {urdf_path}"),
            });
        };
        let turn = nominal.rotation.angle_to(&t.rotation);
        if turn > FOREIGN_TURN_RAD {
            return Err(Error::Parse {
                path: file.path.clone(),
                message: format!(
                    "joint '{name}': the file's origin is turned {:.1}° from that of {urdf_path}; the file was written for another description of the robot (Universal Robots' ur_description and ROS-Industrial's place their joint axes differently)",
                    turn.to_degrees()
                ),
            });
        }
        edits.push((name.clone(), *t));
    }
    super::urdf_edit::with_origins(text, urdf_path, &edits)
}

#[cfg(test)]
mod tests;

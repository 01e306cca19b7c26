//! The frames file (`cal.yaml`) read back: a calibration's measurement
//! frame, tool or markers and joint origins (written by
//! [`crate::write::frames`]), to mount a (calibrated) URDF in the sensor's
//! frame with its tool.
//!
//! Written and read with `serde_saphyr` (pure Rust, maintained, panic-free),
//! the crate design files use too.

use crate::error::{Error, Result};
use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion, Vector3};
use serde::Deserialize;
use serde::de::IgnoredAny;
use serde_saphyr::Spanned;
use std::collections::HashMap;
use std::path::Path;

/// Numbers with the place they were read from.
type Numbers = Spanned<Vec<f64>>;

#[derive(Deserialize)]
struct FrameEntry {
    parent: Option<Spanned<String>>,
    xyz: Option<Numbers>,
    rpy: Option<Numbers>,
    rpy_deg: Option<Numbers>,
    quaternion: Option<Numbers>,
}

#[derive(Deserialize)]
struct MarkerEntry {
    parent: Option<Spanned<String>>,
    xyz: Option<Numbers>,
}

#[derive(Deserialize)]
struct ChainEntry {
    base: Option<Spanned<String>>,
    tip: Option<Spanned<String>>,
    joints: Option<Vec<Spanned<String>>>,
    #[serde(default)]
    locked: HashMap<Spanned<String>, f64>,
}

#[derive(Deserialize)]
struct ComplianceEntry {
    c: f64,
}

#[derive(Deserialize)]
struct FileEntry {
    robot: Option<String>,
    chain: Option<Spanned<ChainEntry>>,
    measurement_frame: Option<Spanned<FrameEntry>>,
    tool: Option<Spanned<FrameEntry>>,
    markers: Option<Spanned<Vec<Spanned<MarkerEntry>>>>,
    joints: Option<Spanned<HashMap<Spanned<String>, IgnoredAny>>>,
    #[serde(default)]
    compliance: std::collections::BTreeMap<String, ComplianceEntry>,
}

/// A name the file gives, with its key path and line: checked against the
/// robot the file mounts ([`Frames::check_names`]).
#[derive(Clone, Debug, PartialEq)]
pub struct NameAt {
    /// The key path (`chain.joints[2]`, `tool.parent`).
    pub key: String,
    /// The name.
    pub name: String,
    /// Its line in the file (1-based; 0 when unknown).
    pub line: usize,
}

/// What a frames file gives to mount a robot.
#[derive(Clone, Debug, PartialEq)]
pub struct Frames {
    /// The file, as named in errors.
    pub origin: String,
    /// The robot the file was written for (its `robot` key).
    pub robot: Option<String>,
    /// Measurement frame → base link.
    pub mount: Isometry3<f64>,
    /// Tip link → measured frame (the measured point's offset for a single
    /// point).
    pub tool: Isometry3<f64>,
    /// Marker offsets in the tip link's frame (two or more markers).
    pub markers: Vec<[f64; 3]>,
    /// The chain's base and tip links, if the file names them.
    pub base: Option<String>,
    /// The tip link.
    pub tip: Option<String>,
    /// The lines of `chain.base` and `chain.tip` (0 when absent).
    pub base_tip_lines: (usize, usize),
    /// The joints the calibration held still, with their values
    /// (`chain.locked`, sorted by name).
    pub locked: Vec<(String, f64)>,
    /// Joint compliances (rad per N·m) by joint name: the chain deflects
    /// under its gravity torques (from the URDF's inertials).
    pub compliance: Vec<(String, f64)>,
    /// The chain's driven joints as the file lists them (`chain.joints`).
    pub chain_joints: Vec<NameAt>,
    /// Every other joint name the file gives (`joints:` keys,
    /// `chain.locked` keys), each a joint of the chain.
    pub other_joints: Vec<NameAt>,
    /// The links the file names as the chain's tip link (`tool.parent`,
    /// `markers[k].parent`).
    pub links: Vec<NameAt>,
}

fn line(l: &serde_saphyr::Location) -> usize {
    l.line() as usize
}

/// A number for a message with 4 significant digits (`1.595`, `2.000e-6`).
fn short(x: f64) -> String {
    if (1e-3..1e4).contains(&x.abs()) {
        let digits = 3 - x.abs().log10().floor() as i32;
        format!("{x:.*}", digits.max(0) as usize)
    } else {
        format!("{x:.3e}")
    }
}

/// ` (line N)` for a known line, nothing for an unknown one.
fn at(line: usize) -> String {
    if line == 0 {
        String::new()
    } else {
        format!(" (line {line})")
    }
}

/// The `n` finite numbers under `key`, or an error naming the key and line.
fn numbers<const N: usize>(key: &str, v: Option<&Numbers>, block: usize) -> StrResult<[f64; N]> {
    let Some(v) = v else {
        return Err(format!("{key}: missing{}", at(block)));
    };
    let l = line(&v.referenced);
    let Ok(a) = <[f64; N]>::try_from(v.value.as_slice()) else {
        return Err(format!(
            "{key}{}: {} numbers, expected {N}",
            at(l),
            v.value.len()
        ));
    };
    if let Some(x) = a.iter().find(|x| !x.is_finite()) {
        return Err(format!("{key}{}: {x} is not finite", at(l)));
    }
    Ok(a)
}

type StrResult<T> = std::result::Result<T, String>;

/// A frame block's pose: its rpy and quaternion both read, the quaternion
/// a unit one (within 1e-9) and the same rotation (within 1e-6 rad); an
/// `rpy_deg`, when given, the same angles.
fn frame(key: &str, e: &Spanned<FrameEntry>) -> StrResult<Isometry3<f64>> {
    let block = line(&e.referenced);
    let e = &e.value;
    let xyz: [f64; 3] = numbers(&format!("{key}.xyz"), e.xyz.as_ref(), block)?;
    let rpy: [f64; 3] = numbers(&format!("{key}.rpy"), e.rpy.as_ref(), block)?;
    let q: [f64; 4] = numbers(&format!("{key}.quaternion"), e.quaternion.as_ref(), block)?;
    let q_line = e.quaternion.as_ref().map_or(0, |v| line(&v.referenced));
    let norm = q.iter().map(|x| x * x).sum::<f64>().sqrt();
    if (norm - 1.0).abs() > QUATERNION_NORM_TOL {
        return Err(format!(
            "{key}.quaternion{}: norm {}, not 1 (within {QUATERNION_NORM_TOL:e}): a rotation is a unit quaternion [w, x, y, z]",
            at(q_line),
            short(norm)
        ));
    }
    let from_rpy = UnitQuaternion::from_euler_angles(rpy[0], rpy[1], rpy[2]);
    let from_q = UnitQuaternion::new_normalize(Quaternion::new(q[0], q[1], q[2], q[3]));
    let rpy_line = e.rpy.as_ref().map_or(0, |v| line(&v.referenced));
    let angle = from_rpy.angle_to(&from_q);
    if angle > AGREE_TOL_RAD {
        return Err(format!(
            "{key}.quaternion{}: {} rad from the rotation of {key}.rpy{}: the two must agree (within {AGREE_TOL_RAD:e} rad)",
            at(q_line),
            short(angle),
            at(rpy_line)
        ));
    }
    if let Some(d) = &e.rpy_deg {
        let deg: [f64; 3] = numbers(&format!("{key}.rpy_deg"), Some(d), block)?;
        let r = deg.map(f64::to_radians);
        let angle = from_rpy.angle_to(&UnitQuaternion::from_euler_angles(r[0], r[1], r[2]));
        if angle > AGREE_TOL_RAD {
            return Err(format!(
                "{key}.rpy_deg{}: {} rad from the rotation of {key}.rpy{}: the two must agree (within {AGREE_TOL_RAD:e} rad)",
                at(line(&d.referenced)),
                short(angle),
                at(rpy_line)
            ));
        }
    }
    Ok(Isometry3::from_parts(
        Translation3::new(xyz[0], xyz[1], xyz[2]),
        from_rpy,
    ))
}

/// A quaternion's norm may differ from 1 by this much (a written file's
/// shortest round-trip decimals are within 1e-15).
const QUATERNION_NORM_TOL: f64 = 1e-9;
/// A block's rpy, rpy_deg and quaternion agree within this angle (rad).
const AGREE_TOL_RAD: f64 = 1e-6;

/// Reads a frames file.
pub fn read(path: &Path) -> Result<Frames> {
    let name = path.display().to_string();
    let text = crate::io::read::read_text(path)?;
    parse(&text, &name)
}

/// Parses a frames file's text (`origin` names it in errors): the keys a
/// written file has (`chain`, `measurement_frame`, `joints`, and a `tool`
/// or `markers`) must be there, each rotation given by rpy and quaternion
/// alike.
pub fn parse(text: &str, origin: &str) -> Result<Frames> {
    let bad = |message: String| Error::Parse {
        path: origin.to_string(),
        message,
    };
    if text.trim().is_empty() {
        return Err(bad(
            "the file is empty: a frames file (written by a calibration) has chain, measurement_frame, joints and a tool or markers".into(),
        ));
    }
    let f: FileEntry = serde_saphyr::from_str(text).map_err(|e| bad(schema_error(text, &e)))?;
    let mut frames = build(&f).map_err(bad)?;
    frames.origin = origin.to_string();
    Ok(frames)
}

/// A YAML or schema error as `KEY.PATH (line L, column C): what`, the
/// source excerpt the parser shows on the lines after it.
fn schema_error(text: &str, e: &serde_saphyr::Error) -> String {
    let full = e.to_string();
    let Some(loc) = e.location() else {
        return format!("not a frames file: {full}");
    };
    let (l, c) = (loc.line() as usize, loc.column());
    let what = e.without_snippet().to_string();
    let what = what.trim_start_matches("error: ");
    let what = what
        .split_once(": ")
        .filter(|(head, _)| head.starts_with("line "))
        .map_or(what, |(_, rest)| rest);
    let at_end = format!(" at line {l}, column {c}");
    let what = what.strip_suffix(at_end.as_str()).unwrap_or(what);
    let key = key_path_at(text, l);
    let key = if key.is_empty() {
        "not a frames file".into()
    } else {
        key
    };
    let detail: String = full.lines().skip(1).map(|x| format!("\n{x}")).collect();
    format!("{key} (line {l}, column {c}): {what}{detail}")
}

/// The key path (`measurement_frame.xyz`) of the node at 1-based `line` of
/// block-style YAML `text`: the keys of the lines above it with less
/// indentation (a list's items sit at their key's). Best effort: empty
/// when no key is found.
fn key_path_at(text: &str, line: usize) -> String {
    let lines: Vec<&str> = text.lines().collect();
    let Some(start) = line.checked_sub(1).and_then(|k| lines.get(k)) else {
        return String::new();
    };
    let indent = |l: &str| l.len() - l.trim_start().len();
    let item = |l: &str| l.trim_start().starts_with('-');
    let key_of = |l: &str| {
        let t = l.trim_start().trim_start_matches('-').trim_start();
        t.split_once(':')
            .map(|(k, _)| k.trim())
            .filter(|k| !k.is_empty() && !k.contains(' ') && !k.starts_with('#'))
            .map(str::to_string)
    };
    let mut keys: Vec<String> = key_of(start).into_iter().collect();
    let mut need = (indent(start), item(start));
    for l in lines[..line - 1].iter().rev() {
        if l.trim().is_empty() || l.trim_start().starts_with('#') {
            continue;
        }
        let i = indent(l);
        let parent = if need.1 {
            i <= need.0 && (i < need.0 || !item(l))
        } else {
            i < need.0
        };
        if !parent {
            continue;
        }
        if !item(l) {
            keys.extend(key_of(l));
        }
        need = (i, item(l));
        if i == 0 && !item(l) {
            break;
        }
    }
    keys.reverse();
    keys.join(".")
}

/// The required top-level block `key`, or an error naming it.
fn required<'a, T>(key: &str, v: Option<&'a T>) -> StrResult<&'a T> {
    v.ok_or_else(|| {
        format!("{key}: missing (a frames file has chain, measurement_frame, joints and a tool or markers)")
    })
}

fn build(f: &FileEntry) -> StrResult<Frames> {
    let chain = required("chain", f.chain.as_ref())?;
    let mount = frame(
        "measurement_frame",
        required("measurement_frame", f.measurement_frame.as_ref())?,
    )?;
    let joints = required("joints", f.joints.as_ref())?;
    let markers_in = f.markers.as_ref().map_or(&[][..], |m| m.value.as_slice());
    let mut links = Vec::new();
    let name_at = |key: String, s: &Spanned<String>| NameAt {
        key,
        name: s.value.clone(),
        line: line(&s.referenced),
    };
    let mut tool = match (&f.tool, markers_in.is_empty()) {
        (Some(_), false) => {
            return Err("both a tool and markers: a frames file has one or the other".into());
        }
        (None, true) => {
            return Err(
                "tool: missing, and no markers: a frames file has a tool (pose data) or markers (points)".into(),
            );
        }
        (Some(t), true) => {
            if let Some(p) = &t.value.parent {
                links.push(name_at("tool.parent".into(), p));
            }
            frame("tool", t)?
        }
        (None, false) => Isometry3::identity(),
    };
    let mut markers = Vec::new();
    for (k, m) in markers_in.iter().enumerate() {
        let key = format!("markers[{k}]");
        if let Some(p) = &m.value.parent {
            links.push(name_at(format!("{key}.parent"), p));
        }
        markers.push(numbers(
            &format!("{key}.xyz"),
            m.value.xyz.as_ref(),
            line(&m.referenced),
        )?);
    }
    for (joint, c) in &f.compliance {
        if !c.c.is_finite() {
            return Err(format!("compliance.{joint}.c: {} is not finite", c.c));
        }
    }
    if markers.len() == 1 {
        // One measured point: the tool's origin.
        tool = Isometry3::from_parts(
            Translation3::from(Vector3::from(markers[0])),
            UnitQuaternion::identity(),
        );
        markers.clear();
    }
    let c = &chain.value;
    let Some(chain_joints) = &c.joints else {
        return Err(format!(
            "chain.joints: missing{}",
            at(line(&chain.referenced))
        ));
    };
    let chain_joints = chain_joints
        .iter()
        .enumerate()
        .map(|(k, j)| name_at(format!("chain.joints[{k}]"), j))
        .collect();
    let mut other_joints: Vec<NameAt> = joints
        .value
        .keys()
        .map(|j| name_at("joints".into(), j))
        .chain(c.locked.keys().map(|j| name_at("chain.locked".into(), j)))
        .collect();
    other_joints.sort_by_key(|n| n.line);
    Ok(Frames {
        origin: String::new(),
        robot: f.robot.clone(),
        mount,
        tool,
        markers,
        base: c.base.as_ref().map(|b| b.value.clone()),
        tip: c.tip.as_ref().map(|t| t.value.clone()),
        base_tip_lines: (
            c.base.as_ref().map_or(0, |b| line(&b.referenced)),
            c.tip.as_ref().map_or(0, |t| line(&t.referenced)),
        ),
        locked: {
            let mut l: Vec<(String, f64)> = c
                .locked
                .iter()
                .map(|(k, v)| (k.value.clone(), *v))
                .collect();
            l.sort_by(|a, b| a.0.cmp(&b.0));
            l
        },
        compliance: f.compliance.iter().map(|(j, c)| (j.clone(), c.c)).collect(),
        chain_joints,
        other_joints,
        links,
    })
}

/// A few names, comma-separated (the first eight and a count).
fn few(names: &[String]) -> String {
    let mut s = names.iter().take(8).cloned().collect::<Vec<_>>().join(", ");
    if names.len() > 8 {
        s += &format!(", … ({} in all)", names.len());
    }
    s
}

impl Frames {
    /// `; the file was written for R` (its `robot` key), or nothing.
    fn written_for(&self) -> String {
        self.robot
            .as_ref()
            .map_or(String::new(), |r| format!("; the file was written for {r}"))
    }

    fn bad(&self, message: String) -> Error {
        Error::Parse {
            path: self.origin.clone(),
            message,
        }
    }

    /// Checks the joints and links the file names against the robot it
    /// mounts (a URDF robot): `chain.joints` the chain's driven joints in
    /// order, every `joints:` and `chain.locked` key a joint of the chain,
    /// every tool or marker parent the chain's tip link. An error names
    /// the frames file, the key and its line.
    pub fn check_names(&self, robot: &crate::model::Robot) -> Result<()> {
        let Some(src) = robot.source.as_ref() else {
            return Ok(());
        };
        let why = self.written_for();
        let all: Vec<String> = src.joints.iter().map(|j| j.name.clone()).collect();
        let driven = src.driven_names();
        let chain = format!("the chain {} → {}", src.base, src.tip);
        for n in self.chain_joints.iter().chain(&self.other_joints) {
            if !all.contains(&n.name) {
                let near = crate::names::did_you_mean(&n.name, &all);
                let near = near
                    .trim_start()
                    .trim_start_matches('(')
                    .trim_end_matches(')');
                let listed = if near.is_empty() {
                    format!("its driven joints: {}", few(&driven))
                } else {
                    near.to_string()
                };
                return Err(self.bad(format!(
                    "{}{}: '{}' is not a joint of {chain} ({listed}{why})",
                    n.key,
                    at(n.line),
                    n.name,
                )));
            }
        }
        let listed: Vec<String> = self.chain_joints.iter().map(|n| n.name.clone()).collect();
        if listed != driven {
            let first = self.chain_joints.first().map_or(0, |n| n.line);
            let only = |a: &[String], b: &[String]| -> Vec<String> {
                a.iter().filter(|n| !b.contains(n)).cloned().collect()
            };
            let (extra, missing) = (only(&listed, &driven), only(&driven, &listed));
            let differ = match (extra.is_empty(), missing.is_empty()) {
                (true, true) => "lists them in another order".to_string(),
                (false, true) => format!("drives {}, which this one holds", few(&extra)),
                (true, false) => format!("holds {}, which this one drives", few(&missing)),
                (false, false) => format!("drives {}, not {}", few(&extra), few(&missing)),
            };
            return Err(self.bad(format!(
                "chain.joints{}: the file's chain {differ} ({chain}; lock the joints the calibration locked, no others)",
                at(first),
            )));
        }
        for n in &self.links {
            if n.name != src.tip {
                return Err(self.bad(format!(
                    "{}{}: '{}' is not the tip link '{}' of {chain}{}",
                    n.key,
                    at(n.line),
                    n.name,
                    src.tip,
                    self.written_for()
                )));
            }
        }
        Ok(())
    }

    /// A URDF error about the base or tip link the file chose (when the
    /// command gave none) named as this file's: the file is likely for
    /// another robot.
    #[must_use]
    pub fn blame_links(&self, e: Error, base_given: bool, tip_given: bool) -> Error {
        let Error::Parse { path, message } = &e else {
            return e;
        };
        let (base_line, tip_line) = self.base_tip_lines;
        let chosen = [
            ("chain.base", "base", &self.base, base_given, base_line),
            ("chain.tip", "tip", &self.tip, tip_given, tip_line),
        ];
        for (key, what, link, given, line) in chosen {
            let Some(link) = link.as_ref().filter(|_| !given) else {
                continue;
            };
            if message.contains(&format!("the {what} link '{link}' is not in the URDF")) {
                return self.bad(format!(
                    "{key}{}: '{link}' is not a link of {path}{}",
                    at(line),
                    self.written_for()
                ));
            }
        }
        e
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn key_paths_are_found_from_the_indentation() {
        let text = "robot: r\nmeasurement_frame:\n  parent: m\n  xyz:\n  - 0.1\n  - abc\nmarkers:\n- name: point\n  parent: t\n  xyz:\n  - 1\n";
        assert_eq!(key_path_at(text, 1), "robot");
        assert_eq!(key_path_at(text, 3), "measurement_frame.parent");
        assert_eq!(key_path_at(text, 6), "measurement_frame.xyz");
        assert_eq!(key_path_at(text, 9), "markers.parent");
        assert_eq!(key_path_at(text, 11), "markers.xyz");
        assert_eq!(key_path_at(text, 99), "");
    }

    #[test]
    fn a_value_of_the_wrong_type_names_its_key_and_line() {
        let text = "chain:\n  base: b\n  tip: t\n  joints:\n  - j\nmeasurement_frame:\n  xyz:\n  - 0\n  - 0\n  - 0\n  rpy:\n  - 0\n  - 0\n  - 0\n  quaternion:\n  - 1\n  - x\n";
        let e = parse(text, "f.yaml").unwrap_err().to_string();
        let first = e.lines().next().unwrap();
        assert!(
            first.starts_with("f.yaml: measurement_frame.quaternion (line 17, column"),
            "{e}"
        );
    }
}

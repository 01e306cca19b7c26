//! Files in and out: robot descriptions (built-in names, TOML, URDF), design
//! files and their pools. Loaders are one-way producers of model types: the
//! model never imports them.

pub mod atomic;
pub mod calibrated;
pub mod design;
pub mod design_formats;
pub mod frames_file;
pub mod inertia;
pub mod joint_speeds;
pub mod measurements;
pub mod robot_toml;
pub mod table;
pub mod urdf;
pub mod urdf_edit;

use crate::error::{Error, Result};
use crate::measure::Visibility;
use crate::model::{BUILTIN, MeasurementKind, Robot};
use std::path::Path;

/// A robot as a description gives it: the model and the sensor's visibility
/// region, if the description names one (used to filter pose pools when no
/// other region is given).
#[derive(Clone, Debug)]
pub struct Description {
    /// The robot model.
    pub robot: Robot,
    /// The region the sensor sees, if given.
    pub visibility: Option<Visibility>,
}

/// A robot by built-in name (see [`Robot::builtin`]) or from a file: a
/// `.toml` description ([`robot_toml`]) or a `.urdf` file ([`urdf`], unknowns
/// chosen automatically). The result is validated, and a file's unknowns are
/// checked to be identifiable.
///
/// A robot from a file is named by the path as given (not by the name inside
/// the file), so that design files, which record the robot's name, load it
/// again.
///
/// As for built-in names, the suffix `:pose` asks for full-pose
/// measurements: `arm.urdf:pose` imports with [`MeasurementKind::Pose`];
/// `arm.toml:pose` turns a point description into its full-pose variant
/// ([`Robot::with_measurement`]).
pub fn load_robot(name_or_path: &str) -> Result<Robot> {
    load_description(name_or_path).map(|d| d.robot)
}

/// Which chain of a URDF tree to take: the `#…` part of a robot name
/// (`arm.urdf#base=torso;tip=tool;lock=lift:0.1,head:0`), which the
/// command line's `--base`, `--tip` and `--lock` write, so that a design
/// file's robot name loads the same chain again.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ChainChoice {
    /// The base link (default: the URDF's root).
    pub base: Option<String>,
    /// The tip link (required on a tree).
    pub tip: Option<String>,
    /// Joints made fixed at a value.
    pub lock: Vec<(String, f64)>,
    /// A frames file ([`frames_file`]): the measurement frame and tool (or
    /// markers) to mount the chain with.
    pub frames: Option<String>,
}

impl ChainChoice {
    /// Whether nothing is chosen.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.base.is_none() && self.tip.is_none() && self.lock.is_empty() && self.frames.is_none()
    }

    /// The `#…` fragment of a robot name (empty when nothing is chosen).
    #[must_use]
    pub fn fragment(&self) -> String {
        let mut parts = Vec::new();
        if let Some(b) = &self.base {
            parts.push(format!("base={b}"));
        }
        if let Some(t) = &self.tip {
            parts.push(format!("tip={t}"));
        }
        if !self.lock.is_empty() {
            let l: Vec<String> = self.lock.iter().map(|(n, v)| format!("{n}:{v}")).collect();
            parts.push(format!("lock={}", l.join(",")));
        }
        if let Some(f) = &self.frames {
            parts.push(format!("frames={f}"));
        }
        if parts.is_empty() {
            String::new()
        } else {
            format!("#{}", parts.join(";"))
        }
    }

    /// Parses `JOINT=VALUE,…` (the `--lock` option) or `JOINT:VALUE,…` (in a
    /// name's fragment).
    pub fn parse_lock(text: &str) -> Result<Vec<(String, f64)>> {
        text.split(',')
            .filter(|s| !s.trim().is_empty())
            .map(|item| {
                let (n, v) = item
                    .split_once('=')
                    .or_else(|| item.split_once(':'))
                    .ok_or_else(|| {
                        Error::Invalid(format!(
                            "--lock {item}: expected JOINT=VALUE (radians or metres)"
                        ))
                    })?;
                let v: f64 = v.trim().parse().map_err(|_| {
                    Error::Invalid(format!("--lock {item}: '{}' is not a number", v.trim()))
                })?;
                if !v.is_finite() {
                    return Err(Error::Invalid(format!(
                        "--lock {item}: not a finite number"
                    )));
                }
                Ok((n.trim().to_string(), v))
            })
            .collect()
    }

    fn parse_fragment(frag: &str) -> Result<ChainChoice> {
        let mut c = ChainChoice::default();
        for part in frag.split(';').filter(|p| !p.is_empty()) {
            match part.split_once('=') {
                Some(("base", v)) => c.base = Some(v.to_string()),
                Some(("tip", v)) => c.tip = Some(v.to_string()),
                Some(("lock", v)) => c.lock = ChainChoice::parse_lock(v)?,
                Some(("frames", v)) => c.frames = Some(v.to_string()),
                _ => {
                    return Err(Error::Invalid(format!(
                        "robot name: unknown chain choice '{part}' after '#' (expected base=LINK, tip=LINK, lock=JOINT:VALUE,… or frames=FILE)"
                    )));
                }
            }
        }
        Ok(c)
    }
}

/// The URDF behind a robot name and the chain chosen in it, as a collision
/// filter needs them.
#[derive(Clone, Debug)]
pub struct UrdfChain {
    /// The URDF file.
    pub file: String,
    /// The chain's moving joints, in configuration order.
    pub joints: Vec<String>,
    /// The chain's base link.
    pub base: String,
    /// Joints held at a value.
    pub lock: Vec<(String, f64)>,
}

/// The [`UrdfChain`] of a robot name; `None` for a built-in robot or a
/// description file.
pub fn urdf_chain(name_or_path: &str) -> Result<Option<UrdfChain>> {
    let (head, chain) = match name_or_path.rsplit_once('#') {
        Some((h, f)) if f.contains('=') => (h, ChainChoice::parse_fragment(f)?),
        _ => (name_or_path, ChainChoice::default()),
    };
    let file = match head.strip_suffix(":pose") {
        Some(f) if !Path::new(head).exists() => f,
        _ => head,
    };
    let path = Path::new(file);
    if !path
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("urdf"))
    {
        return Ok(None);
    }
    let opts = urdf::UrdfOptions {
        base: chain.base.clone(),
        tip: chain.tip.clone(),
        lock: chain.lock.clone(),
        ..urdf::UrdfOptions::default()
    };
    let (joints, base) = urdf::chain_joints(path, &opts)?;
    Ok(Some(UrdfChain {
        file: file.to_string(),
        joints,
        base,
        lock: chain.lock,
    }))
}

/// As [`load_robot`], with the description's visibility region. A `#…`
/// fragment chooses the chain of a URDF tree ([`ChainChoice`]).
pub fn load_description(name_or_path: &str) -> Result<Description> {
    let (head, chain) = match name_or_path.rsplit_once('#') {
        Some((h, f)) if f.contains('=') => (h, ChainChoice::parse_fragment(f)?),
        _ => (name_or_path, ChainChoice::default()),
    };
    let mut d = load_head(head, &chain)?;
    d.robot.name = name_or_path.to_string();
    Ok(d)
}

/// A URDF robot with the chain options, mounted with the frames file's
/// measurement frame and tool (whose chain, if it names one, is the default
/// base and tip); two or more markers in the frames file make a marker
/// robot.
fn load_urdf(path: &Path, chain: &ChainChoice, pose: bool) -> Result<Robot> {
    let frames = chain
        .frames
        .as_ref()
        .map(|f| frames_file::read(Path::new(f)))
        .transpose()?;
    let mut opts = urdf::UrdfOptions {
        measurement: if pose {
            MeasurementKind::Pose
        } else {
            MeasurementKind::Point
        },
        base: chain.base.clone(),
        tip: chain.tip.clone(),
        lock: chain.lock.clone(),
        ..urdf::UrdfOptions::default()
    };
    if let Some(f) = &frames {
        opts.base = opts.base.or_else(|| f.base.clone());
        opts.tip = opts.tip.or_else(|| f.tip.clone());
        opts.mount = f.mount;
        opts.tool = f.tool;
    }
    let robot = urdf::load(path, &opts)?;
    let robot = match &frames {
        Some(f) if !f.compliance.is_empty() => with_compliance(robot, &f.compliance, chain)?,
        _ => robot,
    };
    match frames {
        // A copy of the robot with markers: its source comes along.
        Some(f) if !f.markers.is_empty() => robot.with_markers(&f.markers),
        _ => Ok(robot),
    }
}

/// The robot deflecting under gravity with the frames file's compliances
/// (rad per N·m by joint name) in both tables; an unknown joint, or one
/// that is not a revolute joint of the chain, is an error naming the file.
fn with_compliance(
    mut robot: Robot,
    compliance: &[(String, f64)],
    chain: &ChainChoice,
) -> Result<Robot> {
    let file = chain.frames.clone().unwrap_or_default();
    let g = inertia::gravity_model(&robot, &inertia::InertiaOptions::default())?;
    robot.gravity = Some(std::sync::Arc::new(g));
    let names = robot
        .source
        .as_ref()
        .map(|s| s.driven_names())
        .unwrap_or_default();
    for (joint, c) in compliance {
        let frame = names.iter().position(|n| n == joint).and_then(|j| {
            robot
                .frames
                .iter()
                .position(|f| f.joint == Some(j))
                .filter(|&f| robot.is_compliant_frame(f))
        });
        let Some(frame) = frame else {
            return Err(Error::Parse {
                path: file,
                message: format!(
                    "compliance.{joint}: not a revolute joint of the chain ({})",
                    names.join(", ")
                ),
            });
        };
        let id = crate::model::ParamId {
            frame,
            symbol: crate::model::Symbol::C,
        };
        robot.nominal.set(id, *c);
        robot.real.set(id, *c);
    }
    Ok(robot)
}

fn load_head(name_or_path: &str, chain: &ChainChoice) -> Result<Description> {
    if let Ok(robot) = Robot::builtin(name_or_path) {
        if !chain.is_empty() {
            return Err(Error::Invalid(format!(
                "{name_or_path}: --base, --tip and --lock choose the chain of a URDF file, not of a built-in robot"
            )));
        }
        return Ok(Description {
            robot,
            visibility: None,
        });
    }
    let (file_name, pose) = match name_or_path.strip_suffix(":pose") {
        Some(f) if !Path::new(name_or_path).exists() => (f, true),
        _ => (name_or_path, false),
    };
    let path = Path::new(file_name);
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    if !chain.is_empty() && ext.as_deref() != Some("urdf") {
        return Err(Error::Invalid(format!(
            "{name_or_path}: --base, --tip, --lock and --frames apply to a .urdf file (in a description, use its `base`, `tip` and [lock] keys)"
        )));
    }
    let d = match ext.as_deref() {
        Some("toml") => {
            let mut d = robot_toml::load_description(path)?;
            if pose && d.robot.measurement == MeasurementKind::Point {
                d.robot = d.robot.with_measurement(MeasurementKind::Pose)?;
            }
            d
        }
        Some("urdf") => Description {
            robot: load_urdf(path, chain, pose)?,
            visibility: None,
        },
        _ if path.exists() => {
            return Err(Error::Invalid(format!(
                "{name_or_path}: unknown robot file type (expected a .toml description or a .urdf file)"
            )));
        }
        _ => {
            return Err(Error::UnknownRobot {
                name: name_or_path.to_string(),
                known: format!("{}; or a path to a .toml or .urdf file", BUILTIN.join(", ")),
            });
        }
    };
    Ok(d)
}

//! Files in and out: robot descriptions (built-in names, TOML, URDF), design
//! files and their pools. Loaders are one-way producers of model types: the
//! model never imports them.

pub mod atomic;
pub mod bag;
pub mod camera_info;
pub mod camera_observations;
pub mod camera_target;
pub mod collision_choice;
pub mod contacts;
pub mod design;
pub mod design_formats;
pub mod frames_file;
pub mod images;
pub mod inertia;
pub mod joint_speeds;
pub mod kinematics_yaml;
pub mod measurements;
pub mod read;
pub mod robot_toml;
pub mod run_files;
pub mod table;
pub mod urdf;
pub mod urdf_branch;
mod urdf_chain;
pub mod urdf_edit;

use crate::error::{Error, Result};
use crate::measure::Visibility;
use crate::model::{BUILTIN, MeasurementKind, Robot};
use std::path::Path;

pub use crate::model::robot_ref::{ChainChoice, MarkerChoice, RobotRef};

/// A robot as a description gives it: the model and the sensor's visibility
/// region, if the description names one (used to filter pose pools when no
/// other region is given).
#[derive(Clone, Debug)]
pub struct Description {
    /// The robot model.
    pub robot: Robot,
    /// The region the sensor sees, if given.
    pub visibility: Option<Visibility>,
    /// Known distances between contact points and known planes
    /// (`[[distance]]`, `[[plane]]` of a description file).
    pub contacts: ContactSetup,
}

/// What a description knows of a contact setup: distances between named
/// points and planes given by name (used with a contact file's `point` and
/// `plane` columns).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ContactSetup {
    /// Known distances.
    pub distances: Vec<crate::data::NamedDistance>,
    /// Known planes.
    pub planes: Vec<crate::data::NamedPlane>,
}

/// A robot by built-in name (see [`Robot::builtin`]) or from a file, in
/// the text form of a [`RobotRef`] (`arm.urdf:pose#tip=tool`): see
/// [`RobotRef::load`].
pub fn load_robot(name_or_path: &str) -> Result<Robot> {
    load_description(name_or_path).map(|d| d.robot)
}

/// As [`load_robot`], with the description's visibility region.
pub fn load_description(name_or_path: &str) -> Result<Description> {
    RobotRef::parse(name_or_path)?.load()
}

impl RobotRef {
    /// The robot and its visibility region: a built-in name (see
    /// [`Robot::builtin`]), a `.toml` description ([`robot_toml`]) or a
    /// `.urdf` file ([`urdf`], unknowns chosen automatically; the chain
    /// and frames of [`RobotRef::chain`]). The result is validated, and a
    /// file's unknowns are checked to be identifiable.
    ///
    /// The robot is named by this reference's text form (not by the name
    /// inside the file), so that design files, which record it, load it
    /// again. [`RobotRef::pose`] asks for full-pose measurements: a URDF
    /// imports with [`MeasurementKind::Pose`], a point description turns
    /// into its full-pose variant ([`Robot::with_measurement`]).
    ///
    /// [`RobotRef::sensor`] (`ur5:NAME`) measures the robot with that
    /// registered sensor ([`crate::measure::registered_kind`]) in place of
    /// its tool point; a name no sensor registers is refused, naming those
    /// that are.
    pub fn load(&self) -> Result<Description> {
        let mut d = load_head(self)?;
        if let Some(name) = &self.sensor {
            d.robot = with_sensor(&d.robot, name, self)?;
        }
        d.robot.name = self.to_string();
        Ok(d)
    }
}

/// `robot` measured by the registered sensor `name` (the `:NAME` suffix
/// of `r`): refused when no sensor registers it, or when the robot's own
/// sensor follows more than its tool point (markers, a full pose).
fn with_sensor(robot: &Robot, name: &str, r: &RobotRef) -> Result<Robot> {
    let Some(kind) = crate::measure::registered_kind(name) else {
        let mut known = vec!["pose"];
        known.extend(crate::measure::registered_names());
        return Err(Error::Invalid(format!(
            "{r}: unknown measurement '{name}' after ':' (known: {})",
            known.join(", ")
        )));
    };
    let own = crate::measure::sensor_for(robot);
    if !own.follows_tool_point() {
        return Err(Error::Invalid(format!(
            "{r}: the robot is measured by {}; ':{name}' replaces a sensor that follows the tool point alone",
            own.describe()
        )));
    }
    robot.with_measurement(kind)
}

/// The URDF behind a robot and the chain chosen in it, as a collision
/// filter needs them.
#[derive(Clone, Debug)]
pub struct UrdfChain {
    /// The URDF file.
    pub file: String,
    /// The file's text, as the robot was imported from it (not read again).
    pub text: std::sync::Arc<str>,
    /// The chain's moving joints, in configuration order.
    pub joints: Vec<String>,
    /// The chain's base link.
    pub base: String,
    /// Joints held at a value.
    pub lock: Vec<(String, f64)>,
}

impl UrdfChain {
    /// The URDF chain of a loaded robot; `None` for a built-in robot or a
    /// description file.
    #[must_use]
    pub fn of(robot: &Robot) -> Option<UrdfChain> {
        let s = robot.source.as_ref()?;
        Some(UrdfChain {
            file: s.path.clone(),
            text: s.text.as_str().into(),
            joints: s
                .joints
                .iter()
                .filter(|j| j.is_driven())
                .map(|j| j.name.clone())
                .collect(),
            base: s.base.clone(),
            lock: s
                .joints
                .iter()
                .filter_map(|j| j.locked.map(|v| (j.name.clone(), v)))
                .collect(),
        })
    }
}

/// A URDF robot with the chain options, mounted with the frames file's
/// measurement frame and tool (whose chain, if it names one, is the default
/// base and tip, and its locked joints the default lock); two or more
/// markers in the frames file make a marker robot.
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
        if opts.lock.is_empty() {
            opts.lock.clone_from(&f.locked);
        }
        opts.mount = f.mount;
        opts.tool = f.tool;
    }
    if opts.tip.is_none()
        && let Some(m) = chain.markers.first()
    {
        // The markers' link is the measured link unless a tip is named.
        opts.tip = Some(m.link.clone());
    }
    let load = |opts: &urdf::UrdfOptions| match &chain.kinematics {
        // The kinematics file's origins in place of the URDF's.
        Some(k) => {
            let file = kinematics_yaml::read(Path::new(k))?;
            let text = read::read_text(path)?;
            let name = path.display().to_string();
            let text = kinematics_yaml::with_file(&text, &name, &file)?;
            urdf::parse(&text, &name, opts)
        }
        None => urdf::load(path, opts),
    };
    let robot = match &frames {
        Some(f) => load(&opts)
            .map_err(|e| f.blame_links(e, chain.base.is_some(), chain.tip.is_some()))
            .and_then(|r| f.check_names(&r).map(|()| r))?,
        None => load(&opts)?,
    };
    let robot = match &frames {
        Some(f) if !f.compliance.is_empty() => with_compliance(robot, &f.compliance, chain)?,
        _ => robot,
    };
    let markers = chosen_markers(&robot, chain, frames.as_ref(), pose)?;
    if markers.is_empty() {
        Ok(robot)
    } else {
        // A copy of the robot with markers: its source comes along.
        robot.with_markers(&markers)
    }
}

/// The marker offsets a URDF robot is measured with: the chain choice's
/// (`marker=LINK@X,Y,Z`, each on the chain's tip) or the frames file's,
/// never both; none for a point or full-pose sensor.
fn chosen_markers(
    robot: &Robot,
    chain: &ChainChoice,
    frames: Option<&frames_file::Frames>,
    pose: bool,
) -> Result<Vec<[f64; 3]>> {
    let from_file = frames.map(|f| f.markers.clone()).unwrap_or_default();
    if chain.markers.is_empty() {
        return Ok(from_file);
    }
    let first = &chain.markers[0];
    if !from_file.is_empty() {
        return Err(Error::Invalid(format!(
            "marker {first}: the frames file {} gives markers already ({}); give the markers once",
            chain.frames.as_deref().unwrap_or_default(),
            from_file.len()
        )));
    }
    if pose {
        return Err(Error::Invalid(format!(
            "marker {first}: a marker measures a point, ':pose' the tip's full pose; give one or the other"
        )));
    }
    let tip = robot
        .source
        .as_ref()
        .map(|s| s.tip.clone())
        .unwrap_or_default();
    if let Some(m) = chain.markers.iter().find(|m| m.link != tip) {
        return Err(Error::Invalid(format!(
            "marker {m}: markers are placed in the chain's tip link '{tip}', not in '{}'; name the tip as the marker's link (or the marker's link as the chain's tip)",
            m.link
        )));
    }
    let reach = crate::units::reach(robot);
    if let Some(why) = chain
        .markers
        .iter()
        .find_map(|m| marker_beyond_reach(m, reach))
    {
        return Err(Error::Invalid(why));
    }
    Ok(chain.markers.iter().map(|m| m.offset).collect())
}

/// Why a marker cannot be, or `None`: its offset from its link is beyond
/// the robot's `reach` (metres, [`crate::units::reach`] of the robot
/// without markers). An offset in millimetres given as metres (named as
/// such) makes a different robot, for `select` and `calibrate` alike.
fn marker_beyond_reach(m: &MarkerChoice, reach: f64) -> Option<String> {
    let [x, y, z] = m.offset;
    let norm = (x * x + y * y + z * z).sqrt();
    if norm.is_finite() && norm <= reach {
        return None;
    }
    let mm = if norm * 1e-3 <= reach {
        let c = |v: f64| crate::error::Compact(v * 1e-3);
        format!(
            "; it looks like millimetres ({}@{},{},{} in metres)",
            m.link,
            c(x),
            c(y),
            c(z)
        )
    } else {
        String::new()
    };
    Some(format!(
        "marker {m}: {norm:.3} m from its link, beyond the robot's reach ({reach:.3} m){mm}"
    ))
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

fn load_head(r: &RobotRef) -> Result<Description> {
    let head = r.head();
    if let Ok(robot) = Robot::builtin(&head) {
        if !r.chain.is_empty() {
            return Err(Error::Invalid(format!(
                "{head}: a chain choice (base, tip, lock, frames or kinematics: {}) chooses the chain of a URDF file, not of a built-in robot",
                r.chain.fragment()
            )));
        }
        return Ok(Description {
            robot,
            visibility: None,
            contacts: ContactSetup::default(),
        });
    }
    let ext = r.extension();
    if !r.chain.is_empty() && !r.is_urdf() {
        return Err(Error::Invalid(format!(
            "{head}: a chain choice (base, tip, lock, frames or kinematics: {}) applies to a .urdf file; in a description use its `base`, `tip` and [lock] keys",
            r.chain.fragment()
        )));
    }
    let path = r.path();
    let d = match ext.as_deref() {
        Some("toml") => {
            let mut d = robot_toml::load_description(path)?;
            // `:pose` turns a description whose sensor follows the tool
            // point alone into its full-pose variant (a marker, full-pose
            // or registered sensor's description keeps its own).
            if r.pose && crate::measure::sensor_for(&d.robot).follows_tool_point() {
                d.robot = d.robot.with_measurement(MeasurementKind::Pose)?;
            }
            d
        }
        Some("urdf") => Description {
            robot: load_urdf(path, &r.chain, r.pose)?,
            visibility: None,
            contacts: ContactSetup::default(),
        },
        _ if path.exists() => {
            return Err(Error::Invalid(format!(
                "{head}: unknown robot file type (expected a .toml description or a .urdf file)"
            )));
        }
        _ => {
            return Err(Error::UnknownRobot {
                name: head,
                known: format!("{}; or a path to a .toml or .urdf file", BUILTIN.join(", ")),
            });
        }
    };
    Ok(d)
}

/// Joint configurations read from a file (CSV or JSON: a planner's export,
/// a measurement campaign), in the user's units and checked against the
/// joint limits; the chain's joint names they are matched by.
pub mod configurations {
    pub use crate::pool::file::{Configurations, joint_names, read_configurations_in};
}

//! Files in and out: robot descriptions (built-in names, TOML, URDF), design
//! files and their pools. Loaders are one-way producers of model types: the
//! model never imports them.

pub mod atomic;
pub mod design;
pub mod robot_toml;
pub mod urdf;

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

/// As [`load_robot`], with the description's visibility region.
pub fn load_description(name_or_path: &str) -> Result<Description> {
    if let Ok(robot) = Robot::builtin(name_or_path) {
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
    let mut d = match ext.as_deref() {
        Some("toml") => {
            let mut d = robot_toml::load_description(path)?;
            if pose && d.robot.measurement == MeasurementKind::Point {
                d.robot = d.robot.with_measurement(MeasurementKind::Pose)?;
            }
            d
        }
        Some("urdf") => Description {
            robot: urdf::load(
                path,
                &urdf::UrdfOptions {
                    measurement: if pose {
                        MeasurementKind::Pose
                    } else {
                        MeasurementKind::Point
                    },
                    ..urdf::UrdfOptions::default()
                },
            )?,
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
    d.robot.name = name_or_path.to_string();
    Ok(d)
}

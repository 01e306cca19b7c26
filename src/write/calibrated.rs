//! A calibrated robot written out, in the format its file name asks for:
//!
//! * `.urdf` — for a robot imported from a URDF, the user's own file with
//!   only the chain's joint `<origin>`s changed ([`crate::io::urdf_edit`]);
//!   for a built-in or TOML robot, its chain as URDF ([`crate::io::urdf::to_urdf`]);
//! * `.yaml` / `.yml` — the frames file ([`super::frames`]);
//! * `.toml` — the description ([`crate::io::robot_toml`]) whose nominal and
//!   real tables are the estimate;
//! * a name ending in `kinematics.yaml` (`default_kinematics.yaml`) —
//!   Universal Robots' kinematics file of the calibrated joint origins, and
//!   one ending in `origins.yaml` — the per-joint origins file
//!   ([`crate::io::kinematics_yaml`]), and one ending in `joint_offsets.yaml`
//!   — the joints' zero offsets as a driver takes them, for a robot
//!   imported from a URDF.
//!
//! Any other extension is refused before any work.

use crate::error::{Error, Result};
use crate::frames::{CalibratedFrames, report::FramesReport};
use crate::model::{ParamTable, Robot};
use std::path::Path;

/// What a calibrated robot can be written as.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// The URDF, origins changed.
    Urdf,
    /// The frames file.
    Yaml,
    /// activecal's description.
    Toml,
    /// Universal Robots' `default_kinematics.yaml` of the joint origins.
    UrKinematics,
    /// The per-joint origins file.
    JointOrigins,
    /// The joints' zero offsets, as a driver takes them.
    JointOffsets(crate::io::kinematics_yaml::OffsetConvention),
}

impl Format {
    /// How a file name written in this format ends (`.urdf`,
    /// `kinematics.yaml`, …): [`Format::of`] reads it back.
    #[must_use]
    pub fn name_ending(self) -> &'static str {
        match self {
            Format::Urdf => ".urdf",
            Format::Yaml => ".yaml",
            Format::Toml => ".toml",
            Format::UrKinematics => "kinematics.yaml",
            Format::JointOrigins => "origins.yaml",
            Format::JointOffsets(_) => "joint_offsets.yaml",
        }
    }

    /// The format a file name asks for: an error naming the three when its
    /// extension is none of them.
    pub fn of(path: &Path) -> Result<Format> {
        let file = path
            .file_name()
            .and_then(|n| n.to_str())
            .map(str::to_ascii_lowercase)
            .unwrap_or_default();
        let ends = |stem: &str| {
            file.ends_with(&format!("{stem}.yaml")) || file.ends_with(&format!("{stem}.yml"))
        };
        if ends("kinematics") {
            return Ok(Format::UrKinematics);
        }
        if ends("origins") {
            return Ok(Format::JointOrigins);
        }
        if ends("joint_offsets") {
            return Ok(Format::JointOffsets(Default::default()));
        }
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match ext.as_deref() {
            Some("urdf") => Ok(Format::Urdf),
            Some("yaml" | "yml") => Ok(Format::Yaml),
            Some("toml") => Ok(Format::Toml),
            _ => Err(Error::Invalid(format!(
                "{}: a calibrated robot is written as .urdf (the URDF with calibrated joint origins), .yaml (the frames file: measurement frame, tool or markers, joint origins), .toml (activecal's description), a name ending in kinematics.yaml (Universal Robots' kinematics file of the joint origins) in origins.yaml (the per-joint origins file) or in joint_offsets.yaml (the joints' zero offsets); the name says none of them",
                path.display()
            ))),
        }
    }
}

/// The text of a calibrated robot `robot` at `table` in `format`.
/// `frames` (the split of [`crate::frames::decompose`]) and `report` are
/// needed for a URDF robot's `.urdf` and for `.yaml`; `header` heads the
/// TOML description.
pub fn render(
    format: Format,
    robot: &Robot,
    table: &ParamTable,
    frames: Option<(&CalibratedFrames, &FramesReport)>,
    header: &str,
) -> Result<String> {
    let no_frames = || {
        Error::Invalid(format!(
            "robot '{}' was not imported from a URDF: the frames file needs a .urdf robot (write .toml or .urdf instead)",
            robot.name
        ))
    };
    match format {
        Format::Toml => {
            let mut r = robot.clone();
            r.nominal = table.clone();
            r.real = table.clone();
            Ok(header.to_string() + &crate::io::robot_toml::to_toml(&r))
        }
        Format::Urdf => match (&robot.source, frames) {
            (Some(src), Some((f, _))) => {
                crate::io::urdf_edit::with_origins(&src.text, &src.path, &file_origins(src, f))
            }
            (Some(_), None) => Err(no_frames()),
            (None, _) => crate::io::urdf::to_urdf(robot, table),
        },
        Format::UrKinematics | Format::JointOrigins => match (&robot.source, frames) {
            (Some(src), Some((f, _))) => {
                let origins = file_origins(src, f);
                let name = src.path.as_str();
                if format == Format::UrKinematics {
                    crate::io::kinematics_yaml::ur_kinematics(name, &origins)
                } else {
                    Ok(crate::io::kinematics_yaml::joint_origins(name, &origins))
                }
            }
            _ => Err(no_frames()),
        },
        Format::JointOffsets(c) => match (&robot.source, frames) {
            (Some(src), Some((f, _))) => Ok(crate::io::kinematics_yaml::joint_offsets(
                &src.path,
                &offsets_of(f),
                c,
            )),
            _ => Err(no_frames()),
        },
        Format::Yaml => match frames {
            Some((_, report)) => super::frames::to_yaml(report),
            None => Err(no_frames()),
        },
    }
}

/// The calibrated origins of the file's joints: a chain's first joint
/// walked against the file's tree has no origin of the file (the camera's
/// placement holds it).
fn file_origins(
    src: &crate::model::source::UrdfSource,
    f: &CalibratedFrames,
) -> Vec<(String, nalgebra::Isometry3<f64>)> {
    let skip_first = usize::from(src.reversed.iter().any(|r| r.neighbour.is_none()));
    f.joints
        .iter()
        .skip(skip_first)
        .map(|j| (j.name.clone(), j.calibrated))
        .collect()
}

/// Each driven joint's zero offset (radians, or metres for a prismatic
/// joint: the origin's slide along its axis) and whether it is revolute.
fn offsets_of(f: &CalibratedFrames) -> Vec<(String, f64, bool)> {
    f.joints
        .iter()
        .map(|j| match j.kind {
            crate::model::JointKind::Revolute => (j.name.clone(), j.offset(), true),
            crate::model::JointKind::Prismatic => {
                let slide = j.nominal.rotation.inverse()
                    * (j.calibrated.translation.vector - j.nominal.translation.vector);
                (j.name.clone(), slide.dot(&j.axis), false)
            }
        })
        .collect()
}

/// A calibrated robot ready to be written: the robot, its estimate and,
/// for a robot imported from a URDF, its calibrated frames (the split of
/// [`crate::frames::decompose`] and the frames file's content); `header`
/// heads a TOML description ([`header`]).
#[derive(Clone, Copy, Debug)]
pub struct CalibratedRobot<'a> {
    /// The robot calibrated.
    pub robot: &'a Robot,
    /// The estimate.
    pub table: &'a ParamTable,
    /// Its calibrated frames, for a URDF robot.
    pub frames: Option<(&'a CalibratedFrames, &'a FramesReport)>,
    /// The first lines of a TOML description.
    pub header: &'a str,
}

impl CalibratedRobot<'_> {
    /// Its text in `format` ([`render`]).
    pub fn render(&self, format: Format) -> Result<String> {
        render(format, self.robot, self.table, self.frames, self.header)
    }

    /// Writes it as `format` to `out`, atomically. The name of `out.path`
    /// must say `format` ([`Format::of`]); an existing file is replaced only
    /// with `overwrite`, and never one of `inputs` or the robot's own file,
    /// even with `overwrite`. Messages name the file by `out.label` (the
    /// front end's name for it). The command line (`--out`, `--force`) and
    /// Python's writers call this.
    pub fn write(
        &self,
        format: Format,
        out: crate::io::atomic::Output<'_>,
        overwrite: bool,
        inputs: &[&Path],
    ) -> Result<()> {
        let (label, path) = (out.label, out.path);
        let said = Format::of(path).ok().map(|f| std::mem::discriminant(&f));
        if said != Some(std::mem::discriminant(&format)) {
            return Err(Error::Invalid(format!(
                "{label} {}: this writer writes a file whose name ends in {}",
                path.display(),
                format.name_ending()
            )));
        }
        let text = self
            .render(format)
            .map_err(|e| Error::Invalid(format!("{label} {}: {e}", path.display())))?;
        let out = [out];
        let mut given: Vec<&Path> = inputs.to_vec();
        if let Some(src) = self.robot.source.as_ref() {
            given.push(Path::new(&src.path));
        }
        // Never over an input, even when overwriting is asked.
        crate::io::atomic::check_outputs(&out, &given, overwrite)?;
        crate::io::atomic::write_atomic(path, text.as_bytes())
    }
}

/// The first lines of a calibrated robot's TOML description: where it is
/// from and how the fit ended.
#[must_use]
pub fn header(id: &crate::identify::Identification, source: &str) -> String {
    format!(
        "# Calibrated by activecal from {source}: nominal = real = the estimate\n# ({:?}, {} iterations, σ̂ = {}).\n",
        id.status,
        id.iterations,
        id.sigma_hat.map_or("-".into(), |v| format!("{v:.6e}"))
    )
}

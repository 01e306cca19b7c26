//! A calibrated robot written out, in the format its file name asks for:
//!
//! * `.urdf` — for a robot imported from a URDF, the user's own file with
//!   only the chain's joint `<origin>`s changed ([`super::urdf_edit`]);
//!   for a built-in or TOML robot, its chain as URDF ([`super::urdf::to_urdf`]);
//! * `.yaml` / `.yml` — the frames file ([`super::frames_file`]);
//! * `.toml` — the description ([`super::robot_toml`]) whose nominal and
//!   real tables are the estimate.
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
}

impl Format {
    /// The format a file name asks for: an error naming the three when its
    /// extension is none of them.
    pub fn of(path: &Path) -> Result<Format> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match ext.as_deref() {
            Some("urdf") => Ok(Format::Urdf),
            Some("yaml" | "yml") => Ok(Format::Yaml),
            Some("toml") => Ok(Format::Toml),
            _ => Err(Error::Invalid(format!(
                "{}: a calibrated robot is written as .urdf (the URDF with calibrated joint origins), .yaml (the frames file: measurement frame, tool or markers, joint origins) or .toml (activecal's description); the extension says none of them",
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
            Ok(header.to_string() + &super::robot_toml::to_toml(&r))
        }
        Format::Urdf => match (&robot.source, frames) {
            (Some(src), Some((f, _))) => {
                // A chain's first joint walked against the file's tree has
                // no origin of the file (the camera's placement holds it).
                let skip_first = usize::from(src.reversed.iter().any(|r| r.neighbour.is_none()));
                let origins: Vec<(String, nalgebra::Isometry3<f64>)> = f
                    .joints
                    .iter()
                    .skip(skip_first)
                    .map(|j| (j.name.clone(), j.calibrated))
                    .collect();
                super::urdf_edit::with_origins(&src.text, &src.path, &origins)
            }
            (Some(_), None) => Err(no_frames()),
            (None, _) => super::urdf::to_urdf(robot, table),
        },
        Format::Yaml => match frames {
            Some((_, report)) => super::frames_file::to_yaml(report),
            None => Err(no_frames()),
        },
    }
}

/// Writes a calibrated robot ([`render`]) to `path` in the format its
/// extension names, atomically; an existing file only with `overwrite`.
/// The command line (`--out`, `--force`) and Python's writers call this.
pub fn write(
    robot: &Robot,
    table: &ParamTable,
    frames: Option<(&CalibratedFrames, &FramesReport)>,
    header: &str,
    path: &Path,
    overwrite: bool,
) -> Result<()> {
    let text = render(Format::of(path)?, robot, table, frames, header)
        .map_err(|e| Error::Invalid(format!("{}: {e}", path.display())))?;
    let out = [super::atomic::Output {
        label: "calibrated robot",
        path,
    }];
    super::atomic::check_outputs(&out, &[], overwrite)?;
    super::atomic::write_atomic(path, text.as_bytes())
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

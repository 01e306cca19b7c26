//! A camera calibration's files: the URDF with the calibrated joint
//! origins and the frames file with the camera's and target's placements
//! ([`CameraCalibration::write_robot`]), the refined intrinsics as a ROS
//! `camera_info` ([`CameraCalibration::write_camera_info`]), and the
//! checks of their names made before any work. Each output is named in
//! messages by its label (the front end's word for it).

use super::CameraCalibration;
use crate::error::{Error, Result};
use crate::io::atomic::Output;
use crate::model::Robot;
use crate::write::calibrated::{CalibratedRobot, Format};
use std::path::Path;

/// Refuses, before any work, a robot file a camera calibration of `robot`
/// cannot be written as: a TOML description, or any file for a robot not
/// imported from a URDF.
pub fn check_robot_outputs(outs: &[Output<'_>], robot: &Robot) -> Result<()> {
    for o in outs {
        if Format::of(o.path)? == Format::Toml || robot.source.is_none() {
            return Err(Error::Invalid(format!(
                "{} {}: a camera calibration is written as .urdf (your URDF with the calibrated joint origins) and .yaml (the frames file with the camera's and target's placements), for a robot imported from a URDF",
                o.label,
                o.path.display()
            )));
        }
    }
    Ok(())
}

/// Refuses, before any work, refined intrinsics written other than as a
/// ROS `camera_info` `.yaml`.
pub fn check_camera_info_output(out: &Output<'_>) -> Result<()> {
    let yaml = out
        .path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("yaml") || e.eq_ignore_ascii_case("yml"));
    if yaml {
        return Ok(());
    }
    Err(Error::Invalid(format!(
        "{} {}: the refined intrinsics are written as a ROS camera_info .yaml",
        out.label,
        out.path.display()
    )))
}

impl CameraCalibration {
    /// Writes the calibrated robot to `out` as `format` (which its name
    /// must say: `.urdf`, the URDF with the calibrated joint origins;
    /// `.yaml`, the frames file with the `camera` block), atomically; an
    /// existing file only with `overwrite`, never one of `inputs` or the
    /// robot's own file. Refused for a robot not imported from a URDF (no
    /// frames).
    pub fn write_robot(
        &self,
        format: Format,
        out: Output<'_>,
        overwrite: bool,
        inputs: &[&Path],
    ) -> Result<()> {
        let Some((frames, report)) = &self.frames else {
            return Err(Error::Invalid(format!(
                "{} {}: robot '{}' was not imported from a URDF: there is no URDF or frames file to write",
                out.label,
                out.path.display(),
                self.robot_name
            )));
        };
        let calibrated = CalibratedRobot {
            robot: &self.fit.robot,
            table: &self.fit.table,
            frames: Some((frames, report)),
            header: "",
        };
        calibrated.write(format, out, overwrite, inputs)
    }

    /// Writes the intrinsics at the estimate to `out` as a ROS
    /// `camera_info` YAML naming the camera by the file's stem, its first
    /// line saying they were refined from `source`; atomically, an
    /// existing file only with `overwrite`, never one of `inputs` or the
    /// robot's own file.
    pub fn write_camera_info(
        &self,
        out: Output<'_>,
        source: &str,
        overwrite: bool,
        inputs: &[&Path],
    ) -> Result<()> {
        check_camera_info_output(&out)?;
        let name = out
            .path
            .file_stem()
            .map_or_else(|| "camera".into(), |s| s.to_string_lossy());
        let comment = format!("intrinsics refined by activecal's camera calibration from {source}");
        let mut given = inputs.to_vec();
        if let Some(src) = self.fit.robot.source.as_ref() {
            given.push(Path::new(&src.path));
        }
        crate::io::atomic::check_outputs(&[out], &given, overwrite)?;
        let text = self.camera_info_text(&name, &comment);
        crate::io::atomic::write_atomic(out.path, text.as_bytes())
    }
}

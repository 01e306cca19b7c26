//! The frames file (`cal.yaml`): a calibration's measurement frame, tool or
//! markers and joint origins ([`FramesReport`]) written as YAML with
//! `serde_saphyr` ([`crate::io::frames_file`] reads it back).

use crate::error::{Error, Result};
use crate::frames::report::FramesReport;

/// The header of a written frames file.
const HEADER: &str = "# Calibrated frames written by activecal. Units: metres and radians (xyz, rpy);\n# millimetres and degrees where a name says so (_mm, _deg). rpy as in URDF:\n# R = Rz(yaw) Ry(pitch) Rx(roll); quaternion [w, x, y, z]. measurement_frame is\n# the base link's pose in the sensor's frame; tool the measured frame's pose in\n# the tip link's; markers are positions in the tip link's frame.\n";

/// The frames file's text.
pub fn to_yaml(report: &FramesReport) -> Result<String> {
    let body = serde_saphyr::to_string(report)
        .map_err(|e| Error::Invalid(format!("cannot write the frames as YAML: {e}")))?;
    Ok(format!("{HEADER}{body}"))
}

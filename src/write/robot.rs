//! A robot description written as it is (`robots --export`): its TOML
//! description, or its nominal model in any format a calibrated robot is
//! written in ([`super::calibrated::Format`]).

use super::calibrated::{Format, render};
use crate::error::Result;
use crate::io::Description;

/// The text of the robot of `d` (validated) in `format`: a TOML
/// description with its visibility region, or its nominal model as a URDF,
/// frames file or driver file would carry it (with its frames, for a robot
/// imported from a URDF).
///
/// # Errors
/// A robot whose frames cannot be expressed in the format.
pub fn export(d: &Description, format: Format) -> Result<String> {
    let r = &d.robot;
    if format == Format::Toml {
        return Ok(crate::io::robot_toml::description_to_toml(
            r,
            d.visibility.as_ref(),
        ));
    }
    let frames = crate::frames::calibrated(r, &r.nominal, None, None)
        .map_err(|e| crate::Error::Invalid(e.to_string()))?;
    render(
        format,
        r,
        &r.nominal,
        frames.as_ref().map(|(f, rep)| (f, rep)),
        "",
    )
}

//! `calibrate --out` for a contact fit: the user's URDF with only the
//! chain's `<origin>`s changed, and the frames file whose `point` is the
//! fitted tool point (the ball centre) on the tip link and whose `contacts`
//! block holds the fitted points and planes
//! ([`activecal::frames::contact`]). Checked before the fit, written only
//! when it converged, each file atomically and never over an existing one
//! without `--force`.

use super::out_file;
use activecal::frames::CalibratedFrames;
use activecal::frames::report::FramesReport;
use activecal::identify::contact::ContactFit;
use activecal::model::Robot;
use activecal::write::calibrated::{CalibratedRobot, Format};
use anyhow::{Result, bail};
use std::path::PathBuf;

/// Refuses, before any work, an output a contact calibration cannot be
/// written as: a `.toml` description (it has no place for the tool offset
/// and the points), or any output of a robot not imported from a URDF.
pub fn check(out: &[PathBuf], robot: &Robot) -> Result<()> {
    for path in out {
        if Format::of(path)? == Format::Toml {
            bail!(
                "--out {}: a calibration from contacts is written as .urdf (your URDF with the calibrated joint origins) and .yaml (the frames file with the tool point, the fitted points and planes); a .toml description has no place for them",
                path.display()
            );
        }
        if robot.source.is_none() {
            bail!(
                "--out {}: robot '{}' was not imported from a URDF; a calibration from contacts is written for a .urdf robot only",
                path.display(),
                robot.name
            );
        }
    }
    Ok(())
}

/// Writes every `--out` of a converged fit (by extension); returns the
/// files written.
pub fn write(
    out: &[PathBuf],
    force: bool,
    robot: &Robot,
    fit: &ContactFit,
    frames: &(CalibratedFrames, FramesReport),
) -> Result<Vec<String>> {
    let calibrated = CalibratedRobot {
        robot,
        table: &fit.table,
        frames: Some((&frames.0, &frames.1)),
        header: "",
    };
    let mut written = Vec::new();
    for path in out {
        calibrated.write(Format::of(path)?, out_file(path), force, &[])?;
        written.push(path.display().to_string());
    }
    Ok(written)
}

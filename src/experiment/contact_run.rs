//! Calibration from contacts as a front end asks for it: the request (the
//! fit's options, held-out placements), the fit and its judgement
//! ([`super::contacts::calibrate_contacts`]), the held-out placements, the
//! verdict with its exit status, the report, and the calibrated robot's
//! files (written only when the verdict allows). The command line and the
//! Python package parse and convert their options into a [`ContactRequest`]
//! and render what [`run`] returns.

use super::contacts::{ContactCalibration, ContactCalibrationReport, calibrate_contacts};
use crate::data::{ContactFile, NamedDistance};
use crate::identify::LmSettings;
use crate::identify::contact::{ContactSettings, holdout_by_placement};
use crate::io::atomic::Output;
use crate::measure::contact::KnownDistance;
use crate::model::Robot;
use crate::write::calibrated::{CalibratedRobot, Format};
use std::path::Path;

pub use crate::identify::LossChoice;
pub use crate::identify::contact::{HoldoutMode, PlacementHoldout};
pub use crate::lsq::outliers::OutlierChoice;

/// A contact calibration's options, as a front end resolves them.
#[derive(Clone, Debug)]
pub struct ContactRequest {
    /// Most Levenberg–Marquardt iterations.
    pub max_iterations: usize,
    /// Geodesic acceleration of the steps.
    pub geodesic: bool,
    /// The loss of the residuals.
    pub loss: LossChoice,
    /// Parameters kept free that the rank rule would fix.
    pub keep: Vec<String>,
    /// The gross-error test.
    pub outliers: OutlierChoice,
    /// Placements held out, if asked.
    pub holdout: Option<HoldoutMode>,
}

impl ContactRequest {
    /// The fit's settings (validated).
    pub fn settings(&self) -> crate::identify::Result<ContactSettings> {
        let lm = LmSettings::builder()
            .max_iterations(self.max_iterations)
            .geodesic(self.geodesic)
            .build()?;
        Ok(ContactSettings::builder()
            .lm(lm)
            .loss(self.loss)
            .keep(self.keep.clone())
            .outliers(self.outliers)
            .build()?)
    }
}

/// A finished contact calibration: the fit and its figures, the held-out
/// placements when asked, the outlier test asked for.
#[derive(Clone, Debug)]
pub struct ContactRun {
    /// The calibration (fit, figures, frames, verdict).
    pub calibration: ContactCalibration,
    /// The held-out placements, when asked.
    pub held: Option<PlacementHoldout>,
    /// The gross-error test asked for.
    pub outliers: OutlierChoice,
    /// Rows in the file before any was left out.
    pub rows: usize,
}

/// Fits `file` with the `known` distances (as
/// [`super::contacts::checked_inputs`] gives them; `given` by name) as
/// `request` asks, then holds placements out of the rows kept if asked.
pub fn run(
    robot: &Robot,
    file: &ContactFile,
    known: &[KnownDistance],
    given: &[NamedDistance],
    request: &ContactRequest,
) -> crate::identify::Result<ContactRun> {
    let settings = request.settings()?;
    let cal = calibrate_contacts(robot, file, known, given, &settings)?;
    // The rows kept: those left out as gross errors are neither fitted
    // nor held out.
    let held = match &request.holdout {
        Some(mode) => Some(holdout_by_placement(
            robot,
            &robot.nominal,
            &cal.file,
            given,
            &settings,
            mode,
        )?),
        None => None,
    };
    Ok(ContactRun {
        calibration: cal,
        held,
        outliers: request.outliers,
        rows: file.qs.len(),
    })
}

/// Why a contact calibration's robot cannot be written.
#[derive(Debug, thiserror::Error)]
pub enum ContactOutError {
    /// The file is a `.toml` description, which has no place for the tool
    /// and the points.
    #[error(
        "{path}: a calibration from contacts is written as .urdf (your URDF with the calibrated joint origins) and .yaml (the frames file with the tool point, the fitted points and planes); a .toml description has no place for them"
    )]
    Toml {
        /// The file.
        path: String,
    },
    /// The robot was not imported from a URDF.
    #[error(
        "{path}: robot '{robot}' was not imported from a URDF; a calibration from contacts is written for a .urdf robot only"
    )]
    NotUrdf {
        /// The file.
        path: String,
        /// The robot's name.
        robot: String,
    },
    /// The fit did not converge or is not plausible.
    #[error("{path}: not written: {why}")]
    Refused {
        /// The file.
        path: String,
        /// Why.
        why: String,
    },
    /// The file's format, or writing it.
    #[error(transparent)]
    Write(#[from] crate::Error),
}

/// Refuses, before any work, a file a contact calibration of `robot`
/// cannot be written as: a `.toml` description, or any file of a robot not
/// imported from a URDF.
pub fn check_out(path: &Path, robot: &Robot) -> Result<(), ContactOutError> {
    let name = || path.display().to_string();
    if Format::of(path)? == Format::Toml {
        return Err(ContactOutError::Toml { path: name() });
    }
    if robot.source.is_none() {
        return Err(ContactOutError::NotUrdf {
            path: name(),
            robot: robot.name.clone(),
        });
    }
    Ok(())
}

impl ContactRun {
    /// The exit status the run implies (0, or 3 when the fit did not
    /// converge or is not plausible).
    #[must_use]
    pub fn exit_status(&self) -> i32 {
        self.calibration.exit_status()
    }

    /// Why the calibrated robot may not be written, if it may not.
    #[must_use]
    pub fn refusal(&self) -> Option<String> {
        self.calibration.verdict().refusal().map(str::to_string)
    }

    /// The report of this run of `robot` from `measurements`, with the
    /// frames when `with_frames`, and the files written.
    #[must_use]
    pub fn report<'a>(
        &'a self,
        robot: &'a str,
        measurements: &'a str,
        with_frames: bool,
        out: &'a [String],
    ) -> ContactCalibrationReport<'a> {
        self.calibration.report(
            robot,
            measurements,
            self.rows,
            self.outliers,
            self.held.as_ref(),
            with_frames,
            out,
        )
    }

    /// The run as text, with the files `written`
    /// ([`ContactCalibration::text`]).
    #[must_use]
    pub fn text(&self, written: &[String]) -> String {
        self.calibration.text(self.held.as_ref(), written)
    }

    /// Writes the report folder of this run of `robot` into `dir`
    /// ([`ContactCalibration::write_report`]).
    pub fn write_report(
        &self,
        dir: &Path,
        robot: &Robot,
        json: &serde_json::Value,
        text: &str,
    ) -> crate::error::Result<()> {
        self.calibration
            .write_report(dir, robot, json, self.held.as_ref(), text)
    }

    /// Writes the calibrated robot as `out` in `format` (`.urdf`: the URDF
    /// with the calibrated joint origins; `.yaml`: the frames file; a name
    /// that does not end as the format's is refused), atomically, over an
    /// existing file only when `overwrite`; refused when the fit did not
    /// converge or is not plausible, or the robot has no URDF.
    pub fn write_robot(
        &self,
        format: Format,
        out: Output<'_>,
        overwrite: bool,
    ) -> Result<(), ContactOutError> {
        let path = || out.path.display().to_string();
        if let Some(why) = self.refusal() {
            return Err(ContactOutError::Refused { path: path(), why });
        }
        let fit = &self.calibration.fit;
        let Some((f, r)) = &self.calibration.frames else {
            return Err(ContactOutError::NotUrdf {
                path: path(),
                robot: fit.robot.name.clone(),
            });
        };
        let calibrated = CalibratedRobot {
            robot: &fit.robot,
            table: &fit.table,
            frames: Some((f, r)),
            header: "",
        };
        calibrated.write(format, out, overwrite, &[])?;
        Ok(())
    }
}

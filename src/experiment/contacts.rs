//! Calibration from contacts as one step: the checks of the data against
//! the robot (distinct configurations, the known distances and planes in
//! scale), the fit, and what judges it — the in-sample consistency, the rows
//! a robust loss down-weighted, the tool point's predicted true error, the
//! calibrated frames (URDF robots) and whether the result is plausible.
//! The command line and the Python package both call it; held-out
//! placements are the caller's ([`crate::identify::contact::holdout`]).

use crate::data::{ContactFile, NamedDistance};
use crate::experiment::contact_screen::{ContactOutlier, screen_contacts};
use crate::frames::CalibratedFrames;
use crate::frames::report::{FitBlock, FramesReport};
use crate::identify::contact::holdout::{DownweightedRow, Figures, downweighted_rows, judge};
use crate::identify::contact::predict::{PREDICTION_CONFIGURATIONS, PredictedTrueError};
use crate::identify::contact::{ContactFit, ContactSettings, resolve_distances, rms, tool_points};
use crate::measure::contact::KnownDistance;
use crate::model::Robot;

/// A contact calibration and its figures.
#[derive(Clone, Debug)]
pub struct ContactCalibration {
    /// The fit.
    pub fit: ContactFit,
    /// Consistency of the calibrated and the nominal model on the rows.
    pub in_sample: Figures,
    /// Rows a robust loss weighed down.
    pub downweighted: Vec<DownweightedRow>,
    /// The tool point's predicted true error (with a covariance).
    pub predicted: Option<PredictedTrueError>,
    /// The calibrated frames and their report (URDF robots).
    pub frames: Option<(CalibratedFrames, FramesReport)>,
    /// Why a converged fit is not a plausible robot (a joint origin moved
    /// by more than a tenth of its link, a tool beyond reach); `None` when
    /// it is.
    pub implausible: Option<String>,
    /// The rows fitted: the file's, less those left out as gross errors.
    pub file: ContactFile,
    /// The rows the gross-error test left out
    /// ([`crate::experiment::contact_screen`]), in the order it found them.
    pub outliers: Vec<ContactOutlier>,
    /// What the gross-error test did, in words.
    pub notes: Vec<String>,
}

/// The input of a contact calibration a check refused, for the front end
/// to name (its flag or argument): the rows, the known planes, the known
/// distances.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ContactInput {
    /// The contact rows (configurations too close to tell apart).
    Rows,
    /// The known planes (beyond the robot's reach, normals not unit).
    Planes,
    /// The known distances (a point not in the file, none given, out of
    /// scale with the robot).
    Distances,
}

/// A check of a contact calibration's inputs that failed, with the input
/// it concerns.
#[derive(Debug, thiserror::Error)]
#[error("{source}")]
pub struct ContactInputError {
    /// The input the check concerns.
    pub input: ContactInput,
    /// What is wrong with it.
    #[source]
    pub source: crate::Error,
}

/// What the inputs are checked for: a fit (which needs distinct
/// configurations and a known distance to fix the scale) or an evaluation
/// of a model (which needs neither).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ContactUse {
    /// A calibration: every check.
    Fit,
    /// An evaluation of a given model: the planes and the distances named.
    Evaluate,
}

/// The known distances of `file`'s points (`given` by name) after the
/// checks a contact calibration needs, the `planes` given by name made
/// known first: configurations distinct enough (a fit), known planes
/// within reach, every distance naming two of the file's points, at least
/// one distance (a fit: contacts alone leave the scale free), distances in
/// scale. The error names the input it concerns.
pub fn checked_inputs(
    robot: &Robot,
    file: &mut ContactFile,
    planes: &[crate::data::NamedPlane],
    given: &[NamedDistance],
    use_: ContactUse,
) -> Result<Vec<KnownDistance>, ContactInputError> {
    let on = |input| move |source| ContactInputError { input, source };
    if use_ == ContactUse::Fit {
        file.check_distinct().map_err(on(ContactInput::Rows))?;
    }
    file.set_known_planes(planes)
        .map_err(on(ContactInput::Planes))?;
    crate::identify::contact::lengths::check_planes(robot, file)
        .map_err(on(ContactInput::Planes))?;
    let distances = on(ContactInput::Distances);
    let known = resolve_distances(file, given, true).map_err(distances)?;
    if use_ == ContactUse::Fit {
        crate::identify::contact::check_scale(file, &known).map_err(distances)?;
    }
    crate::identify::contact::lengths::check_distances(robot, file, &known).map_err(distances)?;
    Ok(known)
}

/// A model's consistency on the contact file `file` read from
/// `measurements`, without a fit (`evaluate`): the inputs checked for an
/// evaluation ([`checked_inputs`] with [`ContactUse::Evaluate`], the known
/// `planes` made known), then each point's consistency and pooled, each
/// distance's error and each plane's flatness at the robot's nominal
/// parameters, the tool point at the chain's tip
/// ([`crate::identify::contact::evaluate::evaluate_contacts`]).
pub fn evaluate(
    robot: &Robot,
    file: &mut ContactFile,
    planes: &[crate::data::NamedPlane],
    given: &[NamedDistance],
    measurements: &str,
) -> Result<crate::report::ContactEvaluationReport, ContactInputError> {
    checked_inputs(robot, file, planes, given, ContactUse::Evaluate)?;
    let e = crate::identify::contact::evaluate::evaluate_contacts(
        robot,
        &robot.nominal,
        &[0.0; 3],
        file,
        given,
    );
    Ok(crate::report::ContactEvaluationReport {
        robot: robot.name.clone(),
        chain: crate::report::chain(robot),
        measurements: measurements.to_string(),
        rows: file.qs.len(),
        contacts: e,
    })
}

/// Fits `file` with the `known` distances (as [`checked_inputs`] gives
/// them; `given` by name for the frames file), the rows the gross-error
/// test flags left out ([`ContactSettings::outliers`],
/// [`crate::experiment::contact_screen`]), and judges the fit (see the
/// module documentation) on the rows kept.
pub fn calibrate_contacts(
    robot: &Robot,
    file: &ContactFile,
    known: &[KnownDistance],
    given: &[NamedDistance],
    settings: &ContactSettings,
) -> crate::identify::Result<ContactCalibration> {
    let screened = screen_contacts(robot, file, known, given, settings)?;
    let (fit, file) = (screened.fit, &screened.file);
    let in_sample = judge(robot, &robot.nominal, &fit, file, given);
    let predicted =
        crate::identify::contact::predict::predicted_true_error(&fit, PREDICTION_CONFIGURATIONS, 0);
    let downweighted = downweighted_rows(&fit, file);
    let frames = crate::frames::contact::contact_frames(&fit, given, fit_block(&fit, file))
        .map_err(|e| crate::Error::Invalid(e.to_string()))?;
    let implausible = fit
        .converged
        .then(|| implausible(&fit, frames.as_ref().map(|(f, _)| f)))
        .flatten();
    Ok(ContactCalibration {
        fit,
        in_sample,
        downweighted,
        predicted,
        frames,
        implausible,
        file: screened.file,
        outliers: screened.outliers,
        notes: screened.notes,
    })
}

/// The fit's figures for the frames file: the rows and the RMS distance of
/// each calibrated tool point to its fitted point.
#[must_use]
pub fn fit_block(fit: &ContactFit, file: &ContactFile) -> FitBlock {
    let pts = tool_points(&fit.robot, &fit.table, &fit.tool_offset, &file.qs);
    let d: Vec<f64> = pts
        .iter()
        .zip(&file.groups)
        .filter(|(_, g)| **g < fit.point_positions.len())
        .map(|(p, &g)| (p - nalgebra::Vector3::from(fit.point_positions[g])).norm())
        .collect();
    FitBlock {
        poses: file.qs.len(),
        position_rms_mm: 1e3 * rms(&d),
        orientation_rms_deg: None,
    }
}

/// Why a converged contact fit is not a plausible robot, if it is not.
#[must_use]
pub fn implausible(fit: &ContactFit, frames: Option<&CalibratedFrames>) -> Option<String> {
    use crate::identify::plausible::check_offsets;
    crate::frames::plausible::implausible(&fit.robot, &fit.table, frames).or_else(|| {
        let reach = crate::units::reach(&fit.robot);
        check_offsets("the tool offset", &[fit.tool_offset], reach)
    })
}

/// The outlier test's choice and the rows it left out, as reported.
#[derive(Debug, serde::Serialize)]
pub struct ContactOutliersReport<'a> {
    /// The test asked for (drop, keep; its rate).
    pub choice: crate::lsq::outliers::OutlierChoice,
    /// The rows it left out, in the order it found them.
    pub left_out: &'a [ContactOutlier],
}

/// A contact calibration's report: what `calibrate --json` prints for a
/// contact file and Python's `ContactCalibration.report` holds (one
/// construction for both).
#[derive(Debug, serde::Serialize)]
pub struct ContactCalibrationReport<'a> {
    /// The robot's name.
    pub robot: &'a str,
    /// The contact file.
    pub measurements: &'a str,
    /// Rows in the file (before any was left out).
    pub rows: usize,
    /// The gross-error test.
    pub outliers: ContactOutliersReport<'a>,
    /// What the test did, in words.
    pub notes: &'a [String],
    /// The fit.
    pub fit: &'a ContactFit,
    /// Rows a robust loss weighed down.
    pub downweighted: &'a [DownweightedRow],
    /// In-sample consistency, nominal and calibrated.
    pub in_sample: &'a Figures,
    /// Held-out placements, when asked for.
    pub holdout: Option<&'a crate::identify::contact::PlacementHoldout>,
    /// The tool point's predicted true error.
    pub predicted_true_error: Option<&'a PredictedTrueError>,
    /// The calibrated frames (when written).
    pub frames: Option<&'a FramesReport>,
    /// The files written.
    pub out: &'a [String],
    /// 0, or 3 when the fit did not converge or is not plausible.
    pub exit_status: i32,
}

impl ContactCalibration {
    /// The exit status the calibration implies: 0 when the fit converged
    /// to a plausible robot, else [`super::measured::verdict::EXIT_REFUSED`].
    #[must_use]
    pub fn exit_status(&self) -> i32 {
        self.verdict().exit_status()
    }

    /// Whether the calibrated robot may be written: refused when the fit
    /// did not converge or converged to an implausible robot, with why.
    #[must_use]
    pub fn verdict(&self) -> super::measured::verdict::Verdict {
        use super::measured::verdict::Verdict;
        let fit = &self.fit;
        let reason = if let Some(why) = &self.implausible {
            why.clone()
        } else if !fit.converged {
            format!(
                "the contact fit ended {:?} after {} iterations{}",
                fit.stop,
                fit.iterations,
                if fit.std.is_none() {
                    " without a full-rank Jacobian"
                } else {
                    ""
                }
            )
        } else {
            return Verdict::Calibrated;
        };
        Verdict::Refused { reason }
    }

    /// The report of this calibration of `robot` from `measurements`
    /// (`rows` rows before screening), with the outlier test's `choice`,
    /// the held-out placements, the frames when `with_frames`, and the
    /// files written.
    #[allow(clippy::too_many_arguments)]
    #[must_use]
    pub fn report<'a>(
        &'a self,
        robot: &'a str,
        measurements: &'a str,
        rows: usize,
        choice: crate::lsq::outliers::OutlierChoice,
        holdout: Option<&'a crate::identify::contact::PlacementHoldout>,
        with_frames: bool,
        out: &'a [String],
    ) -> ContactCalibrationReport<'a> {
        ContactCalibrationReport {
            robot,
            measurements,
            rows,
            outliers: ContactOutliersReport {
                choice,
                left_out: &self.outliers,
            },
            notes: &self.notes,
            fit: &self.fit,
            downweighted: &self.downweighted,
            in_sample: &self.in_sample,
            holdout,
            predicted_true_error: self.predicted.as_ref(),
            frames: if with_frames {
                self.frames.as_ref().map(|(_, r)| r)
            } else {
                None
            },
            out,
            exit_status: self.exit_status(),
        }
    }
}

impl ContactCalibration {
    /// The calibration as text (what `calibrate` prints for a contact
    /// file): the fit and its figures ([`crate::render::contact_text`]),
    /// the held-out placements, the gross-error test's notes, the tool
    /// point's predicted true error and the files `written`.
    #[must_use]
    pub fn text(
        &self,
        held: Option<&crate::identify::contact::PlacementHoldout>,
        written: &[String],
    ) -> String {
        use std::fmt::Write as _;
        let mut s = crate::render::contact_text::text(&self.file, &self.fit, &self.in_sample, held);
        for n in &self.notes {
            let _ = writeln!(s, "note: {n}");
        }
        if let Some(p) = &self.predicted {
            let _ = writeln!(
                s,
                "predicted true error of the calibrated tool point (the fit's covariance at {} random configurations): {:.4} mm RMS; it includes what held-out placements cannot see (an error common to a placement's rows)",
                p.configurations, p.rms_mm
            );
        }
        if !written.is_empty() {
            s.push('\n');
        }
        for out in written {
            let _ = writeln!(s, "calibrated robot written to {out}");
        }
        s
    }

    /// Writes the report folder of this calibration of `robot` into `dir`
    /// (`calibrate --report DIR` for a contact file): `text` (as
    /// [`ContactCalibration::text`] gives it), `json` the report
    /// ([`ContactCalibration::report`]), the figures and the 3D page with
    /// the robot at each contact, the fitted sockets and planes.
    pub fn write_report(
        &self,
        dir: &std::path::Path,
        robot: &Robot,
        json: &serde_json::Value,
        held: Option<&crate::identify::contact::PlacementHoldout>,
        text: &str,
    ) -> crate::error::Result<()> {
        let file = &self.file;
        let r = crate::render::contact_figures::ContactReport {
            robot,
            file,
            fit: &self.fit,
            figures: &self.in_sample,
            held,
        };
        let touches = |g: usize| match file.points.get(g) {
            Some(p) => format!("point {p}"),
            None => format!("plane {}", g - file.points.len() + 1),
        };
        let poses: Vec<(String, Vec<f64>)> = file
            .qs
            .iter()
            .zip(&file.groups)
            .zip(&file.lines)
            .map(|((q, g), l)| (format!("line {l}: {}", touches(*g)), q.clone()))
            .collect();
        crate::render::folder::contacts(dir, &r, text, json, &poses)
    }
}

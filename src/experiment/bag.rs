//! Measurements from a ROS 2 bag ([`crate::io::bag::extract`]), checked as
//! a measurement file's are: the calibration pipeline's other reader; and
//! the calibration from a bag ([`calibrate_bag`]), whose clock offset is
//! estimated again with the calibrated model.

use super::error::ExperimentError;
use super::measured::{MeasuredCalibration, MeasuredSettings, calibrate_read};
use crate::data::Measurements;
use crate::io::bag::extract::{ExtractReport, ExtractSettings, extract};
use crate::model::Robot;
use crate::render::bag_text::clock_note;
use crate::report::bag::{BagSection, ClockRefit};
use std::path::Path;

/// The measurements of the bag at `path` (one pose per kept rest), checked
/// against `robot` and its reach, with notes on what the extraction found
/// (rests kept and left out with their reasons, the clock offset, the
/// measured noise) and its report.
pub fn read_bag(
    path: &Path,
    robot: &Robot,
    s: &ExtractSettings,
) -> Result<(Measurements, Vec<String>, ExtractReport), ExperimentError> {
    checked(path, robot, extract(path, robot, s)?)
}

/// An extraction's measurements checked against `robot` and its reach,
/// with the notes of its report.
fn checked(
    path: &Path,
    robot: &Robot,
    got: crate::io::bag::extract::Extracted,
) -> Result<(Measurements, Vec<String>, ExtractReport), ExperimentError> {
    let source = path.display().to_string();
    let in_file = |error| ExperimentError::InFile {
        path: source.clone(),
        error,
    };
    got.measurements
        .check(robot)
        .map_err(|e| in_file(e.into()))?;
    crate::identify::evaluation::check_in_reach(
        robot,
        &got.measurements,
        &source,
        crate::units::LengthUnit::M,
    )
    .map_err(in_file)?;
    Ok((got.measurements, notes(&got.report), got.report))
}

/// What an extraction found, as notes.
#[must_use]
pub fn notes(r: &ExtractReport) -> Vec<String> {
    let mut out = vec![format!(
        "{}: {} of {} rests kept as poses ({} at {:.1} Hz, {} at {:.1} Hz)",
        r.bag,
        r.kept(),
        r.rests.len(),
        r.joints,
        r.joint_rate,
        r.source,
        r.measurement_rate
    )];
    for (k, x) in r.rests.iter().enumerate() {
        if let Some(why) = &x.left_out {
            out.push(format!("rest {} left out: {why}", k + 1));
        }
    }
    let c = &r.clock;
    out.push(match &c.estimate {
        Some(e) => format!(
            "clock offset: estimated {:.4} s ± {:.4} s from {} moves; applied {:.4} s ({})",
            e.seconds, e.uncertainty, e.moves, c.applied, c.note
        ),
        None => format!("clock offset {:.4} s ({})", c.applied, c.note),
    });
    out.push(format!(
        "measured noise: {:.4} mm per coordinate per sample (median rest), {:.5} mm for an averaged pose: compare σ̂",
        r.scatter * 1e3,
        r.averaged_noise * 1e3
    ));
    out
}

/// A calibration from a ROS 2 bag: the measurements extracted (those of
/// the final fit) and the fit, whose report says what the extraction found
/// and how the clock was settled (`report.bag`).
pub struct BagCalibration {
    /// The measurements fitted, one pose per kept rest.
    pub measurements: Measurements,
    /// The calibration of those measurements.
    pub calibration: MeasuredCalibration,
}

/// Calibrates `robot` from the bag at `path`: extracts one pose per rest
/// ([`read_bag`]), fits it as a measurement file's data
/// ([`calibrate_read`]) and, when the clock offset was estimated, estimates
/// it again with the calibrated model (the nominal model's predicted moves
/// bias it); when it moved by more than its uncertainty, the bag is
/// extracted with the new offset and fitted once more.
pub fn calibrate_bag(
    path: &Path,
    robot: &Robot,
    x: &ExtractSettings,
    s: &MeasuredSettings,
    on_note: &mut dyn FnMut(&str),
) -> Result<BagCalibration, ExperimentError> {
    let source = path.display().to_string();
    let (meas, notes, report) = read_bag(path, robot, x)?;
    let first = calibrate_read(robot, &meas, &source, notes, s, on_note)?;
    let estimated = match (&report.clock.estimate, x.time_offset) {
        (Some(e), None) if first.fit.id.converged() => e.clone(),
        _ => return Ok(done(meas, first, report, None)),
    };
    let mut calibrated = first.robot.clone();
    calibrated.nominal = first.fit.id.table.clone();
    let again = extract(path, &calibrated, x)?;
    let Some(e2) = again.report.clock.estimate.clone() else {
        let clock = ClockRefit {
            nominal: estimated,
            calibrated: None,
            refitted: false,
        };
        return Ok(done(meas, first, report, Some(clock)));
    };
    let moved = (e2.seconds - estimated.seconds).abs() > estimated.uncertainty;
    let clock = ClockRefit {
        nominal: estimated,
        calibrated: Some(e2.clone()),
        refitted: moved,
    };
    if !moved {
        on_note(&clock_note(&clock));
        return Ok(done(meas, first, report, Some(clock)));
    }
    // The extraction with the calibrated model applied its estimate.
    let (meas2, mut notes2, report2) = checked(path, robot, again)?;
    notes2.push(clock_note(&clock));
    let second = calibrate_read(robot, &meas2, &source, notes2, s, on_note)?;
    Ok(done(meas2, second, report2, Some(clock)))
}

/// The calibration of `measurements`, its report saying what the
/// extraction found and how the clock was settled.
fn done(
    measurements: Measurements,
    mut calibration: MeasuredCalibration,
    extraction: ExtractReport,
    clock_refit: Option<ClockRefit>,
) -> BagCalibration {
    calibration.report.bag = Some(BagSection {
        extraction,
        clock_refit,
    });
    BagCalibration {
        measurements,
        calibration,
    }
}

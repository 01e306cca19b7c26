//! Measurements from a ROS 2 bag ([`crate::io::bag::extract`]), checked as
//! a measurement file's are: the calibration pipeline's other reader.

use super::error::ExperimentError;
use crate::identify::Measurements;
use crate::io::bag::extract::{ExtractReport, ExtractSettings, extract};
use crate::model::Robot;
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
    let got = extract(path, robot, s)?;
    let source = path.display().to_string();
    let in_file = |error| ExperimentError::InFile {
        path: source.clone(),
        error,
    };
    got.measurements.check(robot).map_err(in_file)?;
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

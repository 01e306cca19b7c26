//! What every kind of calibration shares on the way out: the calibrated
//! robot written by `--out` (by extension, with its frames), the exit status
//! of an unconverged fit, and the status line.

use super::calibrate_args::CalibrateArgs;
use activecal::experiment::CalibratedFrames;
use activecal::experiment::Identification;
use activecal::model::Robot;
use activecal::report::FramesReport;
use activecal::write::calibrated::{CalibratedRobot, Format};
use anyhow::Result;

/// Writes the calibrated robot to every `--out` when identification
/// converged (by extension, [`Format`]); returns the files written. A
/// non-converged estimate is never written as a robot model (see
/// [`refuse_unconverged`]).
pub fn write_calibrated(
    a: &CalibrateArgs,
    robot: &Robot,
    id: &Identification,
    source: &str,
    frames: Option<&(CalibratedFrames, FramesReport)>,
) -> Result<Vec<String>> {
    if !id.converged() {
        return Ok(Vec::new());
    }
    let header = activecal::write::calibrated::header(id, source);
    let calibrated = CalibratedRobot {
        robot,
        table: &id.table,
        frames: frames.map(|(f, r)| (f, r)),
        header: &header,
    };
    let mut written = Vec::new();
    for out in &a.out {
        let format = match Format::of(out)? {
            Format::JointOffsets(_) => Format::JointOffsets(a.offset_convention()),
            f => f,
        };
        calibrated.write(format, super::out_file(out), a.force, &[])?;
        written.push(out.display().to_string());
    }
    Ok(written)
}

/// The exit status of a calibration whose fit did not converge or is rank
/// deficient (0: converged, 1: an error, 2: a usage error).
pub const EXIT_NOT_CONVERGED: i32 = 3;

/// A calibration that ran but whose fit did not converge: the report is
/// printed, and the process exits with [`EXIT_NOT_CONVERGED`].
#[derive(Debug)]
pub struct NotConverged(pub String);

impl std::fmt::Display for NotConverged {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for NotConverged {}

/// After the report is printed: a [`NotConverged`] error (exit status
/// [`EXIT_NOT_CONVERGED`]) with the reason when the estimate did not
/// converge, so that no script mistakes it for a calibrated model; with
/// `--out`, the message says that nothing was written.
pub fn refuse_unconverged(a: &CalibrateArgs, id: &Identification) -> Result<()> {
    if id.converged() {
        return Ok(());
    }
    let mut why = activecal::experiment::measured::verdict::unconverged(id);
    why += &not_written(a);
    Err(NotConverged(why).into())
}

/// `; A, B were not written` for the `--out` files, or nothing.
pub fn not_written(a: &CalibrateArgs) -> String {
    if a.out.is_empty() {
        return String::new();
    }
    let names: Vec<String> = a.out.iter().map(|p| p.display().to_string()).collect();
    format!(
        "; {} {} not written",
        names.join(", "),
        if names.len() == 1 { "was" } else { "were" }
    )
}

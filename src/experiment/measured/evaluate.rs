//! The `evaluate` pipeline: a model's errors on measured data, no fitting.

use crate::data::Measurements;
use crate::experiment::ExperimentError;
use crate::model::{ParamTable, Robot};
use crate::report::measured::EvaluationReport;

/// The errors of `robot` with the parameters `table` on `meas` (read from
/// `source`, with the reader's `notes`): per pose and in total, mm and
/// degrees.
///
/// # Errors
/// Data the model cannot predict (another number of markers than the
/// model carries offsets for).
pub fn evaluate(
    robot: &Robot,
    table: &ParamTable,
    meas: &Measurements,
    source: &str,
    notes: Vec<String>,
) -> Result<EvaluationReport, ExperimentError> {
    let residuals = crate::identify::residuals(robot, table, meas)?;
    Ok(EvaluationReport {
        robot: robot.name.clone(),
        chain: crate::report::chain(robot),
        measurements: source.to_string(),
        poses: meas.len(),
        residuals,
        notes,
    })
}

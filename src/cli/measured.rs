//! `calibrate --measurements` (identification from real data, with a loss,
//! fixed or freed unknowns, parameter significance and held-out splits) and
//! `evaluate` (a model's errors on data, no fitting): rendering only; the
//! work is in `activecal::experiment::measured`.

use super::emit_report;
use activecal::data::Measurements;
use activecal::experiment::measured::evaluate::evaluate;
use activecal::model::Robot;
use anyhow::Result;
use std::path::Path;

/// Reads a measurement file (CSV or JSON) for `robot` in `units`
/// ([`activecal::experiment::measured::read_measurement_file`]), printing
/// its notes to stderr unless `quiet`.
pub fn read_measurements(
    path: &Path,
    robot: &Robot,
    units: activecal::units::Units,
    quiet: bool,
) -> Result<(Measurements, Vec<String>)> {
    let (meas, notes) = activecal::experiment::measured::read_measurement_file(path, robot, units)?;
    if !quiet {
        for n in &notes {
            super::diag(&format!("note: {n}"));
        }
    }
    Ok((meas, notes))
}

/// Arguments of `evaluate`.
#[derive(clap::Args)]
pub struct EvaluateArgs {
    /// The model: a built-in name, a .toml description (e.g. what
    /// `calibrate --out` wrote) or a .urdf file; append `:pose` for full
    /// poses (`:NAME` for a sensor registered by
    /// that name). Its nominal table is evaluated.
    #[arg(long, value_parser = super::parse_robot)]
    pub robot: activecal::io::RobotRef,
    /// Measurement file: CSV (x1,y1,z1…, optional phix1,phiy1,phiz1 or
    /// qw1…qz1, one column per joint by name) or JSON.
    #[arg(long)]
    pub measurements: std::path::PathBuf,
    /// Units of the measurement file.
    #[command(flatten)]
    pub units: super::units::UnitOpts,
    /// A contact file's known distance between two points, A,B=METRES
    /// (repeatable): its error is reported.
    #[arg(long = "point-distance", value_name = "A,B=METRES")]
    pub point_distance: Vec<String>,
    /// A contact file's known plane, NAME=nx,ny,nz,d (repeatable).
    #[arg(long, value_name = "NAME=nx,ny,nz,d", allow_hyphen_values = true)]
    pub plane: Vec<String>,
    /// Print one JSON object.
    #[arg(long)]
    pub json: bool,
    /// The options typed on the command line (set after parsing).
    #[arg(skip)]
    pub given: super::acts_on::Given,
}

/// Runs `evaluate`: the model's errors on the data, no fitting.
pub fn cmd_evaluate(a: EvaluateArgs) -> Result<()> {
    let robot = super::load_robot(&a.robot)?;
    let (meas, notes) = read_measurements(&a.measurements, &robot, a.units.units(), a.json)?;
    let source = a.measurements.display().to_string();
    let report = evaluate(&robot, &robot.nominal, &meas, &source, notes).map_err(|e| {
        anyhow::anyhow!(
            "{source}: {e}{}",
            if meas.markers() > 1 {
                " (a model for several markers carries their offsets: evaluate the description `calibrate --out` wrote)"
            } else {
                ""
            }
        )
    })?;
    emit_report(a.json, &report, || {
        activecal::render::measured_text::evaluation_text(&report)
    })
}

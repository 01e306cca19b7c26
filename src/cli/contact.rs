//! `calibrate --measurements contacts.csv` for a file with a `point` column
//! or a `plane` column (calibration from contacts with fixed points and
//! planes, no instrument): parsing of `--point-distance` and `--plane`,
//! rendering of the fit and of `--holdout-by
//! placement` / `--train-on`. The work is in
//! `activecal::experiment::contact_run`.

use super::calibrate_args::{CalibrateArgs, HoldoutBy};
use activecal::data::{NamedDistance, NamedPlane};
use activecal::experiment::contact_run::{
    ContactOutError, ContactRequest, HoldoutMode, check_out, run,
};
use activecal::experiment::contacts::{
    ContactInput, ContactInputError, ContactUse, checked_inputs,
};
use activecal::io::contacts::read_contacts;
use activecal::model::Robot;
use activecal::write::calibrated::Format;
use anyhow::{Result, bail};
use std::path::Path;

/// Whether `path` is a CSV whose header has a `point` column.
pub fn is_contact_file(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("csv"))
        && std::fs::read_to_string(path)
            .is_ok_and(|t| activecal::io::contacts::has_point_column(&t))
}

/// Parses one `--point-distance A,B=METRES`.
pub fn parse_distance(s: &str) -> Result<NamedDistance> {
    s.parse()
        .map_err(|e| anyhow::anyhow!("--point-distance {s}: {e}"))
}

/// The description's distances and planes followed by those of
/// `--point-distance` and `--plane`.
pub fn contact_setup(
    setup: &activecal::io::ContactSetup,
    point_distance: &[String],
    plane: &[String],
) -> Result<(Vec<NamedDistance>, Vec<NamedPlane>)> {
    let mut given = setup.distances.clone();
    for s in point_distance {
        given.push(parse_distance(s)?);
    }
    let mut planes = setup.planes.clone();
    for s in plane {
        planes.push(s.parse().map_err(|e| anyhow::anyhow!("--plane {s}: {e}"))?);
    }
    Ok((given, planes))
}

/// Calibrates from a contact file; `Ok(Some(why))` when the fit did not
/// converge (the report is printed).
pub fn calibrate_contacts(
    a: &CalibrateArgs,
    robot: &Robot,
    setup: &activecal::io::ContactSetup,
    path: &Path,
) -> Result<Option<String>> {
    if a.holdout.is_some() {
        bail!(
            "--holdout: contacts are held out by placement (--holdout-by placement or --train-on NAME), not by random rows"
        );
    }
    for out in &a.out {
        check_out(out, robot).map_err(out_err)?;
    }
    let (given, planes) = contact_setup(setup, &a.point_distance, &a.plane)?;
    let mut file = read_contacts(path, robot, a.units.units())?;
    let known =
        checked_inputs(robot, &mut file, &planes, &given, ContactUse::Fit).map_err(named)?;
    let r = run(robot, &file, &known, &given, &request_of(a)?)?;
    let mut written = Vec::new();
    if r.exit_status() == 0 && r.calibration.frames.is_some() {
        for out in &a.out {
            r.write_robot(Format::of(out)?, super::out_file(out), a.force)
                .map_err(out_err)?;
            written.push(out.display().to_string());
        }
    }
    let measurements = path.display().to_string();
    let v =
        serde_json::to_value(r.report(&robot.name, &measurements, !a.out.is_empty(), &written))?;
    let report = r.text(&written);
    if let Some(dir) = &a.report {
        r.write_report(dir, robot, &v, &report)?;
    }
    super::emit(a.json, &v, || report)?;
    Ok(r.refusal().map(|why| {
        let names: Vec<String> = a.out.iter().map(|p| p.display().to_string()).collect();
        if names.is_empty() {
            why
        } else {
            format!("{why}; {} not written", names.join(", "))
        }
    }))
}

/// A refused or failed `--out`, named as the command line gives it.
fn out_err(e: ContactOutError) -> anyhow::Error {
    match e {
        ContactOutError::Write(e) => e.into(),
        e => anyhow::anyhow!("--out {e}"),
    }
}

/// A refused input of a contact calibration, named as the command line
/// gives it: `--plane` or `--point-distance` (a refused row names its file
/// and line itself).
pub fn named(e: ContactInputError) -> anyhow::Error {
    let source = anyhow::Error::new(e.source);
    match e.input {
        ContactInput::Rows => source,
        ContactInput::Planes => source.context("--plane"),
        ContactInput::Distances => source.context("--point-distance"),
    }
}

/// The calibration's request from the command line.
fn request_of(a: &CalibrateArgs) -> Result<ContactRequest> {
    let holdout = match (&a.holdout_by, &a.train_on) {
        (_, Some(t)) => Some(HoldoutMode::TrainOn(t.clone())),
        (Some(HoldoutBy::Placement), None) => Some(HoldoutMode::LeaveOneOut),
        (None, None) => None,
    };
    Ok(ContactRequest {
        max_iterations: a.max_iterations,
        geodesic: !a.no_geodesic,
        loss: activecal::options::LossChoice::of(a.loss, a.loss_scale)?,
        keep: a.free.clone(),
        outliers: a.outlier_choice()?,
        holdout,
    })
}

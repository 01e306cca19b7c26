//! `calibrate --measurements contacts.csv` for a file with a `point` column
//! or a `plane` column (calibration from contacts with fixed points and
//! planes, no instrument): parsing of `--point-distance` and `--plane`,
//! rendering of the fit and of `--holdout-by
//! placement` / `--train-on`. The work is in
//! `activecal::experiment::contact_run`.

use activecal::data::{NamedDistance, NamedPlane};
use activecal::experiment::contact_run::{
    ContactOutError, ContactRequest, HoldoutMode, OutlierChoice, check_out, run,
};
use activecal::experiment::contacts::{
    ContactInput, ContactInputError, ContactUse, checked_inputs,
};
use activecal::io::contacts::read_contacts;
use activecal::model::Robot;
use activecal::write::calibrated::Format;
use anyhow::{Result, bail};
use std::path::Path;

/// How to hold contacts out.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum HoldoutBy {
    /// By placement: the part of a point's name before '/'.
    Placement,
}

/// Whether `path` is a CSV whose header has a `point` column.
pub fn is_contact_file(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("csv"))
        && std::fs::read_to_string(path)
            .is_ok_and(|t| activecal::io::contacts::has_point_column(&t))
}

/// Parses one `--point-distance A,B=METRES`.
pub fn parse_distance(s: &str) -> Result<NamedDistance> {
    let bad = || {
        anyhow::anyhow!(
            "--point-distance {s}: expected A,B=METRES (two point names and a distance in metres, e.g. front_left/0,front_left/1=0.05)"
        )
    };
    let (names, d) = s.split_once('=').ok_or_else(bad)?;
    let (a, b) = names.split_once(',').ok_or_else(bad)?;
    let metres: f64 = d.trim().parse().map_err(|_| bad())?;
    Ok(NamedDistance {
        a: a.trim().to_string(),
        b: b.trim().to_string(),
        metres,
    })
}

/// `NAME=v1,…,vN`: a non-empty name and exactly `N` numbers (`None`
/// otherwise), the form of `--plane` and `select --point`.
pub fn named_numbers<const N: usize>(s: &str) -> Option<(String, [f64; N])> {
    let (name, rest) = s.split_once('=')?;
    let v: Vec<f64> = rest
        .split(',')
        .map(|c| c.trim().parse::<f64>())
        .collect::<std::result::Result<_, _>>()
        .ok()?;
    let name = name.trim();
    (!name.is_empty()).then(|| v.try_into().ok().map(|a| (name.to_string(), a)))?
}

/// Parses one `--plane NAME=nx,ny,nz,d` (the normal's length is checked
/// with the file's planes).
pub fn parse_plane(s: &str) -> Result<NamedPlane> {
    let Some((name, [nx, ny, nz, d])) = named_numbers::<4>(s) else {
        anyhow::bail!(
            "--plane {s}: expected NAME=nx,ny,nz,d (a plane name, its normal and offset in metres, n · x = d in the base frame, e.g. table=0,0,1,0.02)"
        );
    };
    Ok(NamedPlane {
        name,
        normal: [nx, ny, nz],
        offset: d,
    })
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
        planes.push(parse_plane(s)?);
    }
    Ok((given, planes))
}

/// The options of `calibrate` a contact fit reads.
pub struct ContactArgs<'a> {
    /// `--holdout` was given (refused).
    pub holdout: bool,
    /// `--out` (checked before the fit, written when it converged).
    pub out: &'a [std::path::PathBuf],
    /// `--force`.
    pub force: bool,
    /// `--point-distance`.
    pub point_distance: &'a [String],
    /// `--plane`.
    pub plane: &'a [String],
    /// The description's `[[distance]]` and `[[plane]]` tables.
    pub setup: &'a activecal::io::ContactSetup,
    /// `--holdout-by`.
    pub holdout_by: Option<HoldoutBy>,
    /// `--train-on`.
    pub train_on: Option<&'a str>,
    /// `--loss`, `--loss-scale`.
    pub loss: super::measured::LossKind,
    /// `--loss-scale`.
    pub loss_scale: Option<f64>,
    /// `--free`.
    pub free: &'a [String],
    /// `--max-iterations`.
    pub max_iterations: usize,
    /// `--no-geodesic`.
    pub no_geodesic: bool,
    /// The file's units.
    pub units: activecal::units::Units,
    /// `--json`.
    pub json: bool,
    /// `--report DIR` (checked before the fit).
    pub report: Option<&'a Path>,
    /// `--outliers`, `--outlier-rate`.
    pub outliers: OutlierChoice,
}

/// Calibrates from a contact file; `Ok(Some(why))` when the fit did not
/// converge (the report is printed).
pub fn calibrate_contacts(
    a: &ContactArgs<'_>,
    robot: &Robot,
    path: &Path,
) -> Result<Option<String>> {
    if a.holdout {
        bail!(
            "--holdout: contacts are held out by placement (--holdout-by placement or --train-on NAME), not by random rows"
        );
    }
    for out in a.out {
        check_out(out, robot).map_err(out_err)?;
    }
    let (given, planes) = contact_setup(a.setup, a.point_distance, a.plane)?;
    let mut file = read_contacts(path, robot, a.units)?;
    let known =
        checked_inputs(robot, &mut file, &planes, &given, ContactUse::Fit).map_err(named)?;
    let r = run(robot, &file, &known, &given, &request_of(a)?)?;
    let mut written = Vec::new();
    if r.exit_status() == 0 && r.calibration.frames.is_some() {
        for out in a.out {
            r.write_robot(Format::of(out)?, super::out_file(out), a.force)
                .map_err(out_err)?;
            written.push(out.display().to_string());
        }
    }
    let measurements = path.display().to_string();
    let v =
        serde_json::to_value(r.report(&robot.name, &measurements, !a.out.is_empty(), &written))?;
    let report = r.text(&written);
    if let Some(dir) = a.report {
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
fn request_of(a: &ContactArgs<'_>) -> Result<ContactRequest> {
    let holdout = match (&a.holdout_by, &a.train_on) {
        (_, Some(t)) => Some(HoldoutMode::TrainOn((*t).to_string())),
        (Some(HoldoutBy::Placement), None) => Some(HoldoutMode::LeaveOneOut),
        (None, None) => None,
    };
    Ok(ContactRequest {
        max_iterations: a.max_iterations,
        geodesic: !a.no_geodesic,
        loss: super::measured::loss_choice(a.loss, a.loss_scale)?,
        keep: a.free.to_vec(),
        outliers: a.outliers,
        holdout,
    })
}

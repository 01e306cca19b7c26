//! Contacts held out by placement: a placement is the part of a point's
//! name before `/` (`front_left/0` → `front_left`: the sockets of one
//! placement of the block). Leave one placement out (fit on the others,
//! judge on it), or train on one placement and judge on each other one.
//!
//! A model is judged on rows it was not fitted to by their **consistency**:
//! the RMS distance of each row's predicted tool point to the mean of its
//! point's rows (per point, and pooled over the rows of a placement or of
//! every held-out placement), and by the **distance error**: the distance
//! between two points' means against the known distance. Nominal (the
//! start table, no tool offset) against calibrated.

use super::fit::{ContactFit, ContactSettings, fit_contacts};
use super::{best_plane, group_means, placement_of, resolve_distances, rms, spreads, tool_points};
use crate::data::ContactFile;
use crate::data::NamedDistance;
use crate::error::Error;
use crate::identify::Result;
use crate::measure::contact::PlaneKind;
use crate::model::{ParamTable, Robot};
use nalgebra::Vector3;
use serde::Serialize;

/// One point's consistency on held-out rows, millimetres.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct PointFigure {
    /// The point.
    pub point: String,
    /// Its rows.
    pub rows: usize,
    /// Consistency of the nominal model, mm.
    pub nominal_mm: f64,
    /// Consistency of the calibrated model, mm.
    pub calibrated_mm: f64,
}

/// One known distance on held-out rows, millimetres.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct DistanceFigure {
    /// The first point.
    pub a: String,
    /// The second point.
    pub b: String,
    /// The known distance, mm.
    pub known_mm: f64,
    /// |predicted − known| of the nominal model, mm.
    pub nominal_error_mm: f64,
    /// |predicted − known| of the calibrated model, mm.
    pub calibrated_error_mm: f64,
}

/// A row a robust loss down-weighted.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct DownweightedRow {
    /// Its 1-based file line.
    pub line: usize,
    /// The point it touches.
    pub point: String,
    /// Its weight.
    pub weight: f64,
}

/// One plane's flatness on some rows, millimetres: the RMS signed distance
/// `n · t − d` of the rows' tool points to the plane, a known plane's own,
/// an unknown plane's the one that fits the rows best (for the calibrated
/// model on its training rows, the fitted plane: at the optimum the plane's
/// unknowns minimise the same sum).
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct PlaneFigure {
    /// The plane.
    pub plane: String,
    /// Its rows.
    pub rows: usize,
    /// Whether the plane was given (not estimated).
    pub known: bool,
    /// RMS signed distance of the nominal model, mm.
    pub nominal_mm: f64,
    /// RMS signed distance of the calibrated model, mm.
    pub calibrated_mm: f64,
}

/// How a model does on rows it was not fitted to.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct Figures {
    /// Per point.
    pub points: Vec<PointFigure>,
    /// Pooled over the rows, nominal, mm.
    pub nominal_mm: f64,
    /// Pooled over the rows, calibrated, mm.
    pub calibrated_mm: f64,
    /// Known distances between these rows' points.
    pub distances: Vec<DistanceFigure>,
    /// The planes these rows touch.
    pub planes: Vec<PlaneFigure>,
}

/// One row's distance of its predicted tool point to the mean of its
/// point's rows, millimetres: the per-row figure whose RMS is a point's
/// consistency (a row far from the rest is a fault of the recording).
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct RowDistance {
    /// Its 1-based file line.
    pub line: usize,
    /// The point it touches.
    pub point: String,
    /// Under the nominal model, mm.
    pub nominal_mm: f64,
    /// Under the calibrated model, mm.
    pub calibrated_mm: f64,
}

/// Each row of `test` that touches a point: its distance to its point's
/// mean under the `nominal` table (no tool offset) and under `fit`.
#[must_use]
pub fn row_distances(
    robot: &Robot,
    nominal: &ParamTable,
    fit: &ContactFit,
    test: &ContactFile,
) -> Vec<RowDistance> {
    let nom = tool_points(robot, nominal, &[0.0; 3], &test.qs);
    let cal = tool_points(&fit.robot, &fit.table, &fit.tool_offset, &test.qs);
    let all = test.points.len() + test.planes.len();
    let (sn, sc) = (
        spreads(&nom, &test.groups, all),
        spreads(&cal, &test.groups, all),
    );
    (0..test.qs.len())
        .filter(|&i| test.groups[i] < test.points.len())
        .map(|i| RowDistance {
            line: test.lines[i],
            point: test.points[test.groups[i]].clone(),
            nominal_mm: 1e3 * sn[i],
            calibrated_mm: 1e3 * sc[i],
        })
        .collect()
}

/// One fold: a fit on some placements, judged on others.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct HoldoutFold {
    /// The placement judged on.
    pub held_out: String,
    /// The placements fitted to.
    pub trained_on: Vec<String>,
    /// Whether the fit converged.
    pub converged: bool,
    /// Unknowns estimated (robot's and own).
    pub estimated: usize,
    /// Robot unknowns fixed as undetermined.
    pub fixed: usize,
    /// The held-out figures.
    pub figures: Figures,
    /// Training rows a robust loss down-weighted.
    pub downweighted: Vec<DownweightedRow>,
    /// Each held-out row's distance to its point's mean (for figures; not
    /// in the JSON, whose per-point figures summarise them).
    #[serde(skip)]
    pub rows: Vec<RowDistance>,
}

/// Which folds.
#[derive(Clone, Debug, PartialEq)]
pub enum HoldoutMode {
    /// Fit on all placements but one, judge on that one; every placement.
    LeaveOneOut,
    /// Fit on this placement, judge on each other one.
    TrainOn(String),
}

/// A contact fit held out by placement: its figures over every fold (a
/// fit of measured poses held out by random splits reports
/// [`crate::report::measured::HoldoutReport`]).
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct PlacementHoldout {
    /// `leave_one_out` or `train_on`.
    pub mode: String,
    /// The folds.
    pub folds: Vec<HoldoutFold>,
    /// Consistency pooled over every held-out row, nominal, mm.
    pub pooled_nominal_mm: f64,
    /// Consistency pooled over every held-out row, calibrated, mm.
    pub pooled_calibrated_mm: f64,
    /// The mean over folds of each fold's pooled calibrated consistency, mm.
    pub mean_calibrated_mm: f64,
    /// The mean calibrated distance error over every fold's distances, mm.
    pub mean_distance_error_mm: Option<f64>,
    /// The largest calibrated distance error, mm.
    pub max_distance_error_mm: Option<f64>,
}

/// The placements of `file`'s points, in order of appearance.
#[must_use]
pub fn placements(file: &ContactFile) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    // Points only: a plane whose name has no point's placement is in every
    // fold's training rows (its figures are in-sample only).
    for p in &file.points {
        let pl = placement_of(p);
        if !out.iter().any(|o| o == pl) {
            out.push(pl.to_string());
        }
    }
    out
}

/// The rows of `file` whose placement is (or, with `not`, is not) `pl`.
fn rows_of(file: &ContactFile, pl: &str, not: bool) -> Vec<usize> {
    (0..file.qs.len())
        .filter(|&i| (placement_of(file.name_of(file.groups[i])) == pl) != not)
        .collect()
}

/// The figures of `fit` on `test` against the `nominal` table.
#[must_use]
pub fn judge(
    robot: &Robot,
    nominal: &ParamTable,
    fit: &ContactFit,
    test: &ContactFile,
    distances: &[NamedDistance],
) -> Figures {
    let nom = tool_points(robot, nominal, &[0.0; 3], &test.qs);
    let cal = tool_points(&fit.robot, &fit.table, &fit.tool_offset, &test.qs);
    figures_of(&nom, &cal, test, distances)
}

/// The figures of two models' tool points `nom` and `cal` (one a row of
/// `test`).
#[must_use]
pub fn figures_of(
    nom: &[Vector3<f64>],
    cal: &[Vector3<f64>],
    test: &ContactFile,
    distances: &[NamedDistance],
) -> Figures {
    let n = test.points.len();
    let all = n + test.planes.len();
    let (sn, sc) = (
        spreads(nom, &test.groups, all),
        spreads(cal, &test.groups, all),
    );
    let point_rows: Vec<usize> = (0..test.qs.len()).filter(|&i| test.groups[i] < n).collect();
    let pooled = |s: &[f64]| 1e3 * rms(&point_rows.iter().map(|&i| s[i]).collect::<Vec<_>>());
    let points = (0..n)
        .map(|g| {
            let rows = test.rows_of(g);
            let pick = |s: &[f64]| rms(&rows.iter().map(|&i| s[i]).collect::<Vec<_>>());
            PointFigure {
                point: test.points[g].clone(),
                rows: rows.len(),
                nominal_mm: 1e3 * pick(&sn),
                calibrated_mm: 1e3 * pick(&sc),
            }
        })
        .collect();
    let (mn, mc) = (
        group_means(nom, &test.groups, all),
        group_means(cal, &test.groups, all),
    );
    // Every distance given is checked when the test file was read: here a
    // distance whose points are not both in `test` is left out.
    let known = resolve_distances(test, distances, false).unwrap_or_default();
    let distances = known
        .iter()
        .map(|d| DistanceFigure {
            a: test.points[d.a].clone(),
            b: test.points[d.b].clone(),
            known_mm: 1e3 * d.metres,
            nominal_error_mm: 1e3 * ((mn[d.a] - mn[d.b]).norm() - d.metres).abs(),
            calibrated_error_mm: 1e3 * ((mc[d.a] - mc[d.b]).norm() - d.metres).abs(),
        })
        .collect();
    Figures {
        points,
        nominal_mm: pooled(&sn),
        calibrated_mm: pooled(&sc),
        distances,
        planes: plane_figures(test, nom, cal),
    }
}

/// Each plane's RMS signed distance of its rows' tool points (nominal and
/// calibrated, see [`PlaneFigure`]).
fn plane_figures(
    test: &ContactFile,
    nom: &[Vector3<f64>],
    cal: &[Vector3<f64>],
) -> Vec<PlaneFigure> {
    let g0 = test.points.len();
    test.planes
        .iter()
        .enumerate()
        .map(|(l, p)| {
            let rows = test.rows_of(g0 + l);
            let known = match p.kind {
                PlaneKind::Known { normal, offset } => Some((Vector3::from(normal), offset)),
                PlaneKind::Unknown { .. } => None,
            };
            let figure = |pts: &[Vector3<f64>]| {
                let at: Vec<Vector3<f64>> = rows.iter().map(|&i| pts[i]).collect();
                let (nrm, d) = known.unwrap_or_else(|| best_plane(&at));
                let dist: Vec<f64> = at.iter().map(|t| nrm.dot(t) - d).collect();
                1e3 * rms(&dist)
            };
            PlaneFigure {
                plane: p.name.clone(),
                rows: rows.len(),
                known: known.is_some(),
                nominal_mm: figure(nom),
                calibrated_mm: figure(cal),
            }
        })
        .collect()
}

/// The rows of a fit a robust loss down-weighted, by file line and point.
#[must_use]
pub fn downweighted_rows(fit: &ContactFit, train: &ContactFile) -> Vec<DownweightedRow> {
    fit.downweighted()
        .into_iter()
        .map(|(i, weight)| DownweightedRow {
            line: train.lines[i],
            point: train.name_of(train.groups[i]).to_string(),
            weight,
        })
        .collect()
}

/// Held-out figures of `file` by placement (see the module documentation).
/// Errors on a file with one placement (nothing to hold out) and on a
/// training placement the file does not have.
pub fn holdout_by_placement(
    robot: &Robot,
    start: &ParamTable,
    file: &ContactFile,
    distances: &[NamedDistance],
    settings: &ContactSettings,
    mode: &HoldoutMode,
) -> Result<PlacementHoldout> {
    let all = placements(file);
    if all.len() < 2 {
        return Err(Error::Invalid(format!(
            "{}: one placement ({}): holding out by placement needs two or more (a placement is a point name's part before '/')",
            file.origin,
            all.join(", ")
        ))
        .into());
    }
    let pairs: Vec<(Vec<String>, String)> = match mode {
        HoldoutMode::LeaveOneOut => all
            .iter()
            .map(|h| (all.iter().filter(|p| *p != h).cloned().collect(), h.clone()))
            .collect(),
        HoldoutMode::TrainOn(t) => {
            if !all.contains(t) {
                return Err(Error::Invalid(format!(
                    "placement '{t}': {} has no such placement (its placements: {})",
                    file.origin,
                    all.join(", ")
                ))
                .into());
            }
            all.iter()
                .filter(|p| *p != t)
                .map(|h| (vec![t.clone()], h.clone()))
                .collect()
        }
    };
    let mut folds = Vec::with_capacity(pairs.len());
    for (train_on, held) in pairs {
        folds.push(fold(
            robot, start, file, distances, settings, train_on, held,
        )?);
    }
    Ok(summarise(mode, folds))
}

/// One fold's fit and figures.
fn fold(
    robot: &Robot,
    start: &ParamTable,
    file: &ContactFile,
    distances: &[NamedDistance],
    settings: &ContactSettings,
    train_on: Vec<String>,
    held: String,
) -> Result<HoldoutFold> {
    let train_rows: Vec<usize> = match train_on.as_slice() {
        [one] => rows_of(file, one, false),
        _ => rows_of(file, &held, true),
    };
    let train = file.subset(&train_rows);
    let test = file.subset(&rows_of(file, &held, false));
    let known = resolve_distances(&train, distances, false)?;
    let fit = fit_contacts(robot, start, &train, &known, settings)?;
    Ok(HoldoutFold {
        figures: judge(robot, start, &fit, &test, distances),
        rows: row_distances(robot, start, &fit, &test),
        downweighted: downweighted_rows(&fit, &train),
        held_out: held,
        trained_on: train_on,
        converged: fit.converged,
        estimated: fit.estimate.len(),
        fixed: fit.fixed.len(),
    })
}

/// Pooled figures over the folds.
fn summarise(mode: &HoldoutMode, folds: Vec<HoldoutFold>) -> PlacementHoldout {
    let pooled = |f: &dyn Fn(&PointFigure) -> f64| -> f64 {
        let (mut s, mut n) = (0.0, 0usize);
        for p in folds.iter().flat_map(|f| &f.figures.points) {
            s += f(p).powi(2) * p.rows as f64;
            n += p.rows;
        }
        (s / n.max(1) as f64).sqrt()
    };
    let errs: Vec<f64> = folds
        .iter()
        .flat_map(|f| f.figures.distances.iter().map(|d| d.calibrated_error_mm))
        .collect();
    PlacementHoldout {
        mode: match mode {
            HoldoutMode::LeaveOneOut => "leave_one_out".into(),
            HoldoutMode::TrainOn(_) => "train_on".into(),
        },
        pooled_nominal_mm: pooled(&|p| p.nominal_mm),
        pooled_calibrated_mm: pooled(&|p| p.calibrated_mm),
        mean_calibrated_mm: folds.iter().map(|f| f.figures.calibrated_mm).sum::<f64>()
            / folds.len().max(1) as f64,
        mean_distance_error_mm: (!errs.is_empty())
            .then(|| errs.iter().sum::<f64>() / errs.len() as f64),
        max_distance_error_mm: errs.iter().copied().reduce(f64::max),
        folds,
    }
}

//! The figures of `calibrate --report DIR` for a contact file, from the fit
//! and its held-out folds: each placement's consistency and each known
//! distance's error (nominal, calibrated, held out), and each row's
//! distance to its point's mean ([`super::plots`] draws them).

use super::plots::{BarGroup, RowMark, consistency_bars, row_distances};
use crate::data::ContactFile;
use crate::error::Result;
use crate::identify::contact::holdout::{Figures, downweighted_rows};
use crate::identify::contact::{
    ContactFit, PlacementHoldout, RowDistance, placement_of, placements, rms,
    row_distances as rows_of_fit,
};
use crate::model::Robot;
use std::path::Path;

/// What the contact figures are drawn from.
pub struct ContactReport<'a> {
    /// The robot (its nominal table is the nominal model).
    pub robot: &'a Robot,
    /// The contacts.
    pub file: &'a ContactFile,
    /// The fit on every row.
    pub fit: &'a ContactFit,
    /// Its in-sample figures.
    pub figures: &'a Figures,
    /// The held-out folds, when asked for.
    pub held: Option<&'a PlacementHoldout>,
}

/// Each placement's in-sample consistency (the RMS of its rows'
/// distances), nominal and calibrated, with the held-out fold's figure.
fn placement_bars(
    names: &[String],
    rows: &[RowDistance],
    held: Option<&PlacementHoldout>,
) -> Vec<BarGroup> {
    names
        .iter()
        .map(|p| {
            let of: Vec<&RowDistance> = rows
                .iter()
                .filter(|r| placement_of(&r.point) == p)
                .collect();
            let pick =
                |f: fn(&RowDistance) -> f64| rms(&of.iter().map(|r| f(r)).collect::<Vec<_>>());
            BarGroup {
                label: p.clone(),
                nominal_mm: pick(|r| r.nominal_mm),
                calibrated_mm: pick(|r| r.calibrated_mm),
                held_out_mm: held.and_then(|h| {
                    h.folds
                        .iter()
                        .find(|f| &f.held_out == p)
                        .map(|f| f.figures.calibrated_mm)
                }),
            }
        })
        .collect()
}

/// Each known distance's error, in-sample and held out.
fn distance_bars(figures: &Figures, held: Option<&PlacementHoldout>) -> Vec<BarGroup> {
    figures
        .distances
        .iter()
        .map(|d| {
            let (pa, pb) = (placement_of(&d.a), placement_of(&d.b));
            BarGroup {
                label: if pa == pb {
                    pa.to_string()
                } else {
                    format!("{}–{}", d.a, d.b)
                },
                nominal_mm: d.nominal_error_mm,
                calibrated_mm: d.calibrated_error_mm,
                held_out_mm: held.and_then(|h| {
                    h.folds
                        .iter()
                        .flat_map(|f| &f.figures.distances)
                        .find(|e| e.a == d.a && e.b == d.b)
                        .map(|e| e.calibrated_error_mm)
                }),
            }
        })
        .collect()
}

/// Rows as marks in placement order (file order within a placement),
/// ranked 1, 2, …, or at the rank of their file line in `at` (the
/// in-sample marks: a row at the same place in every panel).
fn marks(
    names: &[String],
    rows: &[RowDistance],
    down: &[usize],
    at: Option<&[RowMark]>,
) -> Vec<RowMark> {
    let mut out: Vec<RowMark> = rows
        .iter()
        .map(|r| RowMark {
            rank: 0,
            placement: names
                .iter()
                .position(|p| p == placement_of(&r.point))
                .unwrap_or(0),
            line: r.line,
            mm: r.calibrated_mm,
            downweighted: down.contains(&r.line),
        })
        .collect();
    out.sort_by_key(|m| (m.placement, m.line));
    for (k, m) in out.iter_mut().enumerate() {
        m.rank = match at {
            Some(at) => at
                .iter()
                .find(|a| a.line == m.line)
                .map_or(k + 1, |a| a.rank),
            None => k + 1,
        };
    }
    out
}

/// Draws the contact figures into `dir`; returns each figure's stem and
/// caption for report.md.
pub fn draw(dir: &Path, r: &ContactReport<'_>) -> Result<Vec<(String, String)>> {
    let names = placements(r.file);
    let rows = rows_of_fit(r.robot, &r.robot.nominal, r.fit, r.file);
    let down: Vec<usize> = downweighted_rows(r.fit, r.file)
        .iter()
        .map(|d| d.line)
        .collect();
    let mut figs = Vec::new();
    consistency_bars(
        &dir.join("consistency_by_placement"),
        &placement_bars(&names, &rows, r.held),
        &distance_bars(r.figures, r.held),
    )?;
    figs.push((
        "consistency_by_placement".into(),
        format!(
            "each placement's consistency (RMS distance of a row's predicted tool point to its point's mean, mm) and each known distance's error (mm), nominal against calibrated{}",
            if r.held.is_some() {
                " on its own rows and held out"
            } else {
                ""
            }
        ),
    ));
    let held_rows: Option<Vec<RowDistance>> = r
        .held
        .map(|h| h.folds.iter().flat_map(|f| f.rows.clone()).collect());
    let in_sample = marks(&names, &rows, &down, None);
    let held_marks = held_rows
        .as_ref()
        .map(|h| marks(&names, h, &[], Some(&in_sample)));
    row_distances(
        &dir.join("row_distances"),
        &names,
        &in_sample,
        held_marks.as_deref(),
    )?;
    figs.push((
        "row_distances".into(),
        "each row's distance to its point's mean under the calibrated model (mm), rows grouped by placement, the five largest named by file line".into(),
    ));
    Ok(figs)
}

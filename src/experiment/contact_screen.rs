//! Gross errors in contacts: each row (a contact with a point or plane,
//! three residuals) tested by Baarda's data snooping
//! ([`crate::lsq::outliers::snoop`]) as the tracker's poses are; the
//! row flagged left out and the fit repeated. A row whose point or plane
//! would be left with fewer than [`MIN_DISTINCT`] different configurations
//! is not left out (the fit would have nothing to determine it by): the
//! test stops there with a note.

use crate::data::MIN_DISTINCT;
use crate::data::{ContactFile, NamedDistance};
use crate::identify::LossChoice;
use crate::identify::contact::fit::row_tester;
use crate::identify::contact::{
    ContactFit, ContactSettings, fit_contacts, resolve_distances, tool_points,
};
use crate::lsq::outliers::{
    Capped, Flag, Flagged, MOST_OUTLIERS, OutlierChoice, PoseTest, Snoop, flagged, kept_of, snoop,
    too_many_note,
};
use crate::measure::contact::KnownDistance;
use crate::model::Robot;
use nalgebra::Vector3;
use serde::Serialize;

/// A contact row left out as a gross error.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ContactOutlier {
    /// The row among the file's rows (0-based).
    pub row: usize,
    /// Its file line (1-based).
    pub line: usize,
    /// The point or plane it touches.
    pub point: String,
    /// Its test when flagged (`pose` is `row`).
    pub test: PoseTest,
    /// The bound its tail fell below (`α / n`, `n` the rows tested).
    pub threshold: f64,
    /// The distance of its tool point from its point (or plane) at the
    /// final fit, mm.
    pub residual_mm: f64,
}

/// The fit of the rows kept, those left out, and what the test did.
pub struct ScreenedContacts {
    /// The fit of the rows kept.
    pub fit: ContactFit,
    /// The rows kept.
    pub file: ContactFile,
    /// Their known distances (indices into `file`'s points).
    pub known: Vec<KnownDistance>,
    /// The rows left out.
    pub outliers: Vec<ContactOutlier>,
    /// What the test did, in words.
    pub notes: Vec<String>,
}

/// The rows of a contact file as units of [`snoop`].
struct Rows<'a> {
    robot: &'a Robot,
    file: &'a ContactFile,
    given: &'a [NamedDistance],
    settings: &'a ContactSettings,
    notes: Vec<String>,
}

impl Rows<'_> {
    /// The file without the rows `out`, and its known distances.
    fn without(&self, out: &[usize]) -> crate::identify::Result<(ContactFile, Vec<KnownDistance>)> {
        let sub = self.file.subset(&kept_of(self.file.qs.len(), out));
        let known = resolve_distances(&sub, self.given, false)?;
        Ok((sub, known))
    }
}

impl Snoop for Rows<'_> {
    type Unit = usize;
    type Fit = ContactFit;
    type Error = crate::identify::IdentifyError;

    fn fit(
        &mut self,
        out: &[usize],
        _from: Option<&ContactFit>,
    ) -> crate::identify::Result<ContactFit> {
        let (sub, known) = self.without(out)?;
        fit_contacts(self.robot, &self.robot.nominal, &sub, &known, self.settings)
    }

    fn flag(&mut self, fit: &ContactFit, out: &[usize], alpha: f64) -> Flagged<usize> {
        let Some(flag) = self.worst(fit, out, alpha) else {
            return Flagged::Clean;
        };
        let row = flag.unit;
        let g = self.file.groups[row];
        let name = self.file.name_of(g);
        let rows_of_g = self.file.rows_of(g).len();
        let most = point_most(rows_of_g);
        if out.iter().filter(|&&i| self.file.groups[i] == g).count() >= most {
            return Flagged::Systematic(format!(
                "the gross-error test flags more than {most} of the {rows_of_g} rows of '{name}': not isolated glitches but a point that moved during the capture, or a model that misses something near it (joint sag under gravity, a flexing tool); every row is kept"
            ));
        }
        let kept = kept_of(self.file.qs.len(), out);
        let left = kept
            .iter()
            .filter(|&&i| i != row && self.file.groups[i] == g)
            .fold(Vec::<&Vec<f64>>::new(), |mut d, &i| {
                if !d.contains(&&self.file.qs[i]) {
                    d.push(&self.file.qs[i]);
                }
                d
            });
        if left.len() < MIN_DISTINCT {
            self.notes.push(format!(
                "line {} ({name}) fails the gross-error test (test value {:.1}, P = {:.1e}) but is kept: without it '{name}' would have {} different configuration(s), fewer than the {MIN_DISTINCT} a fit needs",
                self.file.lines[row],
                flag.test.statistic,
                flag.test.p_value,
                left.len()
            ));
            return Flagged::Clean;
        }
        Flagged::Unit(flag)
    }
}

/// The most rows of one point (or plane) with `n` rows the test may leave
/// out: a fifth ([`MOST_OUTLIERS`]), at least 2 (two contacts seated wrong
/// at one socket are still glitches).
fn point_most(n: usize) -> usize {
    ((MOST_OUTLIERS * n as f64).floor() as usize).max(2)
}

impl Rows<'_> {
    /// The row the test flags at `fit` (with `out` left out), if any.
    fn worst(&self, fit: &ContactFit, out: &[usize], alpha: f64) -> Option<Flag<usize>> {
        if !fit.converged {
            return None;
        }
        let kept = kept_of(self.file.qs.len(), out);
        let (sub, known) = self.without(out).ok()?;
        let tester = row_tester(fit, &self.robot.nominal, &sub, &known)?;
        let tests: Vec<PoseTest> = (0..sub.qs.len())
            .filter_map(|i| tester.test(i, &[3 * i, 3 * i + 1, 3 * i + 2]))
            .collect();
        let worst = flagged(&tests, alpha)?;
        Some(Flag {
            unit: kept[worst.pose],
            test: worst.clone(),
            threshold: alpha / tests.len() as f64,
        })
    }
}

/// The fit of `file`'s contacts with the distances `given` (the whole
/// file's `known` ones), and with least squares and
/// [`OutlierChoice::Drop`], the rows the gross-error test flags left out
/// one at a time and the fit repeated, until none is flagged or
/// [`MOST_OUTLIERS`] of the rows are out (then every row is kept).
pub fn screen_contacts(
    robot: &Robot,
    file: &ContactFile,
    known: &[KnownDistance],
    given: &[NamedDistance],
    settings: &ContactSettings,
) -> crate::identify::Result<ScreenedContacts> {
    settings.validate()?;
    let alpha = match (settings.outliers, settings.loss) {
        (OutlierChoice::Drop { alpha }, LossChoice::L2) => alpha,
        _ => {
            return Ok(ScreenedContacts {
                fit: fit_contacts(robot, &robot.nominal, file, known, settings)?,
                file: file.clone(),
                known: known.to_vec(),
                outliers: Vec::new(),
                notes: Vec::new(),
            });
        }
    };
    let mut rows = Rows {
        robot,
        file,
        given,
        settings,
        notes: Vec::new(),
    };
    let most = (MOST_OUTLIERS * file.qs.len() as f64).floor() as usize;
    let snooped = snoop(&mut rows, alpha, most)?;
    let mut notes = std::mem::take(&mut rows.notes);
    match snooped.capped {
        Some(Capped::Total) => notes.push(too_many_note(most, file.qs.len(), "rows")),
        Some(Capped::Systematic(why)) => notes.push(why),
        None => {}
    }
    let out: Vec<usize> = snooped.out.iter().map(|f| f.unit).collect();
    let (sub, sub_known) = if out.is_empty() {
        (file.clone(), known.to_vec())
    } else {
        rows.without(&out)?
    };
    let fit = snooped.fit;
    let outliers: Vec<ContactOutlier> = snooped
        .out
        .into_iter()
        .map(|f| {
            let mut test = f.test;
            test.pose = f.unit;
            ContactOutlier {
                row: f.unit,
                line: file.lines[f.unit],
                point: file.name_of(file.groups[f.unit]).to_string(),
                test,
                threshold: f.threshold,
                residual_mm: 1e3 * row_residual(&fit, file, f.unit),
            }
        })
        .collect();
    for o in &outliers {
        notes.push(format!(
            "line {} ({}) left out as a gross error: {:.3} mm off at the fit, test value {:.1} on {} rows against σ̂ on {} degrees of freedom, P = {:.1e} < {:.1e} (α {alpha} over {} rows; {keep})",
            o.line,
            o.point,
            o.residual_mm,
            o.test.statistic,
            o.test.dof.0,
            o.test.dof.1,
            o.test.p_value,
            o.threshold,
            (alpha / o.threshold).round(),
            keep = crate::names::phrase::KEEP_GROSS_ERRORS
        ));
    }
    Ok(ScreenedContacts {
        fit,
        file: sub,
        known: sub_known,
        outliers,
        notes,
    })
}

/// The distance (metres) of row `row` of `file`'s tool point from its
/// point or plane as `fit` estimates them (by name: `fit` may be of a
/// subset of the rows); NaN when the fit has no such point or plane.
#[must_use]
pub fn row_residual(fit: &ContactFit, file: &ContactFile, row: usize) -> f64 {
    let p = tool_points(
        &fit.robot,
        &fit.table,
        &fit.tool_offset,
        &file.qs[row..=row],
    )[0];
    let name = file.name_of(file.groups[row]);
    if let Some(k) = fit.points.iter().position(|n| n == name) {
        return (p - Vector3::from(fit.point_positions[k])).norm();
    }
    fit.planes
        .iter()
        .find(|pl| pl.name == name)
        .map_or(f64::NAN, |pl| {
            (Vector3::from(pl.normal).dot(&p) - pl.offset_m).abs()
        })
}

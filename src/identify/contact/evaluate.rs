//! A model judged on contacts without a fit: each point's consistency (the
//! RMS distance of its rows' predicted tool points to their mean), each
//! known distance's error and each plane's flatness, millimetres — the
//! figures of [`super::holdout`] for one model.

use super::holdout::figures_of;
use super::tool_points;
use crate::data::ContactFile;
use crate::data::NamedDistance;
use crate::model::{ParamTable, Robot};
use serde::Serialize;

/// One point's consistency under the model.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct PointConsistency {
    /// The point.
    pub point: String,
    /// Its rows.
    pub rows: usize,
    /// RMS distance of its rows' tool points to their mean, mm.
    pub consistency_mm: f64,
}

/// One known distance's error under the model.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct DistanceError {
    /// The first point.
    pub a: String,
    /// The second point.
    pub b: String,
    /// The known distance, mm.
    pub known_mm: f64,
    /// |distance between the two points' means − known|, mm.
    pub error_mm: f64,
}

/// One plane's flatness under the model.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct PlaneFlatness {
    /// The plane.
    pub plane: String,
    /// Its rows.
    pub rows: usize,
    /// Whether the plane was given (else the best-fit plane of the rows).
    pub known: bool,
    /// RMS signed distance of its rows' tool points to it, mm.
    pub rms_mm: f64,
}

/// A model on contacts.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct ContactEvaluation {
    /// Per point.
    pub points: Vec<PointConsistency>,
    /// Consistency pooled over every point's rows, mm.
    pub pooled_mm: f64,
    /// The known distances between the file's points.
    pub distances: Vec<DistanceError>,
    /// The planes.
    pub planes: Vec<PlaneFlatness>,
}

/// `robot` with `table` and tool offset `offset` (end frame, metres) on
/// `file`, with the known `distances` between its points (a distance
/// naming a point the file does not have is left out).
#[must_use]
pub fn evaluate_contacts(
    robot: &Robot,
    table: &ParamTable,
    offset: &[f64; 3],
    file: &ContactFile,
    distances: &[NamedDistance],
) -> ContactEvaluation {
    let t = tool_points(robot, table, offset, &file.qs);
    let f = figures_of(&t, &t, file, distances);
    ContactEvaluation {
        points: f
            .points
            .into_iter()
            .map(|p| PointConsistency {
                point: p.point,
                rows: p.rows,
                consistency_mm: p.nominal_mm,
            })
            .collect(),
        pooled_mm: f.nominal_mm,
        distances: f
            .distances
            .into_iter()
            .map(|d| DistanceError {
                a: d.a,
                b: d.b,
                known_mm: d.known_mm,
                error_mm: d.nominal_error_mm,
            })
            .collect(),
        planes: f
            .planes
            .into_iter()
            .map(|p| PlaneFlatness {
                plane: p.plane,
                rows: p.rows,
                known: p.known,
                rms_mm: p.nominal_mm,
            })
            .collect(),
    }
}

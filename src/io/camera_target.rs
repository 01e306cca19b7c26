//! A camera's target: a set of points in the target's own frame (metres),
//! each with an integer id that observation files name.
//!
//! A YAML file holds either a checkerboard's inner corners
//!
//! ```yaml
//! checkerboard: {rows: 6, cols: 9, square: 0.025}
//! ```
//!
//! (`rows × cols` inner corners, ids `0 … rows·cols − 1` row by row as
//! OpenCV's `findChessboardCorners` returns them for a pattern size `(cols,
//! rows)`: id `i·cols + j` at `(j·square, i·square, 0)`), or an explicit
//! list
//!
//! ```yaml
//! points:
//!   - {id: 0, xyz: [0.0, 0.0, 0.0]}
//!   - {id: 17, xyz: [0.05, 0.0, 0.0]}
//! ```
//!
//! (AprilTag centres, ChArUco corners with their ids). Refused: both or
//! neither, a checkerboard of fewer than 2 × 2 corners or a square that is
//! not a finite length > 0, an id given twice, a point that is not three
//! finite numbers, fewer than 4 points, and points all on one line (a
//! camera cannot place such a target). Errors name the file, line and
//! column.

use crate::error::{Error, Result};
use nalgebra::Vector3;
use serde::Deserialize;
use serde_saphyr::Spanned;
use std::path::Path;

/// The points of a target.
#[derive(Clone, Debug, PartialEq)]
pub struct Target {
    /// Each point's id.
    pub ids: Vec<i64>,
    /// Each point in the target's frame, metres.
    pub points: Vec<Vector3<f64>>,
}

impl Target {
    /// A checkerboard's `rows × cols` inner corners, `square` metres apart
    /// (see the module documentation).
    #[must_use]
    pub fn checkerboard(rows: usize, cols: usize, square: f64) -> Self {
        let n = rows * cols;
        Self {
            ids: (0..n as i64).collect(),
            points: (0..n)
                .map(|k| Vector3::new((k % cols) as f64 * square, (k / cols) as f64 * square, 0.0))
                .collect(),
        }
    }

    /// The index of the point with id `id`.
    #[must_use]
    pub fn index_of(&self, id: i64) -> Option<usize> {
        self.ids.iter().position(|&i| i == id)
    }

    /// The centroid of the points.
    #[must_use]
    pub fn centroid(&self) -> Vector3<f64> {
        self.points.iter().sum::<Vector3<f64>>() / self.points.len().max(1) as f64
    }
}

#[derive(Deserialize)]
struct Board {
    rows: Spanned<i64>,
    cols: Spanned<i64>,
    square: Spanned<f64>,
}

#[derive(Deserialize)]
struct PointEntry {
    id: Spanned<i64>,
    xyz: Spanned<Vec<f64>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TargetEntry {
    checkerboard: Option<Spanned<Board>>,
    points: Option<Spanned<Vec<Spanned<PointEntry>>>>,
}

/// Reads a target file (see the module documentation).
pub fn read_target(path: &Path) -> Result<Target> {
    let text = super::read::read_text(path)?;
    parse_target(&text, &path.display().to_string())
}

fn at<T>(s: &Spanned<T>) -> String {
    format!(
        "line {}, column {}",
        s.referenced.line(),
        s.referenced.column()
    )
}

/// Parses a target from `text` (from `origin`, for messages).
pub fn parse_target(text: &str, origin: &str) -> Result<Target> {
    let err = |message: String| Error::Parse {
        path: origin.to_string(),
        message,
    };
    let f: TargetEntry = serde_saphyr::from_str(text).map_err(|e| {
        let at = e
            .location()
            .map(|l| format!("line {}, column {}: ", l.line(), l.column()))
            .unwrap_or_default();
        err(format!(
            "{at}not a target file (a 'checkerboard: {{rows, cols, square}}' or a 'points' list of {{id, xyz}}): {}",
            e.without_snippet()
        ))
    })?;
    let t = match (&f.checkerboard, &f.points) {
        (Some(b), None) => board(b),
        (None, Some(p)) => list(p),
        (Some(b), Some(_)) => Err(format!(
            "{}: both 'checkerboard' and 'points'; give one",
            at(b)
        )),
        (None, None) => Err(
            "no 'checkerboard' and no 'points': a target is a checkerboard {rows, cols, square} or a list of points {id, xyz}".into(),
        ),
    }
    .map_err(err)?;
    check_spread(&t).map_err(err)?;
    Ok(t)
}

fn board(b: &Spanned<Board>) -> std::result::Result<Target, String> {
    let count = |v: &Spanned<i64>, key: &str| {
        usize::try_from(v.value)
            .ok()
            .filter(|&n| n >= 2)
            .ok_or_else(|| {
                format!(
                    "{} ('checkerboard.{key}'): {} inner corners; at least 2",
                    at(v),
                    v.value
                )
            })
    };
    let (rows, cols) = (count(&b.value.rows, "rows")?, count(&b.value.cols, "cols")?);
    let sq = &b.value.square;
    if !(sq.value.is_finite() && sq.value > 0.0) {
        return Err(format!(
            "{} ('checkerboard.square'): {} is not a length > 0 (metres)",
            at(sq),
            sq.value
        ));
    }
    if sq.value > 1.0 {
        return Err(format!(
            "{} ('checkerboard.square'): {} m squares; the square is in metres (millimetres?)",
            at(sq),
            sq.value
        ));
    }
    Ok(Target::checkerboard(rows, cols, sq.value))
}

fn list(p: &Spanned<Vec<Spanned<PointEntry>>>) -> std::result::Result<Target, String> {
    let mut t = Target {
        ids: Vec::new(),
        points: Vec::new(),
    };
    let mut first_line = std::collections::HashMap::new();
    for e in &p.value {
        let id = &e.value.id;
        if let Some(l) = first_line.insert(id.value, id.referenced.line()) {
            return Err(format!(
                "{} ('points'): id {} given twice (first on line {l}); each point needs its own id",
                at(id),
                id.value
            ));
        }
        let xyz = &e.value.xyz;
        if xyz.value.len() != 3 || xyz.value.iter().any(|v| !v.is_finite()) {
            return Err(format!(
                "{} ('points', id {}): xyz must be three finite numbers (metres)",
                at(xyz),
                id.value
            ));
        }
        t.ids.push(id.value);
        t.points
            .push(Vector3::new(xyz.value[0], xyz.value[1], xyz.value[2]));
    }
    Ok(t)
}

/// At least 4 points, not all on a line (the rank of the centred points is
/// at least 2, judged relative to their extent).
fn check_spread(t: &Target) -> std::result::Result<(), String> {
    if t.points.len() < 4 {
        return Err(format!(
            "{} points; a target needs at least 4 (a camera places it from its points)",
            t.points.len()
        ));
    }
    let c = t.centroid();
    let m = nalgebra::DMatrix::from_fn(t.points.len(), 3, |i, j| t.points[i][j] - c[j]);
    let sv = m.singular_values();
    if sv[1] <= 1e-9 * sv[0].max(f64::MIN_POSITIVE) {
        return Err("the points lie on one line: a camera cannot place such a target".into());
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_checkerboard_is_its_corners_row_by_row() {
        let t = parse_target("checkerboard: {rows: 3, cols: 4, square: 0.02}\n", "t.yaml").unwrap();
        assert_eq!(t.points.len(), 12);
        assert_eq!(t.points[5], Vector3::new(0.02, 0.02, 0.0));
        assert_eq!(t.index_of(11), Some(11));
        let l = parse_target(
            "points:\n  - {id: 3, xyz: [0, 0, 0]}\n  - {id: 9, xyz: [0.1, 0, 0]}\n  - {id: 1, xyz: [0, 0.1, 0]}\n  - {id: 4, xyz: [0.1, 0.1, 0.01]}\n",
            "l.yaml",
        )
        .unwrap();
        assert_eq!((l.index_of(9), l.index_of(2)), (Some(1), None));
    }

    #[test]
    fn bad_targets_are_refused_with_their_place() {
        let cases = [
            (
                "points:\n  - {id: 3, xyz: [0, 0, 0]}\n  - {id: 3, xyz: [0.1, 0, 0]}\n",
                "line 3",
                "given twice",
            ),
            (
                "checkerboard: {rows: 1, cols: 4, square: 0.02}\n",
                "line 1",
                "at least 2",
            ),
            (
                "checkerboard: {rows: 3, cols: 4, square: 25}\n",
                "line 1",
                "millimetres",
            ),
            (
                "points:\n  - {id: 0, xyz: [0, 0]}\n",
                "line 2",
                "three finite",
            ),
            (
                "points:\n  - {id: 0, xyz: [0, 0, 0]}\n  - {id: 1, xyz: [1, 0, 0]}\n  - {id: 2, xyz: [2, 0, 0]}\n  - {id: 4, xyz: [3, 0, 0]}\n",
                "t.yaml",
                "one line",
            ),
            ("board: 3\n", "line 1", "not a target file"),
        ];
        for (text, place, what) in cases {
            let e = parse_target(text, "t.yaml").unwrap_err().to_string();
            assert!(
                e.starts_with("t.yaml: ") && e.contains(place) && e.contains(what),
                "{e}"
            );
        }
    }
}

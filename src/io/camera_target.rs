//! A camera's target: a set of points in the target's own frame (metres),
//! each with an integer id that observation files name.
//!
//! A YAML file holds one of
//!
//! * a checkerboard's inner corners, `checkerboard: {rows: 6, cols: 9,
//!   square: 0.025}`: `rows × cols` inner corners, ids `0 … rows·cols − 1`
//!   row by row as OpenCV's `findChessboardCorners` returns them for a
//!   pattern size `(cols, rows)`: id `i·cols + j` at `(j·square, i·square,
//!   0)`;
//! * a ChArUco board's chessboard corners, `charuco: {rows: 5, cols: 7,
//!   square: 0.04, marker: 0.03}` (`rows × cols` squares, the markers'
//!   side `marker` < `square`; `dictionary` (OpenCV's name, `DICT_4X4_50`
//!   …) and `legacy_pattern` (OpenCV's `setLegacyPattern`, default
//!   false) say how it is printed, which detecting it in images needs and
//!   the corners do not depend on): the `(rows − 1) × (cols − 1)` inner
//!   corners with OpenCV's ids and positions (`cv2.aruco.CharucoBoard((cols,
//!   rows), square, marker, dictionary).getChessboardCorners()`: id
//!   `i·(cols − 1) + j` at `((j + 1)·square, (i + 1)·square, 0)`), the ids
//!   `interpolateCornersCharuco` / `CharucoDetector` report;
//! * a Kalibr aprilgrid's tag corners, `aprilgrid: {rows: 6, cols: 6,
//!   tag_size: 0.088, tag_spacing: 0.3}` (Kalibr's `tagRows`, `tagCols`,
//!   `tagSize` in metres and `tagSpacing`, the gap between tags as a
//!   ratio of `tagSize`): tag `k` (row `k / cols`, column `k % cols`, row
//!   0 at the bottom) has its lower-left corner at `(c·(1 + s)·t,
//!   r·(1 + s)·t, 0)` and its 4 corners get ids `4k … 4k + 3` in Kalibr's
//!   order: lower left, lower right, upper right, upper left (x right, y
//!   up on the printed face, the AprilTag detector's `p[0..3]`; Kalibr's
//!   `GridCalibrationTargetAprilgrid`, `aslam_cameras_april`). Kalibr's z
//!   axis points out of the printed face, towards the camera that sees it:
//!   the target's [`Target::face`] is `−z` (OpenCV's boards: `+z`);
//! * an explicit list, `points: [{id: 0, xyz: [0.0, 0.0, 0.0]}, …]`
//!   (AprilTag centres, any other target, with their ids).
//!
//! Refused: more than one or none, a grid too small for 4 points, a length
//! that is not a finite number > 0 (or over 1 m: millimetres?), a ChArUco
//! marker not smaller than its square, an id given twice, a point that is
//! not three finite numbers, fewer than 4 points, and points all on one
//! line (a camera cannot place such a target). Errors name the file, the
//! field, line and column.

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
    /// The direction, in the target's frame, from the face a camera sees
    /// into the target: `+z` for OpenCV's boards and point lists, `−z` for
    /// Kalibr's aprilgrid (see the module documentation).
    pub face: Vector3<f64>,
    /// A checkerboard's inner-corner grid (rows, cols), stored row by
    /// row: its 180° turn and mirrors map it onto itself, so a detector
    /// may label its corners in any of those orders
    /// ([`crate::identify::camera::start::labels`]); `None` for targets
    /// with unique ids.
    pub grid: Option<(usize, usize)>,
    /// A ChArUco board's printed pattern (`charuco:` targets), which a
    /// detector needs; `None` for other targets.
    pub charuco: Option<CharucoPattern>,
    /// A Kalibr aprilgrid's layout (`aprilgrid:` targets), which a
    /// detector needs; `None` for other targets.
    pub aprilgrid: Option<AprilgridPattern>,
}

/// A Kalibr aprilgrid as printed (see the module documentation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AprilgridPattern {
    /// Tags down (Kalibr's `tagRows`).
    pub rows: usize,
    /// Tags across (Kalibr's `tagCols`).
    pub cols: usize,
    /// A tag's side, m (Kalibr's `tagSize`).
    pub tag_size: f64,
    /// The gap between tags over the tag's side (Kalibr's `tagSpacing`).
    pub tag_spacing: f64,
}

/// A ChArUco board as printed (see the module documentation).
#[derive(Clone, Debug, PartialEq)]
pub struct CharucoPattern {
    /// Squares down.
    pub rows: usize,
    /// Squares across.
    pub cols: usize,
    /// A square's side, m.
    pub square: f64,
    /// A marker's side, m.
    pub marker: f64,
    /// The markers' ArUco dictionary (OpenCV's name), when the file gives it.
    pub dictionary: Option<String>,
    /// OpenCV's legacy pattern (`setLegacyPattern(true)`, the layout before
    /// OpenCV 4.6: on a board with an even number of rows, marker 0 in the
    /// top-left square).
    pub legacy_pattern: bool,
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
            face: Vector3::z(),
            grid: Some((rows, cols)),
            charuco: None,
            aprilgrid: None,
        }
    }

    /// A ChArUco board of `rows × cols` squares of side `square`: its
    /// `(rows − 1) × (cols − 1)` inner chessboard corners with OpenCV's ids
    /// and positions (see the module documentation; the markers' side
    /// does not move them).
    #[must_use]
    pub fn charuco(rows: usize, cols: usize, square: f64) -> Self {
        let mut t = Self::checkerboard(rows - 1, cols - 1, square);
        t.grid = None;
        for p in &mut t.points {
            *p += Vector3::new(square, square, 0.0);
        }
        t
    }

    /// A Kalibr aprilgrid of `rows × cols` tags of side `tag_size`, tags
    /// `tag_spacing · tag_size` apart: tag `k`'s corners, ids `4k … 4k +
    /// 3` (see the module documentation).
    #[must_use]
    pub fn aprilgrid(rows: usize, cols: usize, tag_size: f64, tag_spacing: f64) -> Self {
        let pitch = (1.0 + tag_spacing) * tag_size;
        // Kalibr's corner order: lower left, lower right, upper right,
        // upper left.
        let corners = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        let mut t = Self {
            ids: (0..(4 * rows * cols) as i64).collect(),
            points: Vec::with_capacity(4 * rows * cols),
            face: -Vector3::z(),
            grid: None,
            charuco: None,
            aprilgrid: Some(AprilgridPattern {
                rows,
                cols,
                tag_size,
                tag_spacing,
            }),
        };
        for k in 0..rows * cols {
            let (r, c) = ((k / cols) as f64, (k % cols) as f64);
            for [dx, dy] in corners {
                t.points.push(Vector3::new(
                    c * pitch + dx * tag_size,
                    r * pitch + dy * tag_size,
                    0.0,
                ));
            }
        }
        t
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

/// A grid's size as the file wrote it: a number, or what else stood there
/// (refused with its field named, [`count`] and [`length`]).
#[derive(Debug)]
enum Num {
    Value(f64),
    Other(String),
}

impl<'de> Deserialize<'de> for Num {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        struct V;
        impl<'de> serde::de::Visitor<'de> for V {
            type Value = Num;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a number")
            }
            fn visit_i64<E>(self, v: i64) -> std::result::Result<Num, E> {
                Ok(Num::Value(v as f64))
            }
            fn visit_u64<E>(self, v: u64) -> std::result::Result<Num, E> {
                Ok(Num::Value(v as f64))
            }
            fn visit_f64<E>(self, v: f64) -> std::result::Result<Num, E> {
                Ok(Num::Value(v))
            }
            fn visit_bool<E>(self, v: bool) -> std::result::Result<Num, E> {
                Ok(Num::Other(v.to_string()))
            }
            fn visit_str<E>(self, v: &str) -> std::result::Result<Num, E> {
                Ok(Num::Other(format!("'{v}'")))
            }
            fn visit_unit<E>(self) -> std::result::Result<Num, E> {
                Ok(Num::Other("nothing".into()))
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(
                self,
                mut a: A,
            ) -> std::result::Result<Num, A::Error> {
                while a.next_element::<serde::de::IgnoredAny>()?.is_some() {}
                Ok(Num::Other("a list".into()))
            }
            fn visit_map<A: serde::de::MapAccess<'de>>(
                self,
                mut a: A,
            ) -> std::result::Result<Num, A::Error> {
                while a
                    .next_entry::<serde::de::IgnoredAny, serde::de::IgnoredAny>()?
                    .is_some()
                {}
                Ok(Num::Other("a mapping".into()))
            }
        }
        d.deserialize_any(V)
    }
}

#[derive(Deserialize)]
struct Board {
    rows: Spanned<Num>,
    cols: Spanned<Num>,
    square: Spanned<Num>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Charuco {
    rows: Spanned<Num>,
    cols: Spanned<Num>,
    square: Spanned<Num>,
    marker: Spanned<Num>,
    dictionary: Option<Spanned<String>>,
    legacy_pattern: Option<bool>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Aprilgrid {
    rows: Spanned<Num>,
    cols: Spanned<Num>,
    tag_size: Spanned<Num>,
    tag_spacing: Spanned<Num>,
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
    charuco: Option<Spanned<Charuco>>,
    aprilgrid: Option<Spanned<Aprilgrid>>,
    points: Option<Spanned<Vec<Spanned<PointEntry>>>>,
}

/// The four kinds a target file may give, for messages.
const KINDS: &str = "a 'checkerboard: {rows, cols, square}', a 'charuco: {rows, cols, square, marker, dictionary, legacy_pattern}', an 'aprilgrid: {rows, cols, tag_size, tag_spacing}' or a 'points' list of {id, xyz}";

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
            "{at}not a target file ({KINDS}): {}",
            e.without_snippet()
        ))
    })?;
    let given: Vec<String> = [
        f.checkerboard.as_ref().map(|b| (at(b), "checkerboard")),
        f.charuco.as_ref().map(|b| (at(b), "charuco")),
        f.aprilgrid.as_ref().map(|b| (at(b), "aprilgrid")),
        f.points.as_ref().map(|b| (at(b), "points")),
    ]
    .into_iter()
    .flatten()
    .map(|(place, key)| format!("'{key}' ({place})"))
    .collect();
    if given.len() > 1 {
        return Err(err(format!("{}; give one", given.join(" and "))));
    }
    let t = if let Some(b) = &f.checkerboard {
        board(b)
    } else if let Some(b) = &f.charuco {
        charuco(b)
    } else if let Some(b) = &f.aprilgrid {
        aprilgrid(b)
    } else if let Some(p) = &f.points {
        list(p)
    } else {
        Err(format!("no target: give {KINDS}"))
    }
    .map_err(err)?;
    check_spread(&t).map_err(err)?;
    Ok(t)
}

/// A count of a grid's `what` (`key` in `kind`): a whole number, at
/// least `least`.
fn count(
    v: &Spanned<Num>,
    kind: &str,
    key: &str,
    what: &str,
    least: usize,
) -> std::result::Result<usize, String> {
    match &v.value {
        Num::Value(n) if n.fract() == 0.0 && *n >= least as f64 && *n <= 1e6 => Ok(*n as usize),
        Num::Value(n) => Err(format!(
            "{} ('{kind}.{key}'): {n} {what}; a whole number, at least {least}",
            at(v)
        )),
        Num::Other(o) => Err(format!(
            "{} ('{kind}.{key}'): {o} is not a number of {what}",
            at(v)
        )),
    }
}

/// A positive finite number (`key` in `kind`), else what is wrong with it
/// (`unit` names what it should be).
fn positive(
    v: &Spanned<Num>,
    kind: &str,
    key: &str,
    unit: &str,
) -> std::result::Result<f64, String> {
    match &v.value {
        Num::Value(n) if n.is_finite() && *n > 0.0 => Ok(*n),
        Num::Value(n) => Err(format!("{} ('{kind}.{key}'): {n} is not {unit}", at(v))),
        Num::Other(o) => Err(format!("{} ('{kind}.{key}'): {o} is not {unit}", at(v))),
    }
}

/// A length in metres (`key` in `kind`): finite, > 0 and at most 1 m.
fn length(v: &Spanned<Num>, kind: &str, key: &str) -> std::result::Result<f64, String> {
    let l = positive(v, kind, key, "a length > 0 (metres)")?;
    if l > 1.0 {
        return Err(format!(
            "{} ('{kind}.{key}'): {l} m; lengths are in metres (millimetres?)",
            at(v)
        ));
    }
    Ok(l)
}

/// Bytes a target point takes while the target is made and checked: its
/// id, its position, and its row of the spread check's matrix.
const BYTES_PER_POINT: usize = 8 + 2 * 3 * 8;

/// Refuses a grid of `points` points (`rows × cols` `what` of `kind`, at
/// `b`'s place in the file) whose memory would exceed the budget
/// ([`crate::resources::MemoryBudget`]), with the figure, before it is
/// made.
fn within_memory<T>(
    b: &Spanned<T>,
    kind: &str,
    (rows, cols): (usize, usize),
    what: &str,
    points: usize,
) -> std::result::Result<(), String> {
    let bytes = crate::resources::bytes_of(points, BYTES_PER_POINT);
    let what = format!(
        "{} ('{kind}'): {rows} × {cols} {what}, {points} target points,",
        at(b)
    );
    match crate::resources::MemoryBudget::from_env() {
        Ok(m) => m.check(&what, bytes).map_err(|e| e.to_string()),
        Err(e) => Err(e.to_string()),
    }
}

fn board(b: &Spanned<Board>) -> std::result::Result<Target, String> {
    let (rows, cols) = (
        count(&b.value.rows, "checkerboard", "rows", "inner corners", 2)?,
        count(&b.value.cols, "checkerboard", "cols", "inner corners", 2)?,
    );
    let sq = length(&b.value.square, "checkerboard", "square")?;
    let points = rows.saturating_mul(cols);
    within_memory(b, "checkerboard", (rows, cols), "inner corners", points)?;
    Ok(Target::checkerboard(rows, cols, sq))
}

fn charuco(b: &Spanned<Charuco>) -> std::result::Result<Target, String> {
    let c = &b.value;
    let (rows, cols) = (
        count(&c.rows, "charuco", "rows", "squares", 3)?,
        count(&c.cols, "charuco", "cols", "squares", 3)?,
    );
    let square = length(&c.square, "charuco", "square")?;
    let marker = length(&c.marker, "charuco", "marker")?;
    let points = (rows - 1).saturating_mul(cols - 1);
    within_memory(b, "charuco", (rows, cols), "squares", points)?;
    if marker >= square {
        return Err(format!(
            "{} ('charuco.marker'): a {marker} m marker in a {square} m square; the marker must be smaller",
            at(&c.marker)
        ));
    }
    let dictionary = match &c.dictionary {
        Some(d) if calib_targets_charuco::resolve_dictionary(&d.value).is_none() => {
            return Err(format!(
                "{} ('charuco.dictionary'): '{}' is not an ArUco dictionary activecal knows (OpenCV's names: DICT_4X4_50 … DICT_7X7_1000, DICT_ARUCO_ORIGINAL, DICT_APRILTAG_36h11 …)",
                at(d),
                d.value
            ));
        }
        d => d.as_ref().map(|d| d.value.clone()),
    };
    let mut t = Target::charuco(rows, cols, square);
    t.charuco = Some(CharucoPattern {
        rows,
        cols,
        square,
        marker,
        dictionary,
        legacy_pattern: c.legacy_pattern.unwrap_or(false),
    });
    Ok(t)
}

fn aprilgrid(b: &Spanned<Aprilgrid>) -> std::result::Result<Target, String> {
    let g = &b.value;
    let (rows, cols) = (
        count(&g.rows, "aprilgrid", "rows", "tags", 1)?,
        count(&g.cols, "aprilgrid", "cols", "tags", 1)?,
    );
    let size = length(&g.tag_size, "aprilgrid", "tag_size")?;
    let points = rows.saturating_mul(cols).saturating_mul(4);
    within_memory(b, "aprilgrid", (rows, cols), "tags", points)?;
    let spacing = positive(
        &g.tag_spacing,
        "aprilgrid",
        "tag_spacing",
        "a ratio > 0 (the gap between tags over the tag's size, Kalibr's tagSpacing)",
    )?;
    Ok(Target::aprilgrid(rows, cols, size, spacing))
}

fn list(p: &Spanned<Vec<Spanned<PointEntry>>>) -> std::result::Result<Target, String> {
    let mut t = Target {
        ids: Vec::new(),
        points: Vec::new(),
        face: Vector3::z(),
        grid: None,
        charuco: None,
        aprilgrid: None,
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

    /// A ChArUco board of 4 × 5 squares: its 3 × 4 inner corners, id
    /// `i·4 + j` one square in from the board's corner; a 2 × 1 aprilgrid:
    /// tag 1's corners 4 … 7 one pitch `(1 + s)·t` to the right, in
    /// Kalibr's order (lower left, lower right, upper right, upper left),
    /// seen from −z.
    #[test]
    fn charuco_and_aprilgrid_points() {
        let t = parse_target(
            "charuco: {rows: 4, cols: 5, square: 0.04, marker: 0.03, dictionary: DICT_4X4_50}\n",
            "c.yaml",
        )
        .unwrap();
        assert_eq!(t.points.len(), 12);
        assert_eq!(t.ids, (0..12).collect::<Vec<i64>>());
        let near = |a: Vector3<f64>, b: [f64; 3]| (a - Vector3::from(b)).norm() < 1e-15;
        assert!(near(t.points[0], [0.04, 0.04, 0.0]));
        assert!(near(t.points[6], [0.12, 0.08, 0.0]), "{:?}", t.points[6]);
        assert_eq!(t.face, Vector3::z());
        let p = t.charuco.as_ref().unwrap();
        assert_eq!(p.dictionary.as_deref(), Some("DICT_4X4_50"));
        assert!(!p.legacy_pattern);
        let e = parse_target(
            "charuco: {rows: 4, cols: 5, square: 0.04, marker: 0.03,\n  dictionary: DICT_9X9_1}\n",
            "c.yaml",
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("c.yaml") && e.contains("line 2") && e.contains("DICT_9X9_1"),
            "{e}"
        );
        let g = parse_target(
            "aprilgrid: {rows: 1, cols: 2, tag_size: 0.05, tag_spacing: 0.3}\n",
            "g.yaml",
        )
        .unwrap();
        assert_eq!(g.ids, (0..8).collect::<Vec<i64>>());
        let x0 = 1.3 * 0.05;
        for (k, want) in [
            [x0, 0.0, 0.0],
            [x0 + 0.05, 0.0, 0.0],
            [x0 + 0.05, 0.05, 0.0],
            [x0, 0.05, 0.0],
        ]
        .iter()
        .enumerate()
        {
            assert!(near(g.points[4 + k], *want), "{k}: {:?}", g.points[4 + k]);
        }
        assert_eq!(g.face, -Vector3::z());
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
                "('checkerboard.rows'): 1 inner corners; a whole number, at least 2",
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
            (
                "charuco: {rows: 4, cols: 5, square: 0.04, marker: 0.05}\n",
                "line 1",
                "'charuco.marker'): a 0.05 m marker in a 0.04 m square",
            ),
            (
                "charuco: {rows: 4, cols: 2, square: 0.04, marker: 0.03}\n",
                "line 1",
                "'charuco.cols'): 2 squares; a whole number, at least 3",
            ),
            (
                "charuco:\n  rows: 4\n  cols: 5\n  square: -0.04\n  marker: 0.03\n",
                "line 4",
                "'charuco.square'): -0.04 is not a length > 0",
            ),
            (
                "aprilgrid: {rows: 6, cols: 6, tag_size: 88, tag_spacing: 0.3}\n",
                "line 1",
                "'aprilgrid.tag_size'): 88 m",
            ),
            (
                "aprilgrid:\n  rows: 6\n  cols: 6\n  tag_size: 0.088\n  tag_spacing: 0\n",
                "line 5",
                "'aprilgrid.tag_spacing'): 0 is not a ratio > 0",
            ),
            (
                "aprilgrid: {rows: 0, cols: 6, tag_size: 0.088, tag_spacing: 0.3}\n",
                "line 1",
                "'aprilgrid.rows'): 0 tags; a whole number, at least 1",
            ),
            (
                "aprilgrid: {rows: 6, cols: 6, tagSize: 0.088, tag_spacing: 0.3}\n",
                "line 1",
                "tagSize",
            ),
            (
                "aprilgrid: {rows: 6, cols: 6, tag_size: 0.088, tag_spacing: 0.3}\ncheckerboard: {rows: 3, cols: 4, square: 0.02}\n",
                "line 2",
                "'checkerboard' (line 2, column 15) and 'aprilgrid' (line 1",
            ),
            (
                "charuco: {rows: four, cols: 5, square: 0.04, marker: 0.03}\n",
                "line 1, column 17",
                "('charuco.rows'): 'four' is not a number of squares",
            ),
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

//! Contact files: joint configurations recorded with the tool touching
//! named fixed points ([`crate::measure::contact`]), no measured position.
//!
//! A CSV whose header has a `point` column: one column per joint (named as
//! the robot's joints or `q1`…`qN`, as in [`super::measurements`]) and the
//! name of the point the row touches (`front_left/0`). Every point needs at
//! least [`MIN_ROWS_PER_POINT`] rows.
//!
//! A `plane` column (instead of `point`, or beside it) names the plane a row
//! touches: rows with the same plane name touch one plane (unknown unless
//! made known with [`ContactFile::set_known_planes`]); a plane needs at
//! least [`MIN_ROWS_PER_PLANE`] rows. With both columns, each row names
//! exactly one of a point and a plane (the other cell empty). A file with measured positions
//! (`x1`, `x`, …) or orientations and a `point` column is refused: a
//! contact has no measured position.

use super::table::parse_csv;
use crate::error::{Error, Result};
use crate::measure::contact::{Plane, PlaneKind};
use crate::model::Robot;
use crate::units::{JointSource, Units, joint_names, joint_values_to_model_units};
use std::path::Path;

/// Fewest rows a point needs: its 3 coordinates are unknowns of the fit, so
/// fewer rows than 3 leave nothing of the point's rows to calibrate with.
pub const MIN_ROWS_PER_POINT: usize = 3;

/// Fewest rows a plane needs: an unknown plane has 3 unknowns (its normal's
/// 2 and its offset), and 3 points are the fewest that span a plane.
pub const MIN_ROWS_PER_PLANE: usize = 3;

use crate::data::ContactFile;

/// The name of the column that names the plane a row touches.
pub const PLANE_COLUMN: &str = "plane";

/// The name of the column that makes a CSV a contact file.
pub const POINT_COLUMN: &str = "point";

/// Whether CSV `text`'s header has a [`POINT_COLUMN`] or a
/// [`PLANE_COLUMN`] (a contact file).
#[must_use]
pub fn has_point_column(text: &str) -> bool {
    header_line(text).is_some_and(|(_, h)| {
        split(h)
            .iter()
            .any(|c| c == POINT_COLUMN || c == PLANE_COLUMN)
    })
}

/// Reads a contact CSV for `robot` in `units`.
pub fn read_contacts(path: &Path, robot: &Robot, units: Units) -> Result<ContactFile> {
    let origin = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| Error::Io {
        path: origin.clone(),
        cause: e,
    })?;
    parse_contacts(&text, &origin, robot, units)
}

fn header_line(text: &str) -> Option<(usize, &str)> {
    text.lines()
        .enumerate()
        .map(|(i, l)| (i, l.trim_end_matches('\r')))
        .find(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'))
}

fn split(line: &str) -> Vec<String> {
    line.split(',')
        .map(|c| c.trim().trim_matches('"').trim().to_string())
        .collect()
}

/// Parses contact CSV `text` (from `origin`, for messages).
pub fn parse_contacts(
    text: &str,
    origin: &str,
    robot: &Robot,
    units: Units,
) -> Result<ContactFile> {
    let err = |message: String| Error::Parse {
        path: origin.to_string(),
        message,
    };
    let (hidx, header) = header_line(text).ok_or_else(|| err("empty file".into()))?;
    let columns = split(header);
    let find = |name: &str| columns.iter().position(|c| c == name);
    let (pc, lc) = (find(POINT_COLUMN), find(PLANE_COLUMN));
    if pc.is_none() && lc.is_none() {
        return Err(err(format!(
            "no '{POINT_COLUMN}' or '{PLANE_COLUMN}' column"
        )));
    }
    refuse_measured_columns(&columns, &err)?;
    // The names, then the numeric rest of the table (same lines).
    let name_cols: Vec<usize> = [pc, lc].into_iter().flatten().collect();
    let (numeric, cells) = split_name_columns(text, hidx, &name_cols, &err)?;
    let names = touched(&cells, pc.is_some(), &name_cols, &err)?;
    let t = parse_csv(&numeric, origin)?;
    let joint_cols = joint_columns(robot, &t.columns, &err)?;
    let mut qs: Vec<Vec<f64>> = Vec::with_capacity(t.rows.len());
    for (row, &line) in t.rows.iter().zip(&t.lines) {
        let q = joint_cols
            .iter()
            .map(|&c| {
                let v = row[c];
                if v.is_finite() {
                    Ok(v)
                } else {
                    Err(err(format!(
                        "line {line}, column '{}': {v} is not a finite number",
                        t.columns[c]
                    )))
                }
            })
            .collect::<Result<Vec<f64>>>()?;
        qs.push(q);
    }
    let rows: Vec<String> = t.lines.iter().map(|l| format!("line {l}")).collect();
    let jcols: Vec<String> = joint_cols.iter().map(|&c| t.columns[c].clone()).collect();
    let source = JointSource {
        file: origin,
        rows: &rows,
        columns: &jcols,
    };
    joint_values_to_model_units(robot, units, &source, &mut qs)?;
    let (points, planes, groups) = group_rows(&names, &t.lines, &err)?;
    Ok(ContactFile {
        origin: origin.to_string(),
        qs,
        groups,
        points,
        planes,
        lines: t.lines,
    })
}

/// A `point` column beside measured positions or orientations is refused.
fn refuse_measured_columns(columns: &[String], err: &dyn Fn(String) -> Error) -> Result<()> {
    let measured = |c: &str| {
        let stem = c.trim_end_matches(|ch: char| ch.is_ascii_digit());
        matches!(
            stem,
            "x" | "y" | "z" | "phix" | "phiy" | "phiz" | "qw" | "qx" | "qy" | "qz"
        )
    };
    if let Some(c) = columns.iter().find(|c| measured(c)) {
        return Err(err(format!(
            "a '{POINT_COLUMN}' column with measured coordinates (column '{c}'): a contact file records joint values and the point touched, no measured position or orientation (drop the '{POINT_COLUMN}' column to calibrate from the measured positions, or the coordinates to calibrate from contacts)"
        )));
    }
    Ok(())
}

/// Removes columns `cols` (increasing) from every data line of `text`,
/// returning the rest (same line numbers) and each data row's cells of
/// them (trimmed) with its line.
fn split_name_columns(
    text: &str,
    hidx: usize,
    cols: &[usize],
    err: &dyn Fn(String) -> Error,
) -> Result<(String, Vec<(usize, Vec<String>)>)> {
    let mut out = String::with_capacity(text.len());
    let mut names = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        let l = raw.trim_end_matches('\r');
        let skip = l.trim().is_empty() || l.trim_start().starts_with('#');
        if skip {
            out.push_str(l);
        } else {
            let mut cells: Vec<&str> = l.split(',').collect();
            let last = cols.iter().copied().max().unwrap_or(0);
            if last >= cells.len() {
                return Err(err(format!(
                    "line {}: {} cells, no cell for column {}",
                    i + 1,
                    cells.len(),
                    last + 1
                )));
            }
            let mut row: Vec<String> = Vec::with_capacity(cols.len());
            for &c in cols.iter().rev() {
                row.push(cells.remove(c).trim().trim_matches('"').trim().to_string());
            }
            row.reverse();
            if i > hidx {
                names.push((i + 1, row));
            }
            out.push_str(&cells.join(","));
        }
        out.push('\n');
    }
    Ok((out, names))
}

/// What a row touches, with its line.
enum Touch {
    Point(String),
    Plane(String),
}

/// Each row's point or plane: exactly one of its name cells (`cells` of
/// the columns `cols`, the point column first when `has_point`) is given.
fn touched(
    cells: &[(usize, Vec<String>)],
    has_point: bool,
    cols: &[usize],
    err: &dyn Fn(String) -> Error,
) -> Result<Vec<(usize, Touch)>> {
    let label = |k: usize| {
        let name = if has_point && k == 0 {
            POINT_COLUMN
        } else {
            PLANE_COLUMN
        };
        format!("column {} ('{name}')", cols[k] + 1)
    };
    cells
        .iter()
        .map(|(line, row)| {
            let given: Vec<usize> = (0..row.len()).filter(|&k| !row[k].is_empty()).collect();
            match given.as_slice() {
                [k] if has_point && *k == 0 => Ok((*line, Touch::Point(row[0].clone()))),
                [k] => Ok((*line, Touch::Plane(row[*k].clone()))),
                [] => Err(err(format!(
                    "line {line}, {}: empty name (a row names the {} it touches)",
                    label(0),
                    if cols.len() == 2 { "point or the plane" } else if has_point { "point" } else { "plane" }
                ))),
                _ => Err(err(format!(
                    "line {line}: both a point ('{}', {}) and a plane ('{}', {}): a row touches one (leave the other cell empty)",
                    row[0],
                    label(0),
                    row[1],
                    label(1)
                ))),
            }
        })
        .collect()
}

/// The columns of the robot's joints, by name or `qJ`.
fn joint_columns(
    robot: &Robot,
    columns: &[String],
    err: &dyn Fn(String) -> Error,
) -> Result<Vec<usize>> {
    joint_names(robot)
        .iter()
        .enumerate()
        .map(|(j, n)| {
            let alias = format!("q{}", j + 1);
            columns
                .iter()
                .position(|c| c == n || *c == alias)
                .ok_or_else(|| {
                    err(format!(
                        "no column for joint '{n}' (joint {} of robot '{}'; name the column '{n}' or '{alias}'); the header has {}",
                        j + 1,
                        robot.name,
                        columns.join(", ")
                    ))
                })
        })
        .collect()
}

/// Point and plane names in order of appearance and each row's group
/// (points first, then planes); a point with fewer than
/// [`MIN_ROWS_PER_POINT`] rows or a plane with fewer than
/// [`MIN_ROWS_PER_PLANE`] is an error naming its lines.
fn group_rows(
    names: &[(usize, Touch)],
    lines: &[usize],
    err: &dyn Fn(String) -> Error,
) -> Result<(Vec<String>, Vec<Plane>, Vec<usize>)> {
    debug_assert_eq!(names.len(), lines.len());
    let mut points: Vec<String> = Vec::new();
    let mut planes: Vec<String> = Vec::new();
    let index = |list: &mut Vec<String>, n: &String| {
        list.iter().position(|p| p == n).unwrap_or_else(|| {
            list.push(n.clone());
            list.len() - 1
        })
    };
    let which: Vec<std::result::Result<usize, usize>> = names
        .iter()
        .map(|(_, t)| match t {
            Touch::Point(n) => Ok(index(&mut points, n)),
            Touch::Plane(n) => Err(index(&mut planes, n)),
        })
        .collect();
    let groups: Vec<usize> = which
        .iter()
        .map(|w| match *w {
            Ok(g) => g,
            Err(l) => points.len() + l,
        })
        .collect();
    let all = points.iter().map(|p| {
        (
            "point",
            p,
            MIN_ROWS_PER_POINT,
            "its 3 coordinates are unknowns",
        )
    });
    let all = all.chain(planes.iter().map(|p| {
        (
            "plane",
            p,
            MIN_ROWS_PER_PLANE,
            "3 points span a plane; an unknown one has 3 unknowns",
        )
    }));
    for (g, (what, p, min, why)) in all.enumerate() {
        let at: Vec<String> = names
            .iter()
            .zip(&groups)
            .filter(|(_, k)| **k == g)
            .map(|((l, _), _)| l.to_string())
            .collect();
        if at.len() < min {
            return Err(err(format!(
                "{what} '{p}' has {} row(s) (line {}): a {what} needs at least {min} ({why})",
                at.len(),
                at.join(", ")
            )));
        }
    }
    let planes = planes
        .into_iter()
        .map(|name| Plane {
            name,
            // The chart's centre is set at the start of a fit
            // (`start_planes`); any non-zero normal here.
            kind: PlaneKind::Unknown {
                n0: [0.0, 0.0, 1.0],
            },
        })
        .collect();
    Ok((points, planes, groups))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn arm() -> Robot {
        Robot::builtin("ur5").unwrap()
    }

    fn row(i: usize, p: &str) -> String {
        format!("0.{i},0.1,0.2,0.3,0.4,0.5,{p}\n")
    }

    #[test]
    fn reads_points_and_lines() {
        let mut t = "q1,q2,q3,q4,q5,q6,point\n".to_string();
        for i in 0..3 {
            t += &row(i, "a/0");
            t += &row(i, "b/1");
        }
        let f = parse_contacts(&t, "c.csv", &arm(), Units::default()).unwrap();
        assert_eq!(f.points, ["a/0", "b/1"]);
        assert_eq!(f.groups, [0, 1, 0, 1, 0, 1]);
        assert_eq!(f.lines[1], 3);
        assert_eq!(f.qs[2][0], 0.1);
        assert!(has_point_column(&t));
    }

    #[test]
    fn bad_files_name_the_place() {
        let e = |t: &str| {
            parse_contacts(t, "c.csv", &arm(), Units::default())
                .unwrap_err()
                .to_string()
        };
        let short = format!("q1,q2,q3,q4,q5,q6,point\n{}{}", row(0, "a"), row(1, "a"));
        assert!(
            e(&short).contains("c.csv: point 'a' has 2 row(s) (line 2, 3)"),
            "{}",
            e(&short)
        );
        let with_xyz = "q1,q2,q3,q4,q5,q6,x1,y1,z1,point\n";
        assert!(e(with_xyz).contains("column 'x1'"), "{}", e(with_xyz));
        let no_joint = "q1,q2,point\n1,2,a\n";
        assert!(e(no_joint).contains("joint 3 of robot"), "{}", e(no_joint));
    }
}

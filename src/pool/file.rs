//! Joint configurations from a file, such as a motion planner exports or a
//! measurement campaign recorded: the source of a [`PoolSource::File`] pool
//! and of `select --existing`.
//!
//! Two formats, told apart by the extension (`.json` is JSON, anything else
//! CSV):
//!
//! * **CSV** with a header row naming the joints. A column is a joint when
//!   its name is one of the chain's joints ([`joint_names`]: the URDF joint
//!   names, or the frame labels of a built-in arm) or `q1`…`qN`; the order of
//!   the columns is free, every joint must have one, and other columns
//!   (measured positions, timestamps) are ignored with a note. Blank lines
//!   are skipped.
//! * **JSON** `{"qs": [[...], ...]}` (values in joint order) or
//!   `{"joints": [names], "qs": [...]}` (values in the order of `joints`,
//!   matched by name as CSV columns are), or a design file (`"poses"`,
//!   `"q"`, `"joint_names"`). Other keys (a measurement file's
//!   `points`, `orientations`, `robot`) are ignored with a note; a `robot`
//!   key, when present, must name the robot.
//!
//! Every value is checked: a value that does not parse is an error naming
//! the file, the row (the 1-based line for CSV, `qs[k]` for JSON) and the
//! column; the values are then converted from the file's [`Units`] and
//! checked against the joint limits by the one rule of every joint-value
//! reader ([`crate::units::joint_values_to_model_units`]).
//!
//! [`PoolSource::File`]: super::PoolSource::File

use crate::error::{Error, Result};
use crate::model::Robot;
use crate::model::robot_ref::{ChainChoice, RobotRef};
pub use crate::units::joint_names;
use crate::units::{JointSource, Units, joint_values_to_model_units};
use std::path::Path;

/// Joint configurations read from a file, in row order.
#[derive(Clone, Debug, PartialEq)]
pub struct Configurations {
    /// Joint values, one vector of `dof` per row, in the robot's joint order.
    pub qs: Vec<Vec<f64>>,
    /// What was ignored (extra columns or keys), for reports.
    pub notes: Vec<String>,
}

/// The `id` of a via configuration in a design's CSV: a configuration the
/// robot moves through between two poses, not a pose (skipped on reading).
pub const VIA_ID: &str = "via";

/// The joint index of a column name: a joint name, or `q1`…`qN`.
fn joint_of(name: &str, names: &[String]) -> Option<usize> {
    if let Some(j) = names.iter().position(|n| n == name) {
        return Some(j);
    }
    let k: usize = name.strip_prefix('q')?.parse().ok()?;
    (1..=names.len()).contains(&k).then(|| k - 1)
}

/// Maps header names to joints: `map[c]` is the joint of column `c`, or
/// `None` for an ignored column. Errors name a joint without a column or a
/// joint with two.
fn map_columns(
    path: &Path,
    header: &[String],
    names: &[String],
) -> Result<(Vec<Option<usize>>, Vec<String>)> {
    let mut map = vec![None; header.len()];
    let mut seen: Vec<Option<usize>> = vec![None; names.len()];
    let mut ignored = Vec::new();
    for (c, h) in header.iter().enumerate() {
        match joint_of(h, names) {
            Some(j) => {
                if let Some(c0) = seen[j] {
                    return Err(parse_err(
                        path,
                        format!(
                            "columns '{}' and '{h}' both give joint {} ({})",
                            header[c0],
                            j + 1,
                            names[j]
                        ),
                    ));
                }
                seen[j] = Some(c);
                map[c] = Some(j);
            }
            None => ignored.push(h.clone()),
        }
    }
    if let Some(j) = seen.iter().position(Option::is_none) {
        return Err(parse_err(
            path,
            format!(
                "no column for joint {} '{}' (columns: {}; a joint column is named by its joint, {}, or q1..q{})",
                j + 1,
                names[j],
                header.join(", "),
                names.join(", "),
                names.len()
            ),
        ));
    }
    Ok((map, ignored))
}

fn parse_err(path: &Path, message: String) -> Error {
    Error::Parse {
        path: path.display().to_string(),
        message,
    }
}

/// Reads the joint configurations of `path` for `robot`, in radians and
/// metres (see the module docs for the formats and checks). An empty file
/// or one without rows is an error.
pub fn read_configurations(path: &Path, robot: &Robot) -> Result<Configurations> {
    read_configurations_in(path, robot, Units::default())
}

/// As [`read_configurations`], for a file whose joint values are in `units`
/// (converted to radians and metres).
pub fn read_configurations_in(path: &Path, robot: &Robot, units: Units) -> Result<Configurations> {
    let len = std::fs::metadata(path)
        .map_err(|cause| Error::Io {
            path: path.display().to_string(),
            cause,
        })?
        .len();
    // The text and its parse live together for a moment: twice the file.
    crate::resources::check_alloc::<u8>(
        &format!("reading {}", path.display()),
        usize::try_from(len.saturating_mul(2)).unwrap_or(usize::MAX),
    )?;
    let text = std::fs::read_to_string(path).map_err(|cause| Error::Io {
        path: path.display().to_string(),
        cause,
    })?;
    let json = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("json"));
    let c = if json {
        parse_json_in(path, &text, robot, units)?
    } else {
        parse_csv_in(path, &text, robot, units)?
    };
    if c.qs.is_empty() {
        return Err(parse_err(
            path,
            "no joint configurations in the file".into(),
        ));
    }
    Ok(c)
}

/// Converts and checks the values read ([`joint_values_to_model_units`]),
/// naming each joint's column as the file does.
fn check_units(
    path: &Path,
    robot: &Robot,
    units: Units,
    header: &[String],
    map: &[Option<usize>],
    rows: &[String],
    qs: &mut [Vec<f64>],
) -> Result<()> {
    let mut columns = joint_names(robot);
    for (c, j) in map.iter().enumerate() {
        if let Some(j) = *j {
            columns[j].clone_from(&header[c]);
        }
    }
    let file = path.display().to_string();
    let source = JointSource {
        file: &file,
        rows,
        columns: &columns,
    };
    joint_values_to_model_units(robot, units, &source, qs)
}

/// Parses CSV text (see the module docs), radians and metres.
pub fn parse_csv(path: &Path, text: &str, robot: &Robot) -> Result<Configurations> {
    parse_csv_in(path, text, robot, Units::default())
}

/// Parses CSV text whose joint values are in `units`.
pub fn parse_csv_in(
    path: &Path,
    text: &str,
    robot: &Robot,
    units: Units,
) -> Result<Configurations> {
    let names = joint_names(robot);
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty());
    let Some((_, header)) = lines.next() else {
        return Err(parse_err(
            path,
            "the file is empty (expected a header row of joint names)".into(),
        ));
    };
    let header: Vec<String> = header
        .split(',')
        .map(|h| h.trim().trim_matches('"').to_string())
        .collect();
    let (map, ignored) = map_columns(path, &header, &names)?;
    let id_column = header.iter().position(|h| h == "id");
    let mut qs = Vec::new();
    let mut rows = Vec::new();
    let mut vias = 0usize;
    for (i, line) in lines {
        let row = format!("line {}", i + 1);
        let cells: Vec<&str> = line.split(',').collect();
        if cells.len() != header.len() {
            return Err(parse_err(
                path,
                format!(
                    "{row}: {} columns, the header has {}",
                    cells.len(),
                    header.len()
                ),
            ));
        }
        if id_column.is_some_and(|c| cells[c].trim().trim_matches('"') == VIA_ID) {
            vias += 1;
            continue;
        }
        let mut q = vec![f64::NAN; names.len()];
        for (c, cell) in cells.iter().enumerate() {
            let Some(j) = map[c] else { continue };
            let cell = cell.trim().trim_matches('"');
            let v: f64 = cell.parse().map_err(|_| {
                parse_err(
                    path,
                    format!(
                        "{row}, column '{}' (joint {}): cannot read '{cell}' as a number",
                        header[c],
                        j + 1
                    ),
                )
            })?;
            q[j] = v;
        }
        qs.push(q);
        rows.push(row);
    }
    check_units(path, robot, units, &header, &map, &rows, &mut qs)?;
    let mut notes = Vec::new();
    if vias > 0 {
        notes.push(format!(
            "{}: {vias} via configuration(s) of a tour (id '{VIA_ID}') skipped: the robot moves through them, it is not measured there",
            path.display()
        ));
    }
    if !ignored.is_empty() {
        notes.push(format!(
            "{}: columns ignored (not joints of the chain): {}",
            path.display(),
            ignored.join(", ")
        ));
    }
    Ok(Configurations { qs, notes })
}

/// Parses JSON text (see the module docs), radians and metres.
pub fn parse_json(path: &Path, text: &str, robot: &Robot) -> Result<Configurations> {
    parse_json_in(path, text, robot, Units::default())
}

/// Parses JSON text whose joint values are in `units`.
pub fn parse_json_in(
    path: &Path,
    text: &str,
    robot: &Robot,
    units: Units,
) -> Result<Configurations> {
    let names = joint_names(robot);
    let v: serde_json::Value =
        serde_json::from_str(text).map_err(|e| parse_err(path, e.to_string()))?;
    let Some(obj) = v.as_object() else {
        return Err(parse_err(
            path,
            "expected an object {\"qs\": [[...], ...]} (optionally with \"joints\": [names])"
                .into(),
        ));
    };
    check_robot_key(path, obj, robot)?;
    // A design file (`select --out`) names its joint vectors `q` and its
    // joints `joint_names`.
    let design = !obj.contains_key("qs") && obj.contains_key("q") && obj.contains_key("poses");
    let (rows_key, joints_key) = if design {
        ("q", "joint_names")
    } else {
        ("qs", "joints")
    };
    let Some(rows) = obj.get(rows_key).and_then(|q| q.as_array()) else {
        return Err(parse_err(
            path,
            "no \"qs\" array of joint vectors (nor a design file's \"q\")".into(),
        ));
    };
    let (map, mut ignored, header) = match obj.get(joints_key) {
        Some(j) => {
            let header: Vec<String> = j
                .as_array()
                .and_then(|a| a.iter().map(|x| x.as_str().map(str::to_string)).collect())
                .ok_or_else(|| {
                    parse_err(path, format!("\"{joints_key}\" must be an array of names"))
                })?;
            let (map, ignored) = map_columns(path, &header, &names)?;
            (map, ignored, header)
        }
        None => (
            (0..names.len()).map(Some).collect(),
            Vec::new(),
            names.clone(),
        ),
    };
    let mut keys: Vec<&str> = obj
        .keys()
        .map(String::as_str)
        .filter(|k| ![rows_key, joints_key, "robot"].contains(k))
        .collect();
    keys.sort_unstable();
    let columns = JsonColumns {
        path,
        rows_key,
        header: &header,
        map: &map,
        dof: names.len(),
    };
    let (mut qs, labels) = columns.read_rows(rows)?;
    check_units(path, robot, units, &header, &map, &labels, &mut qs)?;
    let mut notes = Vec::new();
    if !ignored.is_empty() {
        ignored.sort_unstable();
        notes.push(format!(
            "{}: joints ignored (not in the chain): {}",
            path.display(),
            ignored.join(", ")
        ));
    }
    if !keys.is_empty() {
        notes.push(format!(
            "{}: keys ignored (only the joint values are used): {}",
            path.display(),
            keys.join(", ")
        ));
    }
    Ok(Configurations { qs, notes })
}

/// Errors when the file's `robot` (and `chain`) name another robot.
fn check_robot_key(
    path: &Path,
    obj: &serde_json::Map<String, serde_json::Value>,
    robot: &Robot,
) -> Result<()> {
    let Some(r) = obj.get("robot").and_then(|r| r.as_str()) else {
        return Ok(());
    };
    let chain = obj
        .get("chain")
        .map(|c| serde_json::from_value::<ChainChoice>(c.clone()))
        .transpose()
        .map_err(|e| parse_err(path, format!("\"chain\": {e}")))?;
    let mut named = RobotRef::parse(r).map_err(|e| parse_err(path, e.to_string()))?;
    if let Some(c) = chain {
        named.chain = c;
    }
    if RobotRef::parse(&robot.name).ok().as_ref() != Some(&named) {
        return Err(parse_err(
            path,
            format!("the file is for robot '{named}', not '{}'", robot.name),
        ));
    }
    Ok(())
}

/// How a JSON file's rows map onto the robot's joints.
struct JsonColumns<'a> {
    path: &'a Path,
    /// `qs`, or a design file's `q`.
    rows_key: &'a str,
    /// The names of a row's values.
    header: &'a [String],
    /// For each value of a row, the robot joint it is (`None`: ignored).
    map: &'a [Option<usize>],
    /// Joints of the robot.
    dof: usize,
}

impl JsonColumns<'_> {
    /// Each row's joint values (NaN for a `null`) and its label.
    fn read_rows(&self, rows: &[serde_json::Value]) -> Result<(Vec<Vec<f64>>, Vec<String>)> {
        let (path, width) = (self.path, self.header.len());
        let mut qs = Vec::with_capacity(rows.len());
        let mut labels = Vec::with_capacity(rows.len());
        for (k, r) in rows.iter().enumerate() {
            let row = format!("{}[{k}] (row {})", self.rows_key, k + 1);
            let Some(cells) = r.as_array() else {
                return Err(parse_err(path, format!("{row}: not an array of numbers")));
            };
            if cells.len() != width {
                return Err(parse_err(
                    path,
                    format!("{row}: {} values, expected {width}", cells.len()),
                ));
            }
            let mut q = vec![f64::NAN; self.dof];
            for (c, cell) in cells.iter().enumerate() {
                let Some(j) = self.map[c] else { continue };
                // JSON has no NaN; `null` is how serializers write one.
                q[j] = match cell {
                    serde_json::Value::Null => f64::NAN,
                    x => x.as_f64().ok_or_else(|| {
                        parse_err(
                            path,
                            format!(
                                "{row}, column '{}' (joint {}): {x} is not a number",
                                self.header[c],
                                j + 1
                            ),
                        )
                    })?,
                };
            }
            qs.push(q);
            labels.push(row);
        }
        Ok((qs, labels))
    }
}

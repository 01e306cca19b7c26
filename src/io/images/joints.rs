//! The joint values at which each image was taken: a CSV with one row per
//! image,
//!
//! ```text
//! image,shoulder_pan_joint,…,wrist_3_joint
//! img_000.png,0.1,-1.2,…,0.3
//! ```
//!
//! `image` the image's file name (without its directory), then one column
//! per joint named as in the URDF (as the observations CSV has them,
//! radians and metres unless the units say otherwise, checked against the
//! joints' limits by [`crate::units::joint_values_to_model_units`]). Rows
//! for images not given are allowed (a pattern may pick some of a
//! folder's images). Refused, naming the file and line: a missing column,
//! a value that is not a number, an image named twice.

use crate::error::{Error, Result};
use crate::model::Robot;
use crate::units::{JointSource, Units, joint_names, joint_values_to_model_units};
use std::path::Path;

/// The joint values of each image a joints file names.
#[derive(Clone, Debug, PartialEq)]
pub struct ImageJoints {
    /// The file, for messages.
    pub origin: String,
    /// Each row's image file name.
    pub images: Vec<String>,
    /// Each row's 1-based line in the file.
    pub lines: Vec<usize>,
    /// Each row's joint values, radians and metres.
    pub qs: Vec<Vec<f64>>,
}

impl ImageJoints {
    /// The joint values of the image named `name` (its file name).
    #[must_use]
    pub fn of(&self, name: &str) -> Option<&[f64]> {
        self.images
            .iter()
            .position(|n| n == name)
            .map(|k| self.qs[k].as_slice())
    }
}

/// Reads a joints file for `robot`, joint values in `units`.
pub fn read_image_joints(path: &Path, robot: &Robot, units: Units) -> Result<ImageJoints> {
    let text = super::super::read::read_text(path)?;
    parse_image_joints(&text, &path.display().to_string(), robot, units)
}

/// Parses a joints file's `text` (from `origin`, for messages).
pub fn parse_image_joints(
    text: &str,
    origin: &str,
    robot: &Robot,
    units: Units,
) -> Result<ImageJoints> {
    let err = |message: String| Error::Parse {
        path: origin.to_string(),
        message,
    };
    let mut lines = crate::io::table::csv_lines(text);
    let (hline, header) = lines
        .next()
        .ok_or_else(|| err("empty file: expected a header 'image,<joints>'".into()))?;
    let columns = crate::io::table::header_cells(header);
    let names = joint_names(robot);
    let find = |name: &str, what: &str| {
        columns.iter().position(|c| c == name).ok_or_else(|| {
            err(format!(
                "line {hline}: no '{name}' column ({what}); the header needs image, then the joints ({})",
                names.join(", ")
            ))
        })
    };
    let image = find("image", "each image's file name")?;
    let joints = names
        .iter()
        .map(|n| find(n, "a joint of the robot, named as in the URDF"))
        .collect::<Result<Vec<_>>>()?;
    let mut out = ImageJoints {
        origin: origin.to_string(),
        images: Vec::new(),
        lines: Vec::new(),
        qs: Vec::new(),
    };
    for (line, l) in lines {
        let cells: Vec<&str> = l.split(',').map(str::trim).collect();
        if cells.len() != columns.len() {
            return Err(err(format!(
                "line {line}: {} cells, the header has {}",
                cells.len(),
                columns.len()
            )));
        }
        let name = cells[image].trim_matches('"').to_string();
        if let Some(k) = out.images.iter().position(|n| *n == name) {
            return Err(err(format!(
                "line {line}: image '{name}' already has a row (line {})",
                out.lines[k]
            )));
        }
        let q = joints
            .iter()
            .map(|&k| {
                cells[k].parse::<f64>().map_err(|_| {
                    err(format!(
                        "line {line}, column {} ('{}'): '{}' is not a number",
                        k + 1,
                        columns[k],
                        cells[k]
                    ))
                })
            })
            .collect::<Result<Vec<f64>>>()?;
        out.images.push(name);
        out.lines.push(line);
        out.qs.push(q);
    }
    let rows: Vec<String> = out
        .lines
        .iter()
        .zip(&out.images)
        .map(|(l, n)| format!("line {l} ({n})"))
        .collect();
    let cols: Vec<String> = joints.iter().map(|&k| columns[k].clone()).collect();
    let source = JointSource {
        file: origin,
        rows: &rows,
        columns: &cols,
    };
    joint_values_to_model_units(robot, units, &source, &mut out.qs)?;
    Ok(out)
}

//! The design a run followed: each rest matched to the design's pose it
//! reached (the nearest in joint space, within a tolerance), a rest that
//! reached none left out, a design pose that no kept rest reached named.

use crate::error::{Error, Result};
use crate::model::Robot;
use std::path::Path;

/// The joint values of a design file: `select --out`'s JSON or YAML, or a
/// CSV with a column per joint named as the robot's (an `id` column's `via`
/// rows, the moves between poses, skipped).
pub fn read_design(path: &Path, robot: &Robot) -> Result<Vec<Vec<f64>>> {
    let is_csv = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("csv"));
    if !is_csv {
        return crate::io::design::DesignFile::read(path)?.joint_values(robot);
    }
    let origin = path.display().to_string();
    let text = crate::io::read::read_text(path)?;
    let bad = |message: String| Error::Parse {
        path: origin.clone(),
        message,
    };
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'));
    let (_, head) = lines.next().ok_or_else(|| bad("empty file".into()))?;
    let head: Vec<&str> = head.split(',').map(str::trim).collect();
    let id = head.iter().position(|c| *c == "id");
    let names = crate::io::measurements::joint_names(robot);
    let cols = names
        .iter()
        .map(|n| {
            head.iter().position(|c| c == n).ok_or_else(|| {
                bad(format!(
                    "no column for joint '{n}' (columns: {})",
                    head.join(", ")
                ))
            })
        })
        .collect::<Result<Vec<usize>>>()?;
    let mut qs = Vec::new();
    for (i, line) in lines {
        let cells: Vec<&str> = line.split(',').map(str::trim).collect();
        if id.is_some_and(|k| cells.get(k) == Some(&"via")) {
            continue;
        }
        let q = cols
            .iter()
            .map(|&c| {
                let cell = cells.get(c).copied().unwrap_or("");
                cell.parse::<f64>()
                    .ok()
                    .filter(|v| v.is_finite())
                    .ok_or_else(|| {
                        bad(format!(
                            "line {}, column '{}': '{cell}' is not a number",
                            i + 1,
                            head[c]
                        ))
                    })
            })
            .collect::<Result<Vec<f64>>>()?;
        qs.push(q);
    }
    Ok(qs)
}

/// The design pose nearest to `q` (largest joint difference) and that
/// difference.
#[must_use]
pub fn nearest(q: &[f64], design: &[Vec<f64>]) -> Option<(usize, f64)> {
    design
        .iter()
        .enumerate()
        .map(|(k, d)| {
            let far = q
                .iter()
                .zip(d)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            (k, far)
        })
        .min_by(|a, b| a.1.total_cmp(&b.1))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_nearest_pose_is_by_the_largest_joint_difference() {
        let design = vec![vec![0.0, 0.0], vec![1.0, 0.0], vec![0.3, 0.3]];
        assert_eq!(
            nearest(&[0.9, 0.05], &design),
            Some((1, 0.09999999999999998))
        );
        assert_eq!(nearest(&[0.0, 0.35], &design).map(|n| n.0), Some(2));
        assert_eq!(nearest(&[0.0, 0.2], &design).map(|n| n.0), Some(0));
        assert_eq!(nearest(&[0.0], &[]), None);
    }
}

//! A pool's poses written as `--pool file:` reads them back: CSV or JSON,
//! by the file's name.

use crate::error::{Error, Result};
use crate::pool::Pool;
use crate::pool::summary::{PoolSummary, poses_csv, poses_json};
use std::path::Path;

/// The formats a pool's poses are written in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PosesFormat {
    /// A header of the joint names and `id`, a pose a row.
    Csv,
    /// `{"robot", "joints", "ids", "qs"}`.
    Json,
}

impl PosesFormat {
    /// The format `path`'s extension names (`label`: the front end's name
    /// for the file, in messages).
    ///
    /// # Errors
    /// An extension other than `.csv` or `.json`.
    pub fn of(label: &str, path: &Path) -> Result<Self> {
        match path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .as_deref()
        {
            Some("csv") => Ok(Self::Csv),
            Some("json") => Ok(Self::Json),
            _ => Err(Error::Invalid(format!(
                "{label} {}: the poses are written as .csv or .json; name the file with one of these extensions",
                path.display()
            ))),
        }
    }
}

/// The poses of `pool` (summarised by `summary`) in `format`, at full
/// precision.
#[must_use]
pub fn poses_text(format: PosesFormat, summary: &PoolSummary, pool: &Pool) -> String {
    let qs: Vec<Vec<f64>> = (0..pool.len()).map(|k| pool.q(k)).collect();
    match format {
        PosesFormat::Csv => poses_csv(&summary.joints, &qs, &pool.ids),
        PosesFormat::Json => poses_json(&summary.robot, &summary.joints, &qs, &pool.ids),
    }
}

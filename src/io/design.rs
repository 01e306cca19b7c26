//! Design files: the poses chosen for a calibration, as JSON that `select`
//! writes and `score`, `gap` and `calibrate` read.
//!
//! The required keys are `robot`, `levels` and `poses` (lattice indices), so a
//! hand-written file with only these three is accepted; other keys written by
//! `select` (algorithm, seed, criterion values) are kept as extra information.

use crate::error::{Error, Result};
use crate::model::Robot;
use crate::pool::Pool;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// A design as stored on disk.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct DesignFile {
    /// Robot name (built-in) or path of its description.
    pub robot: String,
    /// Lattice values per joint of the pool the indices refer to.
    pub levels: usize,
    /// Lattice indices of the chosen poses.
    pub poses: Vec<usize>,
    /// Anything else (algorithm, seed, ln_oid, ...), kept as written.
    #[serde(flatten)]
    pub extra: serde_json::Map<String, serde_json::Value>,
}

impl DesignFile {
    /// A design with no extra information.
    #[must_use]
    pub fn new(robot: &str, levels: usize, poses: Vec<usize>) -> Self {
        Self {
            robot: robot.to_string(),
            levels,
            poses,
            extra: serde_json::Map::new(),
        }
    }

    /// Reads and parses a design file.
    pub fn read(path: &Path) -> Result<DesignFile> {
        let text = std::fs::read_to_string(path).map_err(|cause| Error::Io {
            path: path.display().to_string(),
            cause,
        })?;
        serde_json::from_str(&text).map_err(|e| Error::Parse {
            path: path.display().to_string(),
            message: e.to_string(),
        })
    }

    /// Writes the design as pretty JSON. An existing file is only replaced
    /// when `overwrite` is set: nothing the user has is lost without asking.
    pub fn write(&self, path: &Path, overwrite: bool) -> Result<()> {
        if path.exists() && !overwrite {
            return Err(Error::Invalid(format!(
                "{} exists; pass --force to overwrite it",
                path.display()
            )));
        }
        let text = serde_json::to_string_pretty(self).expect("a design serializes");
        std::fs::write(path, text + "\n").map_err(|cause| Error::Io {
            path: path.display().to_string(),
            cause,
        })
    }

    /// Checks the design against a robot and its pool, returning the pool
    /// positions of its poses: the robot name must match, every index must be
    /// in the pool, and no pose may repeat.
    pub fn positions_in(&self, robot: &Robot, pool: &Pool) -> Result<Vec<usize>> {
        if self.robot != robot.name {
            return Err(Error::Invalid(format!(
                "the design is for robot '{}', not '{}'",
                self.robot, robot.name
            )));
        }
        if self.levels != pool.lattice.levels {
            return Err(Error::Invalid(format!(
                "the design refers to a {}-level lattice, the pool has {} levels",
                self.levels, pool.lattice.levels
            )));
        }
        check_unique(&self.poses)?;
        pool.positions_of(&self.poses)
    }
}

/// Errors on a repeated pose index.
pub fn check_unique(poses: &[usize]) -> Result<()> {
    let mut sorted = poses.to_vec();
    sorted.sort_unstable();
    if let Some(w) = sorted.windows(2).find(|w| w[0] == w[1]) {
        return Err(Error::Invalid(format!(
            "pose {} appears more than once",
            w[0]
        )));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn minimal_file_is_accepted_and_checked() {
        let d: DesignFile =
            serde_json::from_str(r#"{"robot":"puma560","levels":5,"poses":[1982, 0]}"#).unwrap();
        let r = Robot::puma560();
        let pool = Pool::full(&r, 5).unwrap();
        assert_eq!(d.positions_in(&r, &pool).unwrap(), vec![1982, 0]);
        let bad: DesignFile =
            serde_json::from_str(r#"{"robot":"puma560","levels":5,"poses":[15625]}"#).unwrap();
        assert!(bad.positions_in(&r, &pool).is_err());
        let dup: DesignFile =
            serde_json::from_str(r#"{"robot":"puma560","levels":5,"poses":[3,3]}"#).unwrap();
        assert!(
            dup.positions_in(&r, &pool)
                .unwrap_err()
                .to_string()
                .contains("more than once")
        );
        let other: DesignFile =
            serde_json::from_str(r#"{"robot":"ur5","levels":5,"poses":[3]}"#).unwrap();
        assert!(other.positions_in(&r, &pool).is_err());
    }

    #[test]
    fn write_refuses_to_overwrite() {
        let dir = std::env::temp_dir().join(format!("activecal-design-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("d.json");
        let d = DesignFile::new("puma560", 5, vec![1, 2, 3]);
        d.write(&path, true).unwrap();
        assert!(d.write(&path, false).is_err());
        assert_eq!(DesignFile::read(&path).unwrap(), d);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

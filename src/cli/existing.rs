//! `--existing FILE`: poses measured before a selection, read (joint
//! configurations, measurements or a design) into their prior information.

use activecal::model::{ParamSet, Robot};
use anyhow::Result;

pub use activecal::experiment::select::Existing;

/// Reads the poses of `--existing FILE` ([`Existing::read`]).
pub fn load_existing(
    path: &std::path::Path,
    robot: &Robot,
    params: ParamSet,
    units: activecal::units::Units,
) -> Result<Existing> {
    use anyhow::Context;
    Existing::read(path, robot, params, units).context("--existing")
}

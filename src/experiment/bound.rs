//! The `bound` pipeline: the certified upper bound on ln OI_D of every
//! design of `n` poses from a pool (the D criterion's continuous
//! relaxation, eq. (C)), with the information of poses measured before as
//! a prior, as its report.

use super::ExperimentError;
use super::gap::ScoringPool;
use super::select::Existing;
use crate::bound::{BoundSettings, relaxation_bound};
use crate::report::BoundCommandReport;

/// The bound of designs of `n` poses from the pool `on` with `settings`,
/// on top of the `existing` poses' information when given; `weights`
/// keeps the relaxation's weight per pose of its support in the report.
///
/// # Errors
/// A relaxation that fails (too few poses for the unknowns, a solver
/// failure).
pub fn bound_of_pool(
    on: ScoringPool<'_>,
    existing: Option<Existing>,
    n: usize,
    settings: BoundSettings,
    weights: bool,
) -> Result<BoundCommandReport, ExperimentError> {
    let b = relaxation_bound(on.x, existing.as_ref().map(|e| &e.prior), n, &settings)?;
    let mut report = BoundCommandReport::new(on.robot, on.pool, &b, on.params, settings, weights);
    report.existing = existing.map(|e| e.report);
    Ok(report)
}

//! The certified bound of a pool (`activecal bound`) and a design's gap to
//! it (`activecal gap`) as functions.

use crate::convert::{detached, json_to_py};
use crate::robot::Robot;
use crate::select::{Design, candidates, existing_poses};
use activecal::model::ParamSet;
use activecal::options::BoundSettings;
use pyo3::prelude::*;

/// The certified upper bound on ln OI_D (= ln det XᵀX) of every design of
/// `n` poses from a pool (the D criterion's continuous relaxation, solved
/// to a certified duality gap): the dict
/// `activecal bound --json` prints (`ln_bound`, `status`, `gap`, the pool,
/// the settings; `support` with the relaxation's weight per pose when
/// `weights` is true). robot: a `Robot`. n: design size (at least the
/// poses that determine the unknowns). pool, count, levels, pool_seed,
/// margin: as `select` takes them (a `Pool`, an array of joint values in
/// radians, or a source name). existing: joint values of poses already
/// measured (their information is the prior, as `--existing`). progress:
/// as `select`. Seconds on a pool of thousands of poses.
#[pyfunction]
#[pyo3(signature = (robot, n, pool=None, count=None, levels=None, pool_seed=None, margin=None, existing=None, weights=false, progress=None))]
#[allow(clippy::too_many_arguments)]
pub fn bound<'py>(
    py: Python<'py>,
    robot: &Robot,
    n: i64,
    pool: Option<&Bound<'py, PyAny>>,
    count: Option<i64>,
    levels: Option<i64>,
    pool_seed: Option<i128>,
    margin: Option<f64>,
    existing: Option<&Bound<'py, PyAny>>,
    weights: bool,
    progress: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    let n = crate::convert::count("n", n, 1)?;
    let c = candidates(py, robot, pool, count, levels, pool_seed, margin)?;
    let existing = existing.map(|e| existing_poses(py, robot, e)).transpose()?;
    let r = robot.inner.clone();
    let v = crate::progress::with_callback(progress, || {
        detached(py, move || {
            let on = activecal::experiment::gap::ScoringPool {
                robot: &r,
                pool: &c.pool,
                x: &c.x,
                params: ParamSet::Nominal,
            };
            let report = activecal::experiment::bound::bound_of_pool(
                on,
                existing,
                n,
                BoundSettings::default(),
                weights,
            )?;
            Ok(serde_json::to_value(&report)?)
        })
    })?;
    json_to_py(py, &v)
}

/// A design's D-efficiency against the certified bound over its own pool:
/// the dict `activecal gap --json` prints (`ln_oid`, `ln_bound`,
/// `d_efficiency` — at least this — and the status). The same as
/// `design.bound()`.
#[pyfunction]
#[pyo3(signature = (design, progress=None))]
pub fn gap<'py>(
    py: Python<'py>,
    design: &Design,
    progress: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    design.gap_dict(py, progress)
}

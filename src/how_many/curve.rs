//! The curve itself: for each size, the best design, its certified
//! D-efficiency and its predicted errors.

use super::predict::{ErrorRows, random_configurations};
use super::recommend::{curve_sizes, recommend, sizes_step};
use super::{CurvePoint, CurveSettings, HowManyError, NoiseUnit, PoseCountCurve};
use crate::blocks::Blocks;
use crate::bound::{BoundError, design_gap, relaxation_bound};
use crate::criterion::Prior;
use crate::model::{ParamTable, Robot};
use crate::select::select;
use rayon::prelude::*;

/// The curve on the pool `x` (Jacobian blocks at `table`; `ids` its pose
/// ids): for every size of [`curve_sizes`], the best design of
/// `settings.select`, its certified D-efficiency and its predicted errors at
/// [`random_configurations`]. The curve starts at the fewest poses whose
/// information can have full rank, `⌈p / r⌉` with `r` the rank of one
/// pose's information ([`Blocks::sample_rank`]; its rows `t` for a point or
/// a pose, fewer for markers: a rigid body shows 6 however many points it
/// carries), 1 on top of poses already measured.
pub fn pose_count_curve(
    robot: &Robot,
    table: &ParamTable,
    x: &Blocks,
    ids: &[usize],
    settings: &CurveSettings,
) -> Result<PoseCountCurve, HowManyError> {
    check(settings)?;
    let qs = random_configurations(robot, settings.configurations, settings.seed);
    let rows = ErrorRows::of_robot(robot, table, &qs);
    let n_min = fewest_poses(x, settings);
    pose_count_curve_on(x, ids, settings, &rows, n_min, NoiseUnit::Metres)
}

/// The fewest poses of the curve: `⌈p / r⌉` (see [`pose_count_curve`]),
/// 1 with a prior.
#[must_use]
pub fn fewest_poses(x: &Blocks, settings: &CurveSettings) -> usize {
    if settings.select.prior.is_some() {
        1
    } else {
        x.p().div_ceil(x.sample_rank().max(1))
    }
}

/// Refuses a noise or target error that is not a finite number > 0.
fn check(settings: &CurveSettings) -> Result<(), HowManyError> {
    if !(settings.noise.is_finite() && settings.noise > 0.0) {
        return Err(crate::Error::Invalid(format!(
            "noise {}: the sensor noise σ must be a finite number > 0",
            settings.noise
        ))
        .into());
    }
    if let Some(t) = settings.target_mm
        && !(t.is_finite() && t > 0.0)
    {
        return Err(crate::Error::Invalid(format!(
            "target error {t}: the position error to reach must be a finite number > 0 (mm)"
        ))
        .into());
    }
    Ok(())
}

/// The curve on the pool `x` with the errors predicted from `rows` (see
/// [`ErrorRows`]), from `n_min` poses; `settings.noise` is in `unit`,
/// the unit of `x`'s rows.
pub fn pose_count_curve_on(
    x: &Blocks,
    ids: &[usize],
    settings: &CurveSettings,
    rows: &ErrorRows,
    n_min: usize,
    unit: NoiseUnit,
) -> Result<PoseCountCurve, HowManyError> {
    check(settings)?;
    let sizes = curve_sizes(n_min, &settings.also, settings.max_points, x.n_poses());
    // The sizes are independent: computed in parallel, gathered in order
    // (each size's design and bound do not depend on the thread count).
    let task = crate::progress::Task::start("how many poses", Some(sizes.len() as u64));
    let outcomes: Vec<Result<Size, HowManyError>> = sizes
        .par_iter()
        .map(|&n| {
            let _size_done = task.tick();
            crate::progress::checkpoint();
            curve_point(rows, x, ids, settings, n)
        })
        .collect();
    drop(task);
    let (mut points, mut skipped) = (Vec::new(), Vec::new());
    for (o, &n) in outcomes.into_iter().zip(&sizes) {
        match o? {
            Size::Point(c) => points.push(c),
            Size::Skipped(why) => skipped.push((n, why)),
        }
    }
    let step = sizes_step(&sizes, n_min);
    let recommended = recommend(&points, settings.target_mm);
    let (noise_m, noise_px) = match unit {
        NoiseUnit::Metres => (Some(settings.noise), None),
        NoiseUnit::Pixels => (None, Some(settings.noise)),
    };
    Ok(PoseCountCurve {
        p: x.p(),
        rows_per_pose: x.t(),
        n_min,
        noise_m,
        noise_px,
        configurations: rows.eval.n_poses(),
        seed: settings.seed,
        points,
        skipped,
        step,
        recommended,
    })
}

/// What one size of the curve gave.
enum Size {
    Point(CurvePoint),
    /// Why the size has no point.
    Skipped(String),
}

/// The curve's point at `n` poses: the best design of `settings.select`,
/// its certified D-efficiency and its predicted errors at the
/// configurations of `rows`; skipped (with the reason) when
/// no regular design or bound exists at that size.
fn curve_point(
    rows: &ErrorRows,
    x: &Blocks,
    ids: &[usize],
    settings: &CurveSettings,
    n: usize,
) -> Result<Size, HowManyError> {
    let prior: Option<&Prior> = settings.select.prior.as_ref();
    if n < settings.select.fixed.len() {
        return Ok(Size::Skipped("fewer poses than the fixed ones".into()));
    }
    let mut s = settings.select.clone();
    s.n = n;
    s.initial = s.initial.clamp(s.fixed.len().max(1), n);
    let sel = match select(x, settings.criterion, settings.algorithm, &s) {
        Ok(sel) if sel.ln_oid.is_finite() => sel,
        Ok(_) => return Ok(Size::Skipped("every design found is singular".into())),
        Err(e) => return Ok(Size::Skipped(e.to_string())),
    };
    let bound = match relaxation_bound(x, prior, n, &settings.bound) {
        Ok(b) => b,
        Err(e @ BoundError::TooFewRows { .. }) => return Ok(Size::Skipped(e.to_string())),
        Err(e) => return Err(e.into()),
    };
    let gap = design_gap(x, prior, &sel.poses, &bound)?;
    let mut info = x.information(&sel.poses);
    if let Some(pr) = prior {
        info += pr.matrix();
    }
    let Some(predicted) = rows.errors(info.as_ref(), settings.noise) else {
        return Ok(Size::Skipped(
            "the design's information matrix is singular".into(),
        ));
    };
    Ok(Size::Point(CurvePoint {
        n,
        ln_oid: sel.ln_oid,
        ln_bound: bound.ln_bound,
        d_efficiency: gap.d_efficiency,
        predicted,
        poses: sel.poses.iter().map(|&k| ids[k]).collect(),
    }))
}

//! The order to measure a design's poses in: the tour of
//! [`crate::select::tour`] (joint speeds from the robot's description, a
//! fallback where it states none), its moves checked against the pool's
//! collision filters, and a pose the tour cannot leave or reach exchanged
//! for a free one ([`visit_selection`]). `select --order` and the Python
//! package's `select(order=...)` both run it.

use crate::blocks::Blocks;
use crate::collision::CollisionModel;
use crate::criterion::Prior;
use crate::error::{Error, Result};
use crate::io::design::{DesignFile, ViaPoint};
use crate::io::joint_speeds::JointSpeeds;
use crate::model::Robot;
use crate::pool::Pool;
use crate::report::SelectReport;
use crate::select::swap::SwappedPose;
use crate::select::{Refinement, Selection};
use std::sync::Arc;

pub use crate::select::tour::FALLBACK_SPEED;

/// Replacements of a stuck pose tried, best first by the `ln OI_D` kept.
pub const SWAP_TRIES: usize = 32;

/// Poses exchanged at most because the tour cannot leave or reach them.
pub const MAX_SWAPS: usize = 3;

/// How to order a design.
#[derive(Clone, Debug, Default)]
pub struct Visiting {
    /// Order the poses for the shortest visiting time (else keep selection
    /// order and only check the moves).
    pub reorder: bool,
    /// The configuration the tour starts from.
    pub home: Option<Vec<f64>>,
    /// Whether a pose the tour cannot leave or reach may be exchanged (the
    /// D criterion on pool poses).
    pub may_swap: bool,
}

/// Whether `robot`'s description states joint speeds: `select` orders a
/// design by time by default then.
pub fn default_reorder(robot: &Robot) -> Result<bool> {
    Ok(crate::io::joint_speeds::joint_speeds(robot)?.is_some())
}

/// Orders the selection `sel` over `pool` (Jacobian `x`, information
/// already measured `prior`) for visiting: `report_of` makes the report of
/// a selection (called again after an exchange); returns the report with
/// its configurations, tour and moves in visiting order, the order
/// (positions in selection order) and the poses exchanged.
pub fn visit_selection<E: From<Error>>(
    robot: &Robot,
    pool: &Pool,
    x: &Blocks,
    prior: Option<&Prior>,
    sel: &mut Selection,
    how: &Visiting,
    mut report_of: impl FnMut(&Selection) -> std::result::Result<SelectReport, E>,
) -> std::result::Result<(SelectReport, Vec<usize>, Vec<SwappedPose>), E> {
    let speeds = crate::io::joint_speeds::joint_speeds(robot)?;
    // A joint that turns all the way round may reach a pose a whole turn
    // away, within its limits less the pool's margin.
    let turns = crate::pool::turn::whole_turn_limits(
        robot,
        &crate::units::joint_names(robot),
        pool.spec.margin,
    )?;
    let home = how.home.as_deref();
    let mut swapped = Vec::new();
    loop {
        let mut report = report_of(sel)?;
        let mut order = order_design(&mut report, speeds.as_ref(), home, how.reorder, &turns)?;
        check_moves(&mut report, &mut order, pool, home, &turns, !how.reorder)?;
        // A pose the tour cannot leave or reach freely is exchanged and the
        // tour planned again, a few times at most.
        if how.may_swap
            && swapped.len() < MAX_SWAPS
            && let Some(w) = swap_stuck(pool, x, prior, sel, &report, &order, home)?
        {
            swapped.push(w);
            continue;
        }
        return Ok((report, order, swapped));
    }
}

/// Orders the report's configurations (the design's joint values) for
/// visiting when `reorder` (else keeps selection order) and records the
/// figures; returns the order as positions in selection order.
pub fn order_design(
    report: &mut SelectReport,
    speeds: Option<&JointSpeeds>,
    home: Option<&[f64]>,
    reorder: bool,
    turns: &[Option<[f64; 2]>],
) -> Result<Vec<usize>> {
    let names = &report.joint_names;
    let (v, assumed) = match speeds {
        Some(s) => (
            s.or(FALLBACK_SPEED),
            s.speeds
                .iter()
                .zip(&s.joints)
                .filter(|(v, _)| v.is_none())
                .map(|(_, n)| n.clone())
                .collect(),
        ),
        None => (vec![FALLBACK_SPEED; names.len()], names.clone()),
    };
    let mut qs: Vec<Vec<f64>> = report.configurations.iter().map(|c| c.q.clone()).collect();
    let (order, tour) = crate::select::tour::visit(&v, assumed, home, &mut qs, reorder, turns)?;
    arrange(report, &order, |k| k, &qs);
    report.tour = Some(tour);
    Ok(order)
}

/// Puts the report's configurations in `order` (indices into `qs`; the
/// configuration of pose `k` stands at `at(k)` now), each with its joint
/// values from `qs`.
fn arrange(
    report: &mut SelectReport,
    order: &[usize],
    at: impl Fn(usize) -> usize,
    qs: &[Vec<f64>],
) {
    let old = std::mem::take(&mut report.configurations);
    report.configurations = order
        .iter()
        .map(|&k| {
            let mut c = old[at(k)].clone();
            c.q.clone_from(&qs[k]);
            c
        })
        .collect();
}

/// With collision filters on the pool, checks every move of the visiting
/// order (from `home` when given) at a step where no link point moves more
/// than the clearance (1 mm without one), reorders around colliding moves
/// (or turns poses' joints by whole turns) where it can, and records what
/// it found in the report; `order` (as [`order_design`] returned it) is
/// updated, and so are the report's configurations. With `keep_order` the
/// poses stay in selection order: only whole turns and via configurations
/// avoid a colliding move.
pub fn check_moves(
    report: &mut SelectReport,
    order: &mut Vec<usize>,
    pool: &Pool,
    home: Option<&[f64]>,
    turns: &[Option<[f64; 2]>],
    keep_order: bool,
) -> Result<()> {
    let (models, clearance) = collision_models(pool)?;
    if models.is_empty() {
        return Ok(());
    }
    // The poses in selection order, as `order` indexes them.
    let mut qs = vec![Vec::new(); order.len()];
    for (c, &k) in report.configurations.iter().zip(order.iter()) {
        qs[k].clone_from(&c.q);
    }
    let refs: Vec<&CollisionModel> = models.iter().map(|m| m.as_ref()).collect();
    // Via candidates: the pool's configurations, each free of the filters.
    let vias: Vec<Vec<f64>> = (0..pool.len()).map(|k| pool.q(k)).collect();
    let speeds = report.tour.as_ref().map_or_else(
        || vec![FALLBACK_SPEED; report.joint_names.len()],
        |t| t.speeds.clone(),
    );
    let cost = crate::select::tour::MoveCost::new(&speeds)?;
    let space = crate::select::moves::MoveSpace {
        cost: &cost,
        models: &refs,
        resolution: if clearance > 0.0 { clearance } else { 1e-3 },
        vias: &vias,
        turns,
        keep_order,
    };
    let before = order.clone();
    let moves = crate::select::moves::check_tour(&space, home, &mut qs, order);
    if *order != before || !moves.turned.is_empty() {
        let at: std::collections::HashMap<usize, usize> =
            before.iter().enumerate().map(|(i, &k)| (k, i)).collect();
        arrange(report, order, |k| at[&k], &qs);
        if let Some(t) = report.tour.as_mut() {
            t.visiting_order = crate::select::tour::totals(&cost, home, &qs, order);
            if t.selection_order.time_s > 0.0 {
                t.time_ratio = t.visiting_order.time_s / t.selection_order.time_s;
            }
        }
    }
    report.moves = Some(moves);
    Ok(())
}

/// The collision models of a pool's filters and their largest clearance.
fn collision_models(pool: &Pool) -> Result<(Vec<Arc<CollisionModel>>, f64)> {
    let mut models = Vec::new();
    let mut clearance: f64 = 0.0;
    for f in &pool.spec.filters {
        if let crate::pool::PoolFilter::Collision(c) = f {
            models.push(c.load().map_err(Error::Invalid)?);
            clearance = clearance.max(c.spec.clearance);
        }
    }
    Ok((models, clearance))
}

/// The first colliding move of the report's tour, if any, made avoidable by
/// exchanging the pose it cannot leave (a contact in the first half of the
/// move) or reach (in the second half) for the pool pose that keeps the
/// most `ln OI_D` ([`crate::select::swap::ranked_replacements`], at most
/// [`SWAP_TRIES`]) whose moves from the pose before it and to the pose after
/// it in the visiting order are free. `sel` is updated (its `ln_oid`,
/// `score` and `oi` recomputed); `None` when nothing collides or no
/// replacement is free.
pub fn swap_stuck(
    pool: &Pool,
    x: &Blocks,
    prior: Option<&Prior>,
    sel: &mut Selection,
    report: &SelectReport,
    order: &[usize],
    home: Option<&[f64]>,
) -> Result<Option<SwappedPose>> {
    let Some(c) = report.moves.as_ref().and_then(|m| m.colliding.first()) else {
        return Ok(None);
    };
    let pos = match c.from {
        Some(f) if c.at < 0.5 => f,
        _ => c.to,
    };
    let k = order[pos];
    let (models, clearance) = collision_models(pool)?;
    let resolution = if clearance > 0.0 { clearance } else { 1e-3 };
    let prev: Option<Vec<f64>> = if pos == 0 {
        home.map(<[f64]>::to_vec)
    } else {
        Some(report.configurations[pos - 1].q.clone())
    };
    let next = report.configurations.get(pos + 1).map(|p| p.q.clone());
    let free = |a: &[f64], b: &[f64]| {
        models
            .iter()
            .all(|m| m.check_move(a, b, resolution).contact.is_none())
    };
    let ranked = crate::select::swap::ranked_replacements(x, prior, &sel.poses, k, SWAP_TRIES);
    for (cand, ln_after) in ranked {
        let q = pool.q(cand);
        if prev.as_ref().is_some_and(|p| !free(p, &q))
            || next.as_ref().is_some_and(|n| !free(&q, n))
        {
            continue;
        }
        let old = sel.poses[k];
        let before = sel.ln_oid;
        sel.poses[k] = cand;
        sel.ln_oid = ln_after;
        sel.score = ln_after;
        sel.oi = crate::criterion::Indices::from_design(x, &sel.poses).oi;
        return Ok(Some(SwappedPose {
            pose: pos,
            removed_id: pool.ids[old],
            added_id: pool.ids[cand],
            ln_oid_before: before,
            ln_oid_after: ln_after,
            pair: c.pair.clone(),
        }));
    }
    Ok(None)
}

/// The design file of the selection `sel` of `pool` (its refinement's
/// joint values when refined) in visiting `order` (as
/// [`visit_selection`] returned it): the joint values as visited (a pose may
/// be reached a whole turn away), the via configurations of the moves and
/// the report's design keys.
#[must_use]
pub fn ordered_design(
    robot: &Robot,
    pool: &Pool,
    sel: &Selection,
    refined: Option<&Refinement>,
    order: &[usize],
    report: &SelectReport,
) -> DesignFile {
    let mut d = DesignFile::from_pool(robot, pool, &sel.poses);
    if let Some(r) = refined {
        d.q = Some(r.poses.iter().map(|p| p.q.clone()).collect());
        d.refined = true;
    }
    d.poses = order.iter().map(|&k| d.poses[k]).collect();
    if let Some(q) = d.q.as_mut() {
        for (q, c) in q.iter_mut().zip(&report.configurations) {
            q.clone_from(&c.q);
        }
    }
    d.via = report
        .moves
        .as_ref()
        .map(|m| {
            m.via
                .iter()
                .map(|v| ViaPoint {
                    from: v.from,
                    to: v.to,
                    q: v.q.clone(),
                })
                .collect()
        })
        .unwrap_or_default();
    d.extra.extend(report.design_keys());
    d
}

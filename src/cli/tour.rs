//! `select`'s visiting order and design outputs: the poses in the order to
//! measure them, written in the robot's terms (.json, .csv, .yaml).

use activecal::io::design::DesignFile;
use activecal::io::design_formats;
use activecal::io::joint_speeds::JointSpeeds;
use activecal::model::Robot;
use activecal::report::SelectReport;
use anyhow::{Result, bail};

/// Speed assumed for a joint whose limit the robot does not state, rad/s
/// (or m/s).
pub const FALLBACK_SPEED: f64 = 1.0;

/// Parses `--home`: one finite value per joint of `robot`.
pub fn parse_home(text: Option<&str>, robot: &Robot) -> Result<Option<Vec<f64>>> {
    let Some(t) = text else { return Ok(None) };
    let q: Vec<f64> = super::parse_list(t, "--home")?;
    if q.len() != robot.dof() {
        bail!(
            "--home {t}: {} joint values, the robot has {} joints ({})",
            q.len(),
            robot.dof(),
            activecal::pool::file::joint_names(robot).join(", ")
        );
    }
    if let Some(j) = q.iter().position(|v| !v.is_finite()) {
        bail!("--home {t}: joint {} value {} is not finite", j + 1, q[j]);
    }
    Ok(Some(q))
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
    let (order, tour) = activecal::select::tour::visit(&v, assumed, home, &mut qs, reorder, turns)?;
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
/// updated, and so are the report's configurations. With `keep_order`
/// (`--order none`) the poses stay in selection order: only whole turns
/// and via configurations avoid a colliding move.
pub fn check_moves(
    report: &mut SelectReport,
    order: &mut Vec<usize>,
    pool: &activecal::pool::Pool,
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
    let refs: Vec<&activecal::collision::CollisionModel> =
        models.iter().map(|m| m.as_ref()).collect();
    // Via candidates: the pool's configurations, each free of the filters.
    let vias: Vec<Vec<f64>> = (0..pool.len()).map(|k| pool.q(k)).collect();
    let speeds = report.tour.as_ref().map_or_else(
        || vec![FALLBACK_SPEED; report.joint_names.len()],
        |t| t.speeds.clone(),
    );
    let cost = activecal::select::tour::MoveCost::new(&speeds)?;
    let space = activecal::select::moves::MoveSpace {
        cost: &cost,
        models: &refs,
        resolution: if clearance > 0.0 { clearance } else { 1e-3 },
        vias: &vias,
        turns,
        keep_order,
    };
    let before = order.clone();
    let moves = activecal::select::moves::check_tour(&space, home, &mut qs, order);
    if *order != before || !moves.turned.is_empty() {
        let at: std::collections::HashMap<usize, usize> =
            before.iter().enumerate().map(|(i, &k)| (k, i)).collect();
        arrange(report, order, |k| at[&k], &qs);
        if let Some(t) = report.tour.as_mut() {
            t.visiting_order = activecal::select::tour::totals(&cost, home, &qs, order);
            if t.selection_order.time_s > 0.0 {
                t.time_ratio = t.visiting_order.time_s / t.selection_order.time_s;
            }
        }
    }
    report.moves = Some(moves);
    Ok(())
}

/// The collision models of a pool's filters and their largest clearance.
fn collision_models(
    pool: &activecal::pool::Pool,
) -> Result<(
    Vec<std::sync::Arc<activecal::collision::CollisionModel>>,
    f64,
)> {
    let mut models = Vec::new();
    let mut clearance: f64 = 0.0;
    for f in &pool.spec.filters {
        if let activecal::pool::PoolFilter::Collision(c) = f {
            models.push(c.load().map_err(|e| anyhow::anyhow!(e))?);
            clearance = clearance.max(c.spec.clearance);
        }
    }
    Ok((models, clearance))
}

/// Replacements of a stuck pose tried, best first by the `ln OI_D` kept.
pub const SWAP_TRIES: usize = 32;

/// The first colliding move of the report's tour, if any, made avoidable by
/// exchanging the pose it cannot leave (a contact in the first half of the
/// move) or reach (in the second half) for the pool pose that keeps the
/// most `ln OI_D` ([`activecal::select::swap::ranked_replacements`], at most
/// [`SWAP_TRIES`]) whose moves from the pose before it and to the pose after
/// it in the visiting order are free. `sel` is updated (its `ln_oid`,
/// `score` and `oi` recomputed); `None` when nothing collides or no
/// replacement is free.
pub fn swap_stuck(
    ctx: &super::PoolCtx,
    prior: Option<&activecal::criterion::Prior>,
    sel: &mut activecal::select::Selection,
    report: &SelectReport,
    order: &[usize],
    home: Option<&[f64]>,
) -> Result<Option<activecal::select::swap::SwappedPose>> {
    let Some(c) = report.moves.as_ref().and_then(|m| m.colliding.first()) else {
        return Ok(None);
    };
    let pos = match c.from {
        Some(f) if c.at < 0.5 => f,
        _ => c.to,
    };
    let k = order[pos];
    let (models, clearance) = collision_models(&ctx.pool)?;
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
    let ranked =
        activecal::select::swap::ranked_replacements(&ctx.x, prior, &sel.poses, k, SWAP_TRIES);
    for (cand, ln_after) in ranked {
        let q = ctx.pool.q(cand);
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
        sel.oi = activecal::criterion::Indices::from_design(&ctx.x, &sel.poses).oi;
        return Ok(Some(activecal::select::swap::SwappedPose {
            pose: pos,
            removed_id: ctx.pool.ids[old],
            added_id: ctx.pool.ids[cand],
            ln_oid_before: before,
            ln_oid_after: ln_after,
            pair: c.pair.clone(),
        }));
    }
    Ok(None)
}

/// Text lines of the moves' collision check (`names`: the joints).
fn moves_text(m: &activecal::select::moves::MovesReport, names: &[String]) -> String {
    let mut s = format!(
        "moves checked for collision: {} moves, {} configurations, at most {} mm of link motion between checks",
        m.moves_checked,
        m.configurations_checked,
        m.resolution_m * 1e3
    );
    let fixes: Vec<&str> = [
        m.reordered.then_some("reordering"),
        (!m.turned.is_empty()).then_some("turning joints by whole turns"),
        (!m.via.is_empty()).then_some("via configurations"),
    ]
    .into_iter()
    .flatten()
    .collect();
    if m.colliding.is_empty() {
        s += &if m.colliding_before == 0 {
            "; every move is free\n".to_string()
        } else {
            format!(
                "; the {} colliding move(s) of the planned order avoided by {}: every move is free\n",
                m.colliding_before,
                fixes.join(", ")
            )
        };
    } else {
        s += &format!(
            "; {} move(s) COLLIDE and no reorder, whole turn or via configuration avoids them{}:\n",
            m.colliding.len(),
            if fixes.is_empty() {
                String::new()
            } else {
                format!(" (others avoided by {})", fixes.join(", "))
            }
        );
    }
    let named =
        |from: Option<usize>| from.map_or("home".to_string(), |f| format!("pose {}", f + 1));
    for t in &m.turned {
        let joints: Vec<String> = t
            .turns
            .iter()
            .zip(names)
            .filter(|(t, _)| **t != 0)
            .map(|(t, n)| format!("{n} {:+} turn ({:+} deg)", t, f64::from(*t) * 360.0))
            .collect();
        s += &format!(
            "  pose {}: {} (the same pose, reached the other way round)\n",
            t.pose + 1,
            joints.join(", ")
        );
    }
    for v in &m.via {
        let q: Vec<String> = v.q.iter().map(|x| format!("{x:.4}")).collect();
        s += &format!(
            "  {} -> pose {} goes through the via configuration [{}] (rad or m; not measured)\n",
            named(v.from),
            v.to + 1,
            q.join(", ")
        );
    }
    for c in &m.colliding {
        s += &format!(
            "  {} -> pose {}: {} touches {} at {:.0} % of the move\n",
            named(c.from),
            c.to + 1,
            c.pair.link,
            c.pair.other,
            c.at * 100.0
        );
    }
    s
}

/// Puts a design file's poses in `order` (positions in selection order).
pub fn reorder_design(d: &mut DesignFile, order: &[usize]) {
    d.poses = order.iter().map(|&k| d.poses[k]).collect();
    if let Some(q) = &d.q {
        d.q = Some(order.iter().map(|&k| q[k].clone()).collect());
    }
}

/// Writes the design in the format its extension names (checked before the
/// search too).
pub fn write_design(d: &DesignFile, out: &std::path::Path, force: bool) -> Result<()> {
    // The command's own message for an existing file ("pass --force").
    super::refuse_overwrite(out, force)?;
    design_formats::write(d, out, true)?;
    Ok(())
}

/// Text lines: the ordering's figures and the poses with their named joint
/// values, in visiting order.
pub fn configurations_text(r: &SelectReport) -> String {
    let mut s = String::new();
    if let Some(t) = &r.tour {
        let (b, a) = (&t.selection_order, &t.visiting_order);
        if t.reordered {
            s += &format!(
                "visiting order: move time {:.2} s -> {:.2} s ({:.3} of selection order's), largest-joint travel {:.2} -> {:.2} rad\n",
                b.time_s, a.time_s, t.time_ratio, b.travel, a.travel
            );
            if t.turned_poses > 0 {
                s += &format!(
                    "  {} pose(s) reached a whole turn (360 deg) away on joints that turn all the way round: the same poses, shorter moves\n",
                    t.turned_poses
                );
            }
        } else {
            s += &format!(
                "selection order kept: move time {:.2} s, largest-joint travel {:.2} rad\n",
                b.time_s, b.travel
            );
        }
        if !t.assumed_speeds.is_empty() {
            s += &format!(
                "  (speed limit {FALLBACK_SPEED} rad/s assumed for {})\n",
                t.assumed_speeds.join(", ")
            );
        }
    }
    if let Some(m) = &r.moves {
        s += &moves_text(m, &r.joint_names);
    }
    for w in &r.swapped {
        s += &format!(
            "pose id {} exchanged for pool pose {} (visited {}th): no move could leave or reach it ({} touches {}); ln OI_D {:.4} -> {:.4}\n",
            w.removed_id,
            w.added_id,
            w.pose + 1,
            w.pair.link,
            w.pair.other,
            w.ln_oid_before,
            w.ln_oid_after
        );
    }
    s += &format!("{:>4} {:>8}", "#", "id");
    for n in &r.joint_names {
        s += &format!(" {n:>12}");
    }
    s += "   (rad; m for prismatic joints)\n";
    for (k, c) in r.configurations.iter().enumerate() {
        s += &format!("{:>4} {:>8}", k + 1, c.id);
        for v in &c.q {
            s += &format!(" {v:>12.6}");
        }
        s += "\n";
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use activecal::collision::ContactPair;
    use activecal::select::moves::{CollidingMove, MovesReport, TurnedPose};

    #[test]
    fn the_moves_text_names_turned_joints_and_colliding_pairs() {
        let names = vec!["pan".to_string(), "lift".to_string()];
        let mut m = MovesReport {
            resolution_m: 1e-3,
            moves_checked: 5,
            configurations_checked: 40,
            colliding_before: 2,
            reordered: false,
            turned: vec![TurnedPose {
                pose: 2,
                turns: vec![0, -1],
            }],
            via: Vec::new(),
            colliding: Vec::new(),
        };
        let s = moves_text(&m, &names);
        assert!(
            s.contains("avoided by turning joints by whole turns: every move is free"),
            "{s}"
        );
        assert!(s.contains("pose 3: lift -1 turn (-360 deg)"), "{s}");
        assert!(!s.contains("pan "), "an unturned joint is not listed: {s}");
        m.colliding.push(CollidingMove {
            from: None,
            to: 0,
            pair: ContactPair {
                link: "arm".into(),
                other: "floor".into(),
                obstacle: true,
            },
            at: 0.25,
        });
        let s = moves_text(&m, &names);
        assert!(s.contains("1 move(s) COLLIDE"), "{s}");
        assert!(
            s.contains("(others avoided by turning joints by whole turns)"),
            "{s}"
        );
        assert!(
            s.contains("home -> pose 1: arm touches floor at 25 % of the move"),
            "{s}"
        );
    }
}

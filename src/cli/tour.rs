//! `select`'s visiting order and design outputs: the poses in the order to
//! measure them, written in the robot's terms (.json, .csv, .yaml).

use activecal::io::design::DesignFile;
use activecal::io::design_formats;
use activecal::model::Robot;
use activecal::report::SelectReport;
use anyhow::{Result, bail};

use activecal::experiment::visiting::FALLBACK_SPEED;

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

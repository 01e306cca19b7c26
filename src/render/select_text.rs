//! The text of `select`: the search and its figures, the poses already
//! measured, the refinement, the visiting order and its moves' collision
//! check, the poses in visiting order and the predicted errors (units on
//! every figure).

use crate::report::SelectReport;
use crate::select::Settings;
use crate::select::tour::FALLBACK_SPEED;

/// The text of a selection: the poses already measured, the search
/// with its settings `a` and time (`seconds`), the figures, the
/// refinement, the visiting order, the poses, the predicted errors.
#[must_use]
pub fn text(report: &SelectReport, a: &Settings, seconds: f64) -> String {
    let mut s = String::new();
    if let Some(e) = &report.existing {
        s += &existing_text(e);
    }
    s += &format!(
        "{:?} ({:?} criterion, seed {}, {} start(s){}{}): {} poses in {:.3} s\nlog10 OI_D {:.4}{}  OI {:.6}\nposes: {}\n",
        report.algorithm,
        report.criterion,
        a.seed,
        a.starts,
        if report.ils > 0 {
            format!(", {} ILS rounds of {} kicks", report.ils, report.kick)
        } else {
            String::new()
        },
        if a.polish { ", Fedorov polish" } else { "" },
        report.poses.len(),
        seconds,
        report.log10_oid,
        if report.existing.is_some() {
            " (existing + new poses)"
        } else {
            ""
        },
        report.oi,
        report
            .poses
            .iter()
            .map(|p| p.to_string())
            .collect::<Vec<_>>()
            .join(",")
    );
    if let Some(Some(g)) = report.ln_gain {
        s += &format!(
            "the new poses add {:.4} to log10 det M0\n",
            g / std::f64::consts::LN_10
        );
    }
    if let (Some(b), Some(eff)) = (report.log10_bound, report.d_efficiency) {
        s += &format!(
            "log10 bound {b:.4}{}  D-efficiency >= {eff:.6}\n",
            if report.existing.is_some() {
                " (with the existing poses' information)"
            } else {
                ""
            }
        );
    }
    if let Some(r) = &report.refinement {
        s += &format!(
            "refined off the pool: log10 OI_D {:.4} -> {:.4} (+{:.4}), {} pass(es)\n",
            r.ln_oid_before / std::f64::consts::LN_10,
            r.log10_oid,
            r.ln_gain / std::f64::consts::LN_10,
            r.sweeps
        );
        s += "pose    log10 gain  largest joint move\n";
        for p in &r.poses {
            s += &format!(
                "{:>6}  {:>10.4}  {:.4}\n",
                p.pose,
                p.ln_gain / std::f64::consts::LN_10,
                p.max_move
            );
        }
        if let (Some(true), Some(b)) = (r.exceeds_pool_bound, report.log10_bound) {
            s += &format!(
                "the refined design EXCEEDS the pool's certified bound (log10 {:.4} > {b:.4}): no design of the pool can reach it\n",
                r.log10_oid
            );
        } else if let (Some(false), Some(b)) = (r.exceeds_pool_bound, report.log10_bound) {
            s += &format!(
                "the refined design stays below the pool's certified bound (log10 {:.4} <= {b:.4})\n",
                r.log10_oid
            );
        }
    }
    s += &configurations_text(report);
    s + &predicted_text(report.predicted.as_ref())
}

/// Text lines about the existing poses of a report.
#[must_use]
pub fn existing_text(e: &crate::report::ExistingReport) -> String {
    let mut s = format!(
        "existing: {} poses from {} (rank {}), log10 det M0 {}\n",
        e.poses,
        e.file,
        e.rank,
        e.log10_det
            .map_or("singular (-inf)".to_string(), |v| format!("{v:.4}"))
    );
    for n in &e.notes {
        s += &format!("note: {n}\n");
    }
    s
}

/// The predicted errors' line of the text output (empty without them).
fn predicted_text(p: Option<&crate::report::PredictedAfter>) -> String {
    let Some(p) = p else {
        return String::new();
    };
    let mut s = format!(
        "predicted after calibrating with these poses (σ {} mm per coordinate): position RMS {:.4} mm at {} random configurations (95th percentile of the error {:.4} mm)",
        p.noise_m * 1e3,
        p.errors.position_rms_mm,
        p.configurations,
        p.errors.position_error_p95_mm
    );
    if let Some(o) = p.errors.orientation_rms_deg {
        s += &format!(", orientation RMS {o:.5}°");
    }
    s + "\n"
}

/// Text lines: the ordering's figures and the poses with their named joint
/// values, in visiting order.
#[must_use]
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

/// Text lines of the moves' collision check (`names`: the joints).
fn moves_text(m: &crate::select::moves::MovesReport, names: &[String]) -> String {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::collision::ContactPair;
    use crate::select::moves::{CollidingMove, MovesReport, TurnedPose};

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

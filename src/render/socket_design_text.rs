//! A design of configurations touching sockets as text (`select
//! --point`): the sockets and what reaches them, the predicted true and
//! consistency errors against random draws and the certified bound (in
//! units of σ), and the configurations.

use crate::select::contact::socket_design::{Judged, SocketDesign};
use std::fmt::Write as _;

/// One criterion's figures: the chosen configurations', the D-optimal
/// choice's, random draws' and the pool's bound, in units of σ.
fn judged_lines(s: &mut String, what: &str, j: &Judged) {
    let r = &j.random;
    let _ = writeln!(
        s,
        "{what}, σ = contact noise per coordinate: chosen {:.4} σ (D-optimal {:.4} σ), median of {} random draws {:.4} σ (quartiles {:.4}–{:.4} σ): {:.3}× lower; no design of this pool can be below {:.4} σ (convex relaxation, certified; {} configurations carry weight)",
        j.predicted_sigma,
        j.d_optimal_sigma,
        r.draws,
        r.median_sigma,
        r.q1_sigma,
        r.q3_sigma,
        j.ratio_to_random,
        j.bound.certified_sigma,
        j.bound.support
    );
}

/// A socket design as text: the sockets and what reaches them, the
/// figures, then the configurations with their named joint values.
/// `srdf_hint` ends the pool filters' note on an SRDF not given and
/// `distance_hint` the note on no known distance (the front end's words for
/// where to give them).
#[must_use]
pub fn socket_design_text(d: &SocketDesign, srdf_hint: &str, distance_hint: &str) -> String {
    let mut s = String::new();
    for p in &d.points {
        let x = p.socket.position;
        let _ = writeln!(
            s,
            "point {} at ({:.4}, {:.4}, {:.4}) m: {} of {} samples reach it{}",
            p.socket.name,
            x[0],
            x[1],
            x[2],
            p.configurations,
            d.samples_per_point,
            if d.pool_stats.is_some() {
                " and pass the pool filters"
            } else {
                ""
            }
        );
    }
    if let Some(st) = &d.pool_stats {
        s += &super::pool_text::pool_stats_text(st, srdf_hint);
    }
    let _ = writeln!(
        s,
        "{} configurations chosen from {}; {} unknowns ({} of the robot, tool offset, points)",
        d.configurations.len(),
        d.pool,
        d.unknowns,
        d.robot_unknowns
    );
    if d.known_distances == 0 {
        let _ = writeln!(
            s,
            "no known distance between the points{distance_hint}: contacts alone leave the scale free, and calibrate will need one"
        );
    } else {
        let _ = writeln!(
            s,
            "{} known distance(s) between the points, counted as calibrate will count them",
            d.known_distances
        );
    }
    judged_lines(
        &mut s,
        "predicted true error of the tool point (3-D RMS at 1000 random configurations; the criterion)",
        &d.true_error,
    );
    judged_lines(
        &mut s,
        "predicted consistency error (RMS about each point, per coordinate; what held-out contacts see)",
        &d.consistency,
    );
    let _ = write!(s, "{:>4} {:>6} {:<16}", "#", "id", "point");
    for n in &d.joint_names {
        let _ = write!(s, " {n:>12}");
    }
    s += "  reach (mm)   (rad; m for prismatic joints)\n";
    for (k, c) in d.configurations.iter().enumerate() {
        let _ = write!(s, "{:>4} {:>6} {:<16}", k + 1, c.id, c.point);
        for v in &c.q {
            let _ = write!(s, " {v:>12.6}");
        }
        let _ = writeln!(s, "  {:.2e}", 1e3 * c.reach_m);
    }
    s
}

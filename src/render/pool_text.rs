//! A pool's statistics as text: candidates, what each filter removed (the
//! link pairs a collision filter found touching, those touching in nearly
//! every configuration and not checked), its warnings and notes.

use crate::pool::PoolStats;

/// The pool's statistics as text; `srdf_hint` follows a warning about the
/// robot's own links touching (how the front end gives an SRDF or skips
/// the pairs always touching).
#[must_use]
pub fn pool_stats_text(st: &PoolStats, srdf_hint: &str) -> String {
    let mut s = format!("pool: {} candidates", st.candidates);
    for f in &st.filters {
        s += &format!(", {} filter removed {} of {}", f.filter, f.removed, f.seen);
    }
    s += &format!(", {} kept\n", st.kept);
    for f in &st.filters {
        if let Some(c) = &f.contacts {
            s += &format!(
                "  {} filter: {} removed by two links touching, {} by a link touching an obstacle; {} pairs, the largest:\n",
                f.filter, c.self_collision, c.obstacle, c.distinct_pairs
            );
            for p in &c.top {
                s += &format!(
                    "    {:>7}  {} – {}{}\n",
                    p.removed,
                    p.link,
                    p.other,
                    if p.obstacle { " (obstacle)" } else { "" }
                );
            }
            if !c.always_touching.is_empty() {
                s += &format!(
                    "  {} filter: {} pairs of links touch in nearly every configuration and are not checked:\n",
                    f.filter,
                    c.always_touching.len()
                );
                for p in &c.always_touching {
                    s += &format!(
                        "    {:>5.1} %  {} – {}\n",
                        100.0 * p.fraction,
                        p.link,
                        p.other
                    );
                }
            }
        }
        if let Some(w) = &f.warning {
            s += &format!("warning: {w}");
            let own = f
                .contacts
                .as_ref()
                .and_then(|c| c.top.first())
                .is_some_and(|p| !p.obstacle);
            if own {
                s += srdf_hint;
            }
            s += "\n";
        }
    }
    for n in &st.notes {
        s += &format!("note: {n}\n");
    }
    s
}

/// A pool's summary, as `pool` prints it: what each filter removed, the
/// lattice (`lattice`, when the pool is one: its levels, size and distinct
/// poses), the joint-limit margin (degrees), each joint's levels, the
/// poses kept and distinct, and the file written (`out`); `srdf_hint` ends
/// the filters' note on a robot without an SRDF.
#[must_use]
pub fn pool_summary_text(
    r: &crate::pool::summary::PoolSummary,
    lattice: Option<&crate::pool::Lattice>,
    srdf_hint: &str,
    out: Option<&std::path::Path>,
) -> String {
    let mut s = pool_stats_text(&r.pool_stats, srdf_hint);
    if let Some(l) = lattice {
        s += &format!(
            "lattice: {} levels per joint, {} poses, {} distinct\n",
            l.levels,
            l.size(),
            l.distinct_poses()
        );
    }
    if r.pool.margin > 0.0 {
        s += &format!(
            "margin: {:.4}° inside every revolute joint's limits\n",
            r.pool.margin.to_degrees()
        );
    }
    for j in r.lattice.iter().flatten() {
        s += &format!(
            "  {}: {} levels{}, {} distinct\n",
            j.name,
            j.levels.len(),
            if j.full_turn {
                " on the circle (the joint turns all the way round)"
            } else {
                ""
            },
            j.distinct
        );
    }
    s += &format!("{} poses kept, {} distinct\n", r.size, r.distinct);
    if let Some(out) = out {
        s += &format!("wrote {}\n", out.display());
    }
    s
}

/// One pose of a lattice (`pool --digits`): the lattice's levels and size,
/// the pose's index and joint values (radians).
#[must_use]
pub fn lattice_text(r: &crate::report::LatticeReport) -> String {
    let mut s = format!("lattice: {} levels per joint, {} poses\n", r.levels, r.size);
    if let (Some(i), Some(q)) = (r.index, &r.q) {
        s += &format!("index: {i}\nq (rad): {q:?}\n");
    }
    s
}

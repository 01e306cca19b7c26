//! The text of the project's benchmark ([`crate::report::bench`]): the
//! timing table, peak memory and the robots side by side.

use crate::report::bench::BenchReport;
use std::fmt::Write as _;

/// The benchmark's report as text (milliseconds, seconds, MiB).
#[must_use]
pub fn text(r: &BenchReport) -> String {
    let mut s = format!(
        "activecal bench ({} threads, median of {})\n",
        r.threads, r.reps
    );
    let _ = writeln!(s, "{:<48} {:>12}  ", "", "median ms");
    for row in &r.table {
        let ms = if row.median_ms.is_nan() {
            String::new()
        } else {
            format!("{:.3}", row.median_ms)
        };
        let _ = writeln!(s, "{:<48} {ms:>12}  {}", row.what, row.note);
    }
    let _ = writeln!(s, "peak memory: {:.0} MiB", r.peak_mib);
    let Some(robots) = r.robots.as_ref().filter(|v| !v.is_empty()) else {
        return s;
    };
    s += "\nrobots side by side (5-level lattices, N = 30; one run each):\n";
    let _ = writeln!(
        s,
        "{:<28} {:>3} {:>2} {:>7} {:>8} {:>8} {:>9} {:>10} {:>9} {:>8}",
        "robot",
        "p",
        "t",
        "poses",
        "bound s",
        "EAE s",
        "EAE eff",
        "select s",
        "sel eff",
        "peak MiB"
    );
    for b in robots {
        let _ = writeln!(
            s,
            "{:<28} {:>3} {:>2} {:>7} {:>8.2} {:>8.3} {:>9.4} {:>10.3} {:>9.4} {:>8.0}",
            b.robot,
            b.p,
            b.t,
            b.poses,
            b.bound_s,
            b.eae_s,
            b.eae_d_efficiency,
            b.select_s,
            b.select_d_efficiency,
            b.peak_mib.unwrap_or(f64::NAN),
        );
    }
    s += "(select: 2 starts with the default iterated local search; eff: D-efficiency against the certified bound)\n";
    s
}

//! A design scored on its own (`score`) and against the bound of its pool
//! (`gap`), as text: the information indices, the certified D-efficiency,
//! the poses the relaxation weighs.

use super::select_text::existing_text;
use crate::report::{GapReport, ScoreReport};

/// A design's size, rank and information indices (ln and log10 OI_D, the
/// eigenvalue indices O1–O5 and OI, eq. (1), and tr(M⁻¹)), as `score`
/// prints them.
#[must_use]
pub fn score_text(report: &ScoreReport) -> String {
    let ind = &report.indices;
    format!(
        "{} poses, rank {} of {}\nln OI_D {:.6}  log10 OI_D {:.6}\nOI {:.6}  O1 {:.6e}  O2 {:.6e}  O3 {:.6e}  O4 {:.6e}  O5 {:.6e}  tr(M^-1) {:.6e}\n",
        report.poses.len(),
        ind.rank,
        report.p,
        ind.ln_oid,
        ind.log10_oid,
        ind.oi,
        ind.o1,
        ind.o2,
        ind.o3,
        ind.o4,
        ind.o5,
        ind.a_trace
    )
}

/// The design named `design` against the certified bound of its pool: the
/// poses measured before it, whether a refined design exceeds the pool's
/// bound, log10 OI_D and the bound, the certified D-efficiency and the
/// poses with relaxation weight above `support_weight`, as `gap` prints
/// them.
#[must_use]
pub fn gap_text(design: &str, report: &GapReport, support_weight: f64) -> String {
    let oid = report
        .log10_oid
        .map_or("singular (-inf)".to_string(), |l| format!("{l:.6}"));
    let mut head = report
        .existing
        .as_ref()
        .map_or(String::new(), existing_text);
    if let Some(ex) = report.exceeds_bound {
        head += &format!(
            "refined design (poses off the pool): the pool's bound does not bound it; it {} that bound\n",
            if ex { "EXCEEDS" } else { "stays below" }
        );
    }
    head + &format!(
        "design {design} ({} poses, p = {})\nlog10 OI_D     {oid}\nlog10 bound    {:.6}  ({:?}, gap {:.1e})\nD-efficiency  >= {:.6}\n\
         poses with relaxation weight > {support_weight}: {} of {}: {:?}\n",
        report.n,
        report.p,
        report.log10_bound,
        report.bound.status,
        report.bound.certificate_gap,
        report.d_efficiency,
        report.weighted_poses.len(),
        report.n,
        report.weighted_poses
    )
}

//! The paper's figures 2 to 6 ([`crate::render::paper_figures`]) drawn
//! from a reproduction's report.

use super::PaperReport;
use crate::render::paper_figures as figures;
use std::path::Path;

/// Draws figures 2 to 6 of the paper from its report `r` in `out`
/// (each as PNG and SVG; `levels` the lattice's levels per joint).
pub fn draw_figures(out: &Path, r: &PaperReport, levels: usize) -> crate::error::Result<()> {
    let f = &r.figures;
    figures::random_designs(&out.join("fig2_random_designs"), &f.random_oi, f.eae_oi)?;
    figures::trace(
        &out.join("fig4_log10_oid"),
        "log10 OI_D per EAE iteration (Fig. 4)",
        "log10 OI_D",
        &[("EAE, det criterion", r.eae.trace_log10_oid.clone())],
    )?;
    let mut oi_series = vec![("EAE, det criterion", f.eae_trace_oi.clone())];
    if let Some(o) = &f.eae_oi_trace_oi {
        oi_series.push(("EAE, eigenvalue-OI criterion", o.clone()));
    }
    figures::trace(
        &out.join("fig5_oi"),
        "OI per EAE iteration (Fig. 5)",
        "OI, eq. (1)",
        &oi_series,
    )?;
    // 1/OI_D spans 20 decades: plotted as its log10 on a linear axis (a log
    // scale with every decade labelled).
    let inv: Vec<f64> = r.eae.trace_log10_oid.iter().map(|v| -v).collect();
    figures::trace(
        &out.join("fig6_inverse_oid"),
        "1/OI_D per EAE iteration, log scale (Fig. 6)",
        "log10 (1/OI_D)",
        &[("EAE", inv)],
    )?;
    figures::poses(
        &out.join("fig3_initial_poses"),
        "the initial EAE poses (Fig. 3)",
        &f.initial_digits,
        levels,
    )?;
    figures::poses(
        &out.join("fig4a_selected_poses"),
        "poses selected by EAE (Fig. 4 A)",
        &f.selected_digits,
        levels,
    )?;
    Ok(())
}

//! The text of a contact calibration (what `calibrate --measurements
//! contacts.csv` prints, and its report folder holds): the fit, the
//! in-sample consistency and the held-out placements, and a model's
//! evaluation on contacts (`evaluate`), lengths in mm.

use crate::data::ContactFile;
use crate::identify::contact::evaluate::ContactEvaluation;
use crate::identify::contact::holdout::{Figures, downweighted_rows};
use crate::identify::contact::{ContactFit, PlacementHoldout};
use std::fmt::Write as _;

/// The report of a contact fit as text: the fit, the fixed unknowns, the
/// tool offset and planes, the in-sample consistency (mm), the rows a
/// robust loss weighed down and the held-out placements, if any.
#[must_use]
pub fn text(
    file: &ContactFile,
    fit: &ContactFit,
    fig: &Figures,
    held: Option<&PlacementHoldout>,
) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "{}: {} contacts with {} points and {} planes; {} unknowns estimated ({} robot unknowns fixed), {:?} after {} iterations, σ̂ = {}",
        file.origin,
        file.qs.len(),
        file.points.len(),
        file.planes.len(),
        fit.estimate.len(),
        fit.fixed.len(),
        fit.stop,
        fit.iterations,
        fit.sigma_hat
            .map_or("-".into(), |v| format!("{:.4} mm", 1e3 * v))
    );
    for f in &fit.fixed {
        let _ = writeln!(s, "  fixed {} = {:.6}: {}", f.name, f.value, f.reason);
    }
    let t = fit.tool_offset;
    let _ = writeln!(
        s,
        "tool offset (end frame): {:.3} {:.3} {:.3} mm",
        1e3 * t[0],
        1e3 * t[1],
        1e3 * t[2]
    );
    for p in &fit.planes {
        let n = p.normal;
        let _ = writeln!(
            s,
            "plane {} ({}): normal {:.5} {:.5} {:.5}, offset {:.3} mm",
            p.name,
            if p.known { "given" } else { "estimated" },
            n[0],
            n[1],
            n[2],
            1e3 * p.offset_m
        );
    }
    let _ = writeln!(
        s,
        "in-sample consistency (RMS distance to the point's mean; a plane's: RMS signed distance to it):"
    );
    s += &figures_text(fig);
    let down = downweighted_rows(fit, file);
    if !down.is_empty() {
        let _ = writeln!(s, "down-weighted rows ({}):", down.len());
        for d in &down {
            let _ = writeln!(s, "  line {} ({}): weight {:.3}", d.line, d.point, d.weight);
        }
    }
    if let Some(h) = held {
        s += &holdout_text(h);
    }
    s
}

/// The consistency figures, one line per point, plane and distance (mm).
fn figures_text(f: &Figures) -> String {
    let mut s = String::new();
    for p in &f.points {
        let _ = writeln!(
            s,
            "  {:<20} {:>3} rows  nominal {:7.3} mm  calibrated {:7.3} mm",
            p.point, p.rows, p.nominal_mm, p.calibrated_mm
        );
    }
    let _ = writeln!(
        s,
        "  pooled                        nominal {:7.3} mm  calibrated {:7.3} mm",
        f.nominal_mm, f.calibrated_mm
    );
    for p in &f.planes {
        let _ = writeln!(
            s,
            "  plane {:<14} {:>3} rows  nominal {:7.3} mm  calibrated {:7.3} mm{}",
            p.plane,
            p.rows,
            p.nominal_mm,
            p.calibrated_mm,
            if p.known { " (given plane)" } else { "" }
        );
    }
    for d in &f.distances {
        let _ = writeln!(
            s,
            "  distance {} – {} ({:.3} mm): error nominal {:.3} mm, calibrated {:.3} mm",
            d.a, d.b, d.known_mm, d.nominal_error_mm, d.calibrated_error_mm
        );
    }
    s
}

/// The held-out placements' figures (mm).
fn holdout_text(h: &PlacementHoldout) -> String {
    let mut s = format!("\nheld out ({}):\n", h.mode);
    for f in &h.folds {
        let _ = writeln!(
            s,
            "held out {} (trained on {}; {} unknowns, {} fixed{}):",
            f.held_out,
            f.trained_on.join(", "),
            f.estimated,
            f.fixed,
            if f.converged { "" } else { "; NOT converged" }
        );
        s += &figures_text(&f.figures);
        if !f.downweighted.is_empty() {
            let rows: Vec<String> = f
                .downweighted
                .iter()
                .map(|d| format!("line {} ({}, w {:.2})", d.line, d.point, d.weight))
                .collect();
            let _ = writeln!(s, "  down-weighted training rows: {}", rows.join("; "));
        }
    }
    let _ = writeln!(
        s,
        "pooled over every held-out row: nominal {:.3} mm, calibrated {:.3} mm; mean over folds {:.3} mm",
        h.pooled_nominal_mm, h.pooled_calibrated_mm, h.mean_calibrated_mm
    );
    if let (Some(m), Some(x)) = (h.mean_distance_error_mm, h.max_distance_error_mm) {
        let _ = writeln!(
            s,
            "distance error, calibrated: mean {m:.3} mm, largest {x:.3} mm"
        );
    }
    s
}

/// A contact evaluation of robot `robot` on `origin` (`rows` contacts) as
/// text: the pooled and per-point consistency, each distance's error and
/// each plane's flatness, mm.
#[must_use]
pub fn contact_evaluation_text(
    robot: &str,
    origin: &str,
    rows: usize,
    e: &ContactEvaluation,
) -> String {
    let mut s = format!(
        "{robot} on {origin} ({rows} contacts, tool point at the chain's tip): consistency pooled {:.3} mm (RMS distance to the point's mean)\n",
        e.pooled_mm
    );
    for p in &e.points {
        let _ = writeln!(
            s,
            "  {:<20} {:>3} rows  {:8.3} mm",
            p.point, p.rows, p.consistency_mm
        );
    }
    for d in &e.distances {
        let _ = writeln!(
            s,
            "  distance {} – {} ({:.3} mm): error {:.3} mm",
            d.a, d.b, d.known_mm, d.error_mm
        );
    }
    for p in &e.planes {
        let _ = writeln!(
            s,
            "  plane {:<14} {:>3} rows  {:8.3} mm RMS signed distance{}",
            p.plane,
            p.rows,
            p.rms_mm,
            if p.known {
                " (given plane)"
            } else {
                " (best-fit plane)"
            }
        );
    }
    s
}

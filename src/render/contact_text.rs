//! A contact calibration as text: the fit (unknowns estimated and fixed,
//! the tool offset, the planes), the in-sample and held-out consistency per
//! point, plane and known distance (mm), the rows a robust loss weighed
//! down, the notes of the gross-error test, the tool point's predicted true
//! error and the files written. The same text is printed by `calibrate`
//! and kept in the report folder ([`write_report`]).

use super::contact_figures::ContactReport;
use crate::identify::contact::holdout::{Figures, downweighted_rows};
use crate::identify::contact::predict::PredictedTrueError;
use crate::identify::contact::{ContactFile, ContactFit, HoldoutReport};
use std::fmt::Write as _;
use std::path::Path;

/// What a contact calibration adds to its report beyond the fit: the
/// gross-error test's notes, the predicted true error, the files written.
#[derive(Clone, Copy, Debug, Default)]
pub struct Extras<'a> {
    /// What the gross-error test did, in words.
    pub notes: &'a [String],
    /// The tool point's predicted true error.
    pub predicted: Option<&'a PredictedTrueError>,
    /// The files written.
    pub written: &'a [String],
}

/// The whole text report of a contact calibration.
#[must_use]
pub fn text(r: &ContactReport<'_>, extras: Extras<'_>) -> String {
    let mut report = fit_text(r.file, r.fit, r.figures, r.held);
    for n in extras.notes {
        let _ = writeln!(report, "note: {n}");
    }
    if let Some(p) = extras.predicted {
        let _ = writeln!(
            report,
            "predicted true error of the calibrated tool point (the fit's covariance at {} random configurations): {:.4} mm RMS; it includes what held-out placements cannot see (an error common to a placement's rows)",
            p.configurations, p.rms_mm
        );
    }
    if !extras.written.is_empty() {
        report.push('\n');
    }
    for out in extras.written {
        let _ = writeln!(report, "calibrated robot written to {out}");
    }
    report
}

/// Writes the report folder of a contact calibration: its `text`, its
/// `json` object, the figures and the 3D page of the robot at each row's
/// configuration, labelled by its file line and what it touched.
pub fn write_report(
    dir: &Path,
    r: &ContactReport<'_>,
    text: &str,
    json: &serde_json::Value,
) -> crate::error::Result<()> {
    let file = r.file;
    let touches = |g: usize| match file.points.get(g) {
        Some(p) => format!("point {p}"),
        None => format!("plane {}", g - file.points.len() + 1),
    };
    let poses: Vec<(String, Vec<f64>)> = file
        .qs
        .iter()
        .zip(&file.groups)
        .zip(&file.lines)
        .map(|((q, g), l)| (format!("line {l}: {}", touches(*g)), q.clone()))
        .collect();
    super::folder::contacts(dir, r.robot, text, json, &poses, |d| {
        super::contact_figures::draw(d, r)
    })
}

/// The fit as text (the first part of [`text`]).
fn fit_text(
    file: &ContactFile,
    fit: &ContactFit,
    fig: &Figures,
    held: Option<&HoldoutReport>,
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

/// Per point, pooled, per plane and per known distance: nominal and
/// calibrated consistency, mm.
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

/// The held-out folds' figures, pooled and averaged, mm.
fn holdout_text(h: &HoldoutReport) -> String {
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

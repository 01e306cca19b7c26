//! `evaluate --measurements contacts.csv`: a model's consistency on a
//! contact file (no fit): per point, pooled, each `--point-distance`'s error
//! and each plane's flatness, mm. The work is in
//! `activecal::identify::contact::evaluate`.

use super::contact::contact_setup;
use super::measured::EvaluateArgs;
use activecal::identify::contact::evaluate::{ContactEvaluation, evaluate_contacts};
use activecal::io::contacts::read_contacts;
use anyhow::Result;
use std::fmt::Write as _;

/// Runs `evaluate` on a contact file.
pub fn cmd_evaluate_contacts(a: &EvaluateArgs) -> Result<()> {
    let desc = super::load_description(&a.robot)?;
    let (given, planes) = contact_setup(&desc.contacts, &a.point_distance, &a.plane)?;
    let robot = desc.robot;
    let mut file = read_contacts(&a.measurements, &robot, a.units.units())?;
    activecal::experiment::contacts::checked_inputs(
        &robot,
        &mut file,
        &planes,
        &given,
        activecal::experiment::contacts::ContactUse::Evaluate,
    )
    .map_err(super::contact::named)?;
    let e = evaluate_contacts(&robot, &robot.nominal, &[0.0; 3], &file, &given);
    let report = activecal::report::ContactEvaluationReport {
        robot: robot.name.clone(),
        chain: activecal::report::chain(&robot),
        measurements: a.measurements.display().to_string(),
        rows: file.qs.len(),
        contacts: e,
    };
    super::emit_report(a.json, &report, || {
        text(&robot.name, &file.origin, file.qs.len(), &report.contacts)
    })
}

/// The evaluation as text.
fn text(robot: &str, origin: &str, rows: usize, e: &ContactEvaluation) -> String {
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

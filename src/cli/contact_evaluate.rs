//! `evaluate --measurements contacts.csv`: a model's consistency on a
//! contact file (no fit): per point, pooled, each `--point-distance`'s error
//! and each plane's flatness, mm. The work is in
//! `activecal::experiment::contacts::evaluate`.

use super::contact::contact_setup;
use super::measured::EvaluateArgs;
use activecal::io::contacts::read_contacts;
use anyhow::Result;

/// Runs `evaluate` on a contact file.
pub fn cmd_evaluate_contacts(a: &EvaluateArgs) -> Result<()> {
    let desc = super::load_description(&a.robot)?;
    let (given, planes) = contact_setup(&desc.contacts, &a.point_distance, &a.plane)?;
    let robot = desc.robot;
    let mut file = read_contacts(&a.measurements, &robot, a.units.units())?;
    let measurements = a.measurements.display().to_string();
    let report = activecal::experiment::contacts::evaluate(
        &robot,
        &mut file,
        &planes,
        &given,
        &measurements,
    )
    .map_err(super::contact::named)?;
    super::emit_report(a.json, &report, || {
        activecal::render::contact_text::contact_evaluation_text(
            &robot.name,
            &file.origin,
            file.qs.len(),
            &report.contacts,
        )
    })
}

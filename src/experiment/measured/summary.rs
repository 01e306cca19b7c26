//! What the report folder (`render::folder`) shows of a calibration from
//! measurements: one summary for the command line and the Python package.

use crate::data::Measurements;
use crate::identify::{Identification, ModelErrors};
use crate::model::Robot;

/// What the report folder shows of a calibration from measurements
/// (`calibrate --measurements … --report`, Python's `Calibration`):
/// `source` says where the data came from, `json` is the command's report.
pub fn measured<'a>(
    robot: &'a Robot,
    id: &'a Identification,
    source: String,
    r: &super::MeasuredReport,
    json: &serde_json::Value,
    meas: &Measurements,
) -> crate::render::summary::CalibrationSummary<'a> {
    let pos = |e: &ModelErrors| -> Vec<f64> {
        e.per_sample
            .iter()
            .flat_map(|s| s.position_mm.iter().copied())
            .collect()
    };
    let ori = |e: &ModelErrors| -> Option<Vec<f64>> {
        e.per_sample.iter().map(|s| s.orientation_deg).collect()
    };
    let mut notes: Vec<String> = r
        .fixed
        .iter()
        .map(|f| {
            format!(
                "Fixed at nominal: {}",
                serde_json::to_string(f).unwrap_or_default()
            )
        })
        .collect();
    if let Some(h) = &r.holdout {
        notes.push(format!(
            "Held-out position RMS over {} splits: {:.3} mm calibrated, {:.3} mm nominal (mean).",
            h.splits.len(),
            h.position_rms_mm.mean,
            h.nominal_position_rms_mm
        ));
    }
    crate::render::summary::CalibrationSummary {
        robot,
        id,
        source,
        what: "pose",
        position_mm: (pos(&r.nominal_residuals), pos(&r.residuals)),
        orientation_deg: ori(&r.nominal_residuals).zip(ori(&r.residuals)),
        params: r
            .parameters
            .iter()
            .map(|p| (p.name.clone(), p.change, p.std))
            .collect(),
        splits: r.holdout.as_ref().map(|h| {
            (
                h.splits.iter().map(|s| s.nominal.position_rms_mm).collect(),
                h.splits
                    .iter()
                    .map(|s| s.held_out.position_rms_mm)
                    .collect(),
            )
        }),
        notes,
        json: json.clone(),
        poses: Some(crate::render::summary::FitPoses {
            qs: meas.qs().to_vec(),
            measured: (meas.points().len() == meas.qs().len()).then(|| meas.points().to_vec()),
            flagged: r.outliers.left_out.iter().map(|o| o.pose).collect(),
        }),
    }
}

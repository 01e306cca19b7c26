//! A simulated calibration as text (`calibrate --design`): the design,
//! noise and seed, the fit's status, Tables III and IV, the validation
//! errors before and after (m, rad), the Monte-Carlo summary and frames.

use crate::identify::MonteCarloSummary;
use crate::identify::tables::PaperTables;
use crate::report::SimulatedCalibrationReport;

/// The text report of a simulated calibration: `report`, the `tables`
/// (Tables III and IV), and `noise_note` after the noise (where σ came
/// from, or empty).
#[must_use]
pub fn text(report: &SimulatedCalibrationReport, tables: &PaperTables, noise_note: &str) -> String {
    let id = &tables.identification;
    let (before, after) = (report.validation_rms_before, report.validation_rms_after);
    let (rot_before, rot_after) = (
        report.validation_orientation_rms_before,
        report.validation_orientation_rms_after,
    );
    let (mc, mc_seconds) = (
        &report.monte_carlo,
        report.monte_carlo_seconds.unwrap_or(0.0),
    );
    let noise = match report.orientation_noise {
        Some(o) => format!("σ = {} m and {o:.3e} rad (full poses)", report.noise),
        None => format!("σ = {} m", report.noise),
    };
    let mut s = format!(
        "{}: {} poses, {noise}{noise_note}, seed {}\n{}",
        report.design,
        report.poses,
        report.seed,
        super::measured_text::status_text(id)
    );
    s += "\nestimate (Table III)\n";
    s += &tables.estimate.to_text(6);
    s += "\nresidual = real − estimate (Table IV)\n";
    s += &tables.residual.to_text(6);
    if let Some(std) = &tables.std {
        s += "\nstandard deviation\n";
        s += &std.to_text(6);
    }
    s += &format!(
        "\nvalidation ({} held-out poses): RMS {} error {before:.6} m before, {after:.6} m after\n",
        report.validation_poses,
        position_error_name(report.measurement)
    );
    if let (Some(b), Some(f)) = (rot_before, rot_after) {
        s += &format!("validation: RMS orientation error {b:.6e} rad before, {f:.6e} rad after\n");
    }
    if let Some(mc) = &mc {
        s += &mc_text(mc, mc_seconds);
    }
    if let Some(f) = &report.frames {
        s += &super::frames_text::frames_text(f);
    }
    s
}

/// What the validation's position error measures for a robot measured by
/// `kind`: the end point's `position`, or the coordinates of it the sensor
/// reads (`z` for a height gauge), by its
/// [`crate::measure::Sensor::point_coordinates`].
fn position_error_name(kind: crate::model::MeasurementKind) -> String {
    let read = crate::measure::sensor_of(kind, 1.0).point_coordinates();
    if read.len() == 3 {
        "position".to_string()
    } else {
        read.iter()
            .map(|&k| ["x", "y", "z"][k])
            .collect::<Vec<_>>()
            .join(" ")
    }
}

/// The Monte-Carlo summary as text.
fn mc_text(mc: &MonteCarloSummary, seconds: f64) -> String {
    let mut s = format!(
        "\nMonte-Carlo: {} trials ({} converged {:?}) in {seconds:.2} s\n",
        mc.trials, mc.converged, mc.statuses
    );
    if let Some(it) = &mc.iterations {
        s += &format!("iterations: median {} max {}\n", it.median, it.max);
    }
    if let (Some(n), Some(r)) = (mc.ln_det_information_nominal, mc.ln_det_information_real) {
        s += &format!("ln det XᵀX: {n:.3} (nominal), {r:.3} (real)\n");
    }
    s += "    parameter          truth           bias            std           rmse  predicted std  rmse/pred\n";
    for p in &mc.parameters {
        s += &format!(
            "{:>13} {:>14.6} {:>14.3e} {:>14.3e} {:>14.3e} {:>14.3e} {:>10.3}\n",
            p.name,
            p.truth,
            p.bias,
            p.std,
            p.rmse,
            p.predicted_std,
            p.rmse / p.predicted_std
        );
    }
    if let Some(r) = &mc.rmse_over_predicted {
        s += &format!(
            "rmse/predicted std: min {:.3} median {:.3} max {:.3}\n",
            r.min, r.median, r.max
        );
    }
    if let Some(g) = &mc.generalized_variance {
        s += &format!(
            "ln det C_emp − ln det C_pred = {:.3} (linear-Gaussian expectation {:.3} ± {:.3}, z = {:.2}; bootstrap sd {})\n",
            g.ln_ratio,
            g.expected,
            g.sd_model,
            g.z,
            g.sd_bootstrap.map_or("-".into(), |v| format!("{v:.3}"))
        );
    }
    if let Some(v) = &mc.validation_rms_after {
        s += &format!(
            "validation RMS ({} poses): before {:.6} m; after median {:.6} mean {:.6} p95 {:.6} max {:.6} m (predicted {})\n",
            mc.validation_poses,
            mc.validation_rms_before,
            v.median,
            v.mean,
            v.p95,
            v.max,
            mc.validation_rms_predicted
                .map_or("-".into(), |p| format!("{p:.6}"))
        );
    }
    if let (Some(b), Some(v)) = (
        mc.validation_orientation_rms_before,
        &mc.validation_orientation_rms_after,
    ) {
        s += &format!(
            "validation RMS orientation: before {b:.6e} rad; after median {:.6e} p95 {:.6e} rad (predicted {})\n",
            v.median,
            v.p95,
            mc.validation_orientation_rms_predicted
                .map_or("-".into(), |p| format!("{p:.6e}"))
        );
    }
    s
}

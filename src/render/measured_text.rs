//! A calibration from measured data as text (`calibrate --measurements`,
//! and the report folder's report.md): the fit's status, the unknowns
//! fixed and estimated, noise blocks, residuals, the predicted error, the
//! stated noise's test, the poses left out, the parameters with σ and t,
//! compliances, frames and held-out splits, every figure with its unit.

use crate::identify::Identification;
use crate::identify::compliance::{ComplianceComparison, ComplianceReport};
use crate::report::measured::{FullModelGain, MeasuredReport};

/// The fit's status, residual sum of squares, σ̂ and rank, as text.
#[must_use]
pub fn status_text(id: &Identification) -> String {
    let mut s = format!(
        "status: {:?} ({:?}) after {} iterations, {} evaluations\n",
        id.status, id.stop, id.iterations, id.evaluations
    );
    s += &format!(
        "rss {:.6e} (start {:.6e}), σ̂ = {}, rank {}/{}\n",
        id.rss,
        id.initial_rss,
        id.sigma_hat.map_or("-".into(), |v| format!("{v:.6}")),
        id.rank,
        id.names.len()
    );
    if !id.unidentifiable.is_empty() {
        s += &format!("unidentifiable: {}\n", id.unidentifiable.join(" "));
    }
    s
}

/// The text form of a calibration from measured data: the fit's
/// `status` ([`status_text`]), the unknowns fixed and estimated, noise,
/// residuals, the parameters with σ and t, compliances, frames, held-out
/// splits.
#[must_use]
pub fn measured_text(r: &MeasuredReport, id: &Identification, status: &str) -> String {
    let mut s = format!(
        "{}: {} measured poses ({}), {} parameters\n{status}",
        r.base.measurements,
        r.base.poses,
        r.base.measurement.name(),
        id.names.len()
    );
    if !r.fixed.is_empty() {
        s += &format!(
            "fixed at nominal, not determined by these data ({}):\n",
            r.fixed.len()
        );
        for f in &r.fixed {
            s += &format!("  {} = {:.6} ({})\n", f.name, f.value, f.reason);
        }
    }
    s += &format!(
        "unknowns: {} estimated of {} chosen for the robot ({} fixed: the data do not determine them)\n",
        id.names.len(),
        id.names.len() + r.fixed.len(),
        r.fixed.len()
    );
    s += &noise_text(&r.noise);
    s += &format!("fitted:  {}\n", r.residuals.summary());
    match r.nominal_placed_position_rms_mm {
        Some(placed) => {
            s += &format!(
                "nominal geometry, best rigid placement of the measurement frame: position RMS {placed:.3} mm\n"
            );
            s += &format!(
                "nominal as given (the measurement frame at the base): {}\n",
                r.nominal_residuals.summary()
            );
        }
        None => s += &format!("nominal: {}\n", r.nominal_residuals.summary()),
    }
    s += &judgement_text(r, id);
    if !r.downweighted.is_empty() {
        let v: Vec<String> = r
            .downweighted
            .iter()
            .map(|(i, w)| format!("pose {i} (weight {w:.3})"))
            .collect();
        s += &format!("down-weighted by the {:?} loss: {}\n", r.loss, v.join(", "));
    }
    s += &format!(
        "\n{:<24} {:>13} {:>13} {:>11} {:>10} {:>7}  verdict\n",
        "parameter", "nominal", "estimate", "change", "σ", "t"
    );
    for p in &r.parameters {
        s += &format!(
            "{:<24} {:>13.6} {:>13.6} {:>11.6} {:>10} {:>7}  {}\n",
            p.name,
            p.nominal,
            p.estimate,
            p.change,
            p.std.map_or("-".into(), |v| format!("{v:.6}")),
            p.t.map_or("-".into(), |v| format!("{v:.2}")),
            p.verdict
        );
    }
    if let Some(c) = &r.compliance {
        s += &compliance_text(c);
    }
    if let Some(f) = &r.frames {
        s += &super::frames_text::frames_text(f);
    }
    if let Some(h) = &r.holdout {
        s += &format!(
            "\nheld out ({} splits, {:.0} % held out each, seed {}): position RMS {:.3} mm (per split {}), nominal {:.3} mm, fitted on training {:.3} mm\n",
            h.settings.splits,
            100.0 * h.settings.fraction,
            h.settings.seed,
            h.position_rms_mm.mean,
            join(&h.position_rms_mm.per_split, 3),
            h.nominal_position_rms_mm,
            h.fitted_position_rms_mm
        );
        if let Some(o) = &h.orientation_rms_deg {
            s += &format!(
                "held out orientation RMS {:.4}° (per split {})\n",
                o.mean,
                join(&o.per_split, 4)
            );
        }
        if let Some(p) = &h.pruned {
            s += &format!(
                "pruned to |t| >= 2 ({} parameters per split): held-out position RMS {:.3} mm (per split {})",
                join(&p.n_params.iter().map(|&v| v as f64).collect::<Vec<_>>(), 0),
                p.position_rms_mm.mean,
                join(&p.position_rms_mm.per_split, 3)
            );
            if let Some(o) = &p.orientation_rms_deg {
                s += &format!(", orientation {:.4}°", o.mean);
            }
            s += &format!(
                "\n  → {} model generalises better on held-out poses\n",
                if p.position_rms_mm.mean < h.position_rms_mm.mean {
                    "the pruned"
                } else {
                    "the full"
                }
            );
        }
    }
    if let Some(c) = &r.compliance_comparison {
        s += &format!("\ncompliance on the same splits:\n{}", comparison_text(c));
    }
    s
}

/// What the report says of the fit beyond its residuals: the calibrated
/// model's own predicted error, σ̂ against the stated noise, the poses left
/// out as gross errors.
fn judgement_text(r: &MeasuredReport, id: &Identification) -> String {
    let mut s = String::new();
    if let Some(p) = &r.predicted {
        s += &format!(
            "predicted for the calibrated model (σ̂ {:.4} mm per coordinate): position RMS {:.4} mm at {} random configurations (95th percentile of the error {:.4} mm){}\n",
            id.sigma_hat.unwrap_or(f64::NAN) * 1e3,
            p.position_rms_mm,
            crate::report::measured::PREDICTION_CONFIGURATIONS,
            p.position_error_p95_mm,
            p.orientation_rms_deg
                .map_or(String::new(), |o| format!(", orientation RMS {o:.4}°"))
        );
    }
    if let Some(t) = &r.noise_test {
        s += &format!(
            "stated noise {:.4} mm per coordinate: σ̂ is {:.2}× it (χ² on {} dof: P(larger) {:.2e}, P(smaller) {:.2e}){}\n",
            t.stated_m * 1e3,
            t.ratio,
            t.dof,
            t.p_larger,
            t.p_smaller,
            if t.rejected {
                ", rejected: see the warning"
            } else {
                ", consistent"
            }
        );
    }
    if !r.outliers.left_out.is_empty() {
        let v: Vec<String> = r
            .outliers
            .left_out
            .iter()
            .map(|o| {
                format!(
                    "pose {} ({:.3} mm, F {:.1}, P {:.1e})",
                    o.pose + 1,
                    o.residual_mm,
                    o.test.statistic,
                    o.test.p_value
                )
            })
            .collect();
        s += &format!("left out as gross errors: {}\n", v.join(", "));
    }
    s
}

/// Numbers with `d` decimals, space-separated.
#[must_use]
pub fn join(v: &[f64], d: usize) -> String {
    v.iter()
        .map(|x| format!("{x:.d$}"))
        .collect::<Vec<_>>()
        .join(" ")
}

/// The blocks' estimated σ's and the weight between them.
fn noise_text(n: &crate::report::measured::NoiseReport) -> String {
    let blocks: Vec<String> = n
        .blocks
        .iter()
        .map(|b| {
            let (v, unit) = match b.unit {
                "rad" => (b.sigma.to_degrees(), "°"),
                _ => (b.sigma * 1e3, " mm"),
            };
            format!("{} σ {v:.4}{unit} ({:.1} dof)", b.block, b.redundancy)
        })
        .collect();
    let mut s = format!(
        "noise per coordinate, from the residuals: {}\n",
        blocks.join(", ")
    );
    if n.blocks.iter().any(|b| b.unit == "rad") {
        s += &format!(
            "orientation weight: {:.4} m/rad ({}{})\n",
            n.orientation_scale_m_per_rad,
            match n.weights {
                crate::identify::Weights::Estimated => "estimated: σ_position / σ_orientation",
                crate::identify::Weights::Fixed => "fixed",
            },
            if n.rounds > 0 {
                format!(", {} reweighting rounds", n.rounds)
            } else {
                String::new()
            }
        );
    }
    s
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len().max(1) as f64
}

/// The text of a comparison.
#[must_use]
pub fn comparison_text(c: &ComplianceComparison) -> String {
    let mut s = format!(
        "geometric only:   held-out position RMS {:.3} mm (per split {}), fitted {:.3} mm\n",
        mean(&c.geometric_position_rms_mm),
        join(&c.geometric_position_rms_mm, 3),
        mean(&c.geometric_fitted_rms_mm)
    );
    s += &format!(
        "with compliance:  held-out position RMS {:.3} mm (per split {}), fitted {:.3} mm\n",
        mean(&c.compliant_position_rms_mm),
        join(&c.compliant_position_rms_mm, 3),
        mean(&c.compliant_fitted_rms_mm)
    );
    if let (Some(g), Some(k)) = (
        &c.geometric_orientation_rms_deg,
        &c.compliant_orientation_rms_deg,
    ) {
        s += &format!(
            "held-out orientation RMS {:.4}° geometric, {:.4}° with compliance\n",
            mean(g),
            mean(k)
        );
    }
    s + &format!("  → {}\n", c.verdict)
}

/// The text of fitted compliances.
#[must_use]
pub fn compliance_text(r: &ComplianceReport) -> String {
    let mut s = format!(
        "\n{:<22} {:>12} {:>11} {:>7} {:>14} {:>18} {:>10} {:>9}\n",
        "compliance", "c rad/(N·m)", "σ", "t", "k N·m/rad", "τ range N·m", "max mrad", "max mm"
    );
    for e in &r.estimates {
        s += &format!(
            "{:<22} {:>12.4e} {:>11} {:>7} {:>14} {:>18} {:>10.3} {:>9.3}\n",
            e.joint,
            e.c,
            e.std.map_or("-".into(), |v| format!("{v:.3e}")),
            e.t.map_or("-".into(), |v| format!("{v:.2}")),
            e.stiffness_nm_per_rad
                .map_or("-".into(), |k| format!("{k:.4e}")),
            format!("{:.2} … {:.2}", e.torque_range_nm[0], e.torque_range_nm[1]),
            e.max_deflection_mrad,
            e.max_deflection_tool_mm
        );
    }
    for w in &r.without {
        s += &format!("{:<22} no compliance: {}\n", w.joint, w.reason);
    }
    s + &format!(
        "largest deflection of the end point over the data: {:.3} mm\n",
        r.max_tool_deflection_mm
    )
}

/// `evaluate`'s report as text: the pooled errors and each pose's, mm and
/// degrees.
#[must_use]
pub fn evaluation_text(report: &crate::report::measured::EvaluationReport) -> String {
    let mut s = format!(
        "{} on {} ({} poses): {}\n",
        report.robot,
        report.measurements,
        report.poses,
        report.residuals.summary()
    );
    s += "pose  position error (mm)  orientation error (deg)\n";
    for p in &report.residuals.per_sample {
        s += &format!(
            "{:>4}  {:<20}  {}\n",
            p.pose,
            join(&p.position_mm, 3),
            p.orientation_deg.map_or("-".into(), |v| format!("{v:.4}"))
        );
    }
    s
}

/// The restricted fit's lines beside the full fit, and the relations held.
#[must_use]
pub fn full_model_gain_text(g: &FullModelGain, held_out: Option<f64>) -> String {
    let mut s = String::from("\n");
    if !g.relations_held.is_empty() {
        s += "axis relations kept (closed-form inverse kinematics stay valid):\n";
        for h in &g.relations_held {
            let held = if h.held.is_empty() {
                "no unknown to hold".to_string()
            } else {
                h.held.join(", ")
            };
            s += &format!("  {} – {}: {} (held: {held})\n", h.from, h.to, h.relation);
        }
    }
    let ho = |v: Option<f64>| v.map_or(String::new(), |v| format!(", held out {v:.4} mm"));
    s += &format!(
        "{}: predicted position RMS {:.4} mm{}; the full model ({} unknowns, fitted to the same data) {:.4} mm{}: it would gain {:.4} mm (the two models are {:.4} mm apart, RMS at {} random configurations)\n",
        g.restricted.describe(),
        g.restricted_predicted_rms_mm,
        ho(held_out),
        g.full_unknowns,
        g.full_predicted_rms_mm,
        ho(g.full_held_out_rms_mm),
        g.gain_mm,
        g.models_apart_rms_mm,
        crate::report::measured::PREDICTION_CONFIGURATIONS
    );
    s
}

//! `calibrate --measurements` (identification from real data, with a loss,
//! fixed or freed unknowns, parameter significance and held-out splits) and
//! `evaluate` (a model's errors on data, no fitting): rendering only; the
//! work is in `activecal::experiment::measured` and `activecal::identify`.

use super::emit_report;
use activecal::experiment::measured::MeasuredReport;
use activecal::identify::evaluation::ModelErrors;
use activecal::identify::{Identification, LossChoice, Measurements, residuals};
use activecal::model::Robot;
use anyhow::{Result, bail};
use serde::Serialize;
use std::path::Path;

/// The loss options of `calibrate`.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum LossKind {
    /// Least squares.
    L2,
    /// Huber: quadratic up to the scale, linear beyond.
    Huber,
    /// Cauchy: down-weights gross outliers towards zero.
    Cauchy,
}

/// The loss of `--loss KIND --loss-scale S`.
pub fn loss_choice(kind: LossKind, scale: Option<f64>) -> Result<LossChoice> {
    let need = |s: Option<f64>| -> Result<f64> {
        match s {
            Some(s) if s.is_finite() && s > 0.0 => Ok(s),
            Some(s) => bail!("--loss-scale {s}: must be a finite number > 0 (metres)"),
            None => bail!(
                "--loss {kind:?} needs --loss-scale (metres: the residual norm of one pose where the loss turns robust, e.g. 3 times the sensor noise)"
            ),
        }
    };
    Ok(match kind {
        LossKind::L2 => {
            if scale.is_some() {
                bail!("--loss-scale is for --loss huber or cauchy");
            }
            LossChoice::L2
        }
        LossKind::Huber => LossChoice::Huber {
            scale: need(scale)?,
        },
        LossKind::Cauchy => LossChoice::Cauchy {
            scale: need(scale)?,
        },
    })
}

/// Reads a measurement file (CSV or JSON) for `robot` in `units`
/// ([`activecal::experiment::measured::read_measurement_file`]), printing
/// its notes to stderr unless `quiet`.
pub fn read_measurements(
    path: &Path,
    robot: &Robot,
    units: activecal::units::Units,
    quiet: bool,
) -> Result<(Measurements, Vec<String>)> {
    let (meas, notes) = activecal::experiment::measured::read_measurement_file(path, robot, units)?;
    if !quiet {
        for n in &notes {
            super::diag(&format!("note: {n}"));
        }
    }
    Ok((meas, notes))
}

/// The text form of a measured calibration.
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
        s += &super::compliance::compliance_text(c);
    }
    if let Some(f) = &r.frames {
        s += &activecal::render::frames_text::frames_text(f);
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
        s += &format!(
            "\ncompliance on the same splits:\n{}",
            super::compliance::comparison_text(c)
        );
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
            activecal::experiment::measured::PREDICTION_CONFIGURATIONS,
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

fn join(v: &[f64], d: usize) -> String {
    v.iter()
        .map(|x| format!("{x:.d$}"))
        .collect::<Vec<_>>()
        .join(" ")
}

/// Arguments of `evaluate`.
#[derive(clap::Args)]
pub struct EvaluateArgs {
    /// The model: a built-in name, a .toml description (e.g. what
    /// `calibrate --out` wrote) or a .urdf file; append `:pose` for full
    /// poses. Its nominal table is evaluated.
    #[arg(long, value_parser = super::parse_robot)]
    pub robot: activecal::io::RobotRef,
    /// Measurement file: CSV (x1,y1,z1…, optional phix1,phiy1,phiz1 or
    /// qw1…qz1, one column per joint by name) or JSON.
    #[arg(long)]
    pub measurements: std::path::PathBuf,
    /// Units of the measurement file.
    #[command(flatten)]
    pub units: super::units::UnitOpts,
    /// A contact file's known distance between two points, A,B=METRES
    /// (repeatable): its error is reported.
    #[arg(long = "point-distance", value_name = "A,B=METRES")]
    pub point_distance: Vec<String>,
    /// A contact file's known plane, NAME=nx,ny,nz,d (repeatable).
    #[arg(long, value_name = "NAME=nx,ny,nz,d", allow_hyphen_values = true)]
    pub plane: Vec<String>,
    /// Print one JSON object.
    #[arg(long)]
    pub json: bool,
    /// The options typed on the command line (set after parsing).
    #[arg(skip)]
    pub given: super::acts_on::Given,
}

/// `evaluate`'s report.
#[derive(Serialize)]
struct EvaluateReport {
    robot: String,
    chain: Vec<String>,
    measurements: String,
    poses: usize,
    residuals: ModelErrors,
    notes: Vec<String>,
}

/// Runs `evaluate`: the model's errors on the data, no fitting.
pub fn cmd_evaluate(a: EvaluateArgs) -> Result<()> {
    let robot = super::load_robot(&a.robot)?;
    let (meas, notes) = read_measurements(&a.measurements, &robot, a.units.units(), a.json)?;
    let res = residuals(&robot, &robot.nominal, &meas).map_err(|e| {
        anyhow::anyhow!(
            "{}: {e}{}",
            a.measurements.display(),
            if meas.markers() > 1 {
                " (a model for several markers carries their offsets: evaluate the description `calibrate --out` wrote)"
            } else {
                ""
            }
        )
    })?;
    let report = EvaluateReport {
        robot: robot.name.clone(),
        chain: activecal::report::chain(&robot),
        measurements: a.measurements.display().to_string(),
        poses: meas.len(),
        residuals: res,
        notes,
    };
    emit_report(a.json, &report, || {
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
    })
}

/// The blocks' estimated σ's and the weight between them.
fn noise_text(n: &activecal::experiment::measured::NoiseReport) -> String {
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
                activecal::identify::Weights::Estimated => "estimated: σ_position / σ_orientation",
                activecal::identify::Weights::Fixed => "fixed",
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

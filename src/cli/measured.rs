//! `calibrate --measurements` (identification from real data, with a loss,
//! fixed or freed unknowns, parameter significance and held-out splits) and
//! `evaluate` (a model's errors on data, no fitting): rendering only; the
//! work is in `activecal::identify`.

use super::emit_report;
use activecal::identify::compliance::with_compliance;
use activecal::identify::evaluation::ModelErrors;
use activecal::identify::{
    Fit, FixedParameter, HoldoutSettings, Identification, LmSettings, LossChoice, Measurements,
    ParameterTrust, SplitResult, fit, for_measurements, holdout, prepare_for_data, residuals,
    trust,
};
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

/// Reads a measurement file (CSV or JSON) for `robot` in `units`, printing
/// its notes to stderr unless `quiet`; positions beyond the robot's reach
/// are refused ([`activecal::identify::evaluation::check_in_reach`]).
pub fn read_measurements(
    path: &Path,
    robot: &Robot,
    units: activecal::units::Units,
    quiet: bool,
) -> Result<(Measurements, Vec<String>)> {
    let f = activecal::io::measurements::read_in(path, robot, units)?;
    activecal::identify::evaluation::check_in_reach(
        robot,
        &f.measurements,
        &path.display().to_string(),
        units.length,
    )?;
    let mut notes = f.notes;
    let (meas, repeats) = f.measurements.without_repeated_markers();
    for (copy, of) in repeats {
        notes.push(format!(
            "marker {} repeats marker {} in every row: counted once ({} markers per pose)",
            copy + 1,
            of + 1,
            meas.markers()
        ));
    }
    if !quiet {
        for n in &notes {
            eprintln!("note: {n}");
        }
    }
    Ok((meas, notes))
}

/// What `calibrate --measurements` does beyond the plain fit.
pub struct MeasuredOptions<'a> {
    /// Levenberg–Marquardt settings.
    pub lm: LmSettings,
    /// The loss.
    pub loss: LossChoice,
    /// Unknowns to fix.
    pub fix: &'a [String],
    /// Parameters to free.
    pub free: &'a [String],
    /// Held-out validation, if asked.
    pub holdout: Option<HoldoutSettings>,
    /// JSON output (notes to stderr are silenced).
    pub json: bool,
    /// Units of the measurement file.
    pub units: activecal::units::Units,
    /// The gravity model, when compliances are fitted or compared.
    pub gravity: Option<std::sync::Arc<activecal::model::gravity::GravityModel>>,
    /// Fit a compliance per joint whose gravity torque varies.
    pub fit_compliance: bool,
    /// With held-out splits: fit with and without compliances, side by side.
    pub compare_compliance: bool,
}

/// `calibrate --measurements`' JSON report.
#[derive(Serialize)]
pub struct MeasuredReport {
    /// The plain identification report (status, estimate, covariance, …).
    #[serde(flatten)]
    pub base: activecal::report::MeasuredCalibrationReport,
    /// The loss.
    pub loss: LossChoice,
    /// Errors of the fitted model on the data, mm and degrees.
    pub residuals: ModelErrors,
    /// Errors of the nominal model on the data.
    pub nominal_residuals: ModelErrors,
    /// Each parameter's estimate, change, σ, t and verdict.
    pub parameters: Vec<ParameterTrust>,
    /// Unknowns the data do not determine, fixed at nominal, with why.
    pub fixed: Vec<FixedParameter>,
    /// Poses the robust loss down-weighted: `[pose, weight]`.
    pub downweighted: Vec<(usize, f64)>,
    /// Held-out validation, if asked.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub holdout: Option<HoldoutReport>,
    /// What was adapted to the data (sensor, markers, ignored columns).
    pub notes: Vec<String>,
    /// The calibrated robot's measurement frame, tool or markers and joint
    /// origins (URDF robots).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub frames: Option<activecal::frames::report::FramesReport>,
    /// The fitted joint compliances.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub compliance: Option<activecal::identify::compliance::ComplianceReport>,
    /// Held-out errors with and without compliances on the same splits.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub compliance_comparison: Option<super::compliance::ComplianceComparison>,
}

/// Held-out figures over splits.
#[derive(Serialize)]
pub struct HoldoutReport {
    /// The settings.
    pub settings: HoldoutSettings,
    /// Held-out position RMS (mm): mean and per split.
    pub position_rms_mm: Stat,
    /// Held-out orientation RMS (degrees), full poses only.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub orientation_rms_deg: Option<Stat>,
    /// The nominal model's held-out position RMS (mm), mean over splits.
    pub nominal_position_rms_mm: f64,
    /// The fitted model's position RMS on its training poses, mean.
    pub fitted_position_rms_mm: f64,
    /// The pruned model (|t| ≥ 2 kept): unknowns per split and held-out
    /// position RMS.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pruned: Option<PrunedReport>,
    /// Every split.
    pub splits: Vec<SplitResult>,
}

/// A figure over splits.
#[derive(Serialize)]
pub struct Stat {
    /// Mean over splits.
    pub mean: f64,
    /// Each split's value.
    pub per_split: Vec<f64>,
}

impl Stat {
    fn of(v: Vec<f64>) -> Stat {
        Stat {
            mean: v.iter().sum::<f64>() / v.len().max(1) as f64,
            per_split: v,
        }
    }
}

/// The pruned model's held-out figures.
#[derive(Serialize)]
pub struct PrunedReport {
    /// Parameters identified per split.
    pub n_params: Vec<usize>,
    /// Held-out position RMS (mm).
    pub position_rms_mm: Stat,
    /// Held-out orientation RMS (degrees).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub orientation_rms_deg: Option<Stat>,
}

fn holdout_report(settings: HoldoutSettings, splits: Vec<SplitResult>) -> HoldoutReport {
    let mean = |v: &mut dyn Iterator<Item = f64>| {
        let x: Vec<f64> = v.collect();
        x.iter().sum::<f64>() / x.len().max(1) as f64
    };
    let ori = |f: &dyn Fn(&SplitResult) -> Option<f64>| -> Option<Stat> {
        splits
            .iter()
            .map(f)
            .collect::<Option<Vec<f64>>>()
            .map(Stat::of)
    };
    let pruned = settings.prune.then(|| PrunedReport {
        n_params: splits
            .iter()
            .filter_map(|s| s.pruned.as_ref().map(|p| p.0))
            .collect(),
        position_rms_mm: Stat::of(
            splits
                .iter()
                .filter_map(|s| s.pruned.as_ref().map(|p| p.1.position_rms_mm))
                .collect(),
        ),
        orientation_rms_deg: ori(&|s| s.pruned.as_ref().and_then(|p| p.1.orientation_rms_deg)),
    });
    HoldoutReport {
        settings,
        position_rms_mm: Stat::of(splits.iter().map(|s| s.held_out.position_rms_mm).collect()),
        orientation_rms_deg: ori(&|s| s.held_out.orientation_rms_deg),
        nominal_position_rms_mm: mean(&mut splits.iter().map(|s| s.nominal.position_rms_mm)),
        fitted_position_rms_mm: mean(&mut splits.iter().map(|s| s.fitted.position_rms_mm)),
        pruned,
        splits,
    }
}

/// How much better the rigid fit of the nominal points must fit the data
/// than the nominal model does before identification starts from it: a
/// tracker metres away and turned by tens of degrees gains 450–4,000×
/// (`tests/frames.rs`), where Levenberg–Marquardt from the nominal model
/// ends in a false minimum; FIGAROH's real TIAGo and UR10 data gain 125×
/// and 38× and converge from the nominal model, as before.
const MOUNT_GAIN: f64 = 200.0;

/// A URDF robot mounted in the data's frame when the nominal model is far
/// from it ([`activecal::frames::align`]), with a note saying so.
fn mounted_start(robot: &Robot, meas: &Measurements) -> Result<Option<(Robot, String)>> {
    let Some(src) = robot.source.as_ref() else {
        return Ok(None);
    };
    let Some(a) = activecal::frames::align::measurement_frame(robot, meas) else {
        return Ok(None);
    };
    if !(a.rms_after * MOUNT_GAIN < a.rms_before) {
        return Ok(None);
    }
    let mount = a.motion * src.mount;
    let r = activecal::io::urdf::remount(robot, mount, src.tool * a.tool)?;
    let t = mount.translation.vector;
    let note = format!(
        "the data are far from the nominal model (RMS {:.1} mm): identification starts from the measurement frame that fits them best (RMS {:.1} mm), {:.3} m away and turned {:.1}°",
        a.rms_before * 1e3,
        a.rms_after * 1e3,
        t.norm(),
        mount.rotation.angle().to_degrees()
    );
    Ok(Some((r, note)))
}

/// Identification from a measurement file; returns the fit (for `--out`)
/// and the robot it was fitted as.
pub fn calibrate_measured(
    robot: &Robot,
    path: &Path,
    o: &MeasuredOptions<'_>,
    elapsed: &dyn Fn() -> f64,
) -> Result<(Robot, Fit, MeasuredReport)> {
    let (meas, mut notes) = read_measurements(path, robot, o.units, o.json)?;
    let given = robot;
    let mounted = mounted_start(robot, &meas)?;
    let robot = match &mounted {
        Some((r, note)) => {
            if !o.json {
                eprintln!("note: {note}");
            }
            notes.push(note.clone());
            r
        }
        None => robot,
    };
    let start = for_measurements(robot, &meas, &o.lm)
        .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    notes.extend(start.notes.iter().cloned());
    if !o.json {
        for n in &start.notes {
            eprintln!("note: {n}");
        }
    }
    let (fitted_robot, without) = match (&o.gravity, o.fit_compliance) {
        (Some(g), true) => {
            let (r, w) = with_compliance(&start.robot, g, &meas);
            (r, Some(w))
        }
        _ => (start.robot.clone(), None),
    };
    let det = prepare_for_data(&fitted_robot, &start.table, &meas, o.fix, o.free)
        .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    let r = det.robot;
    let f = fit(&r, &start.table, &meas, &o.lm, o.loss)
        .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    let res = residuals(&r, &f.id.table, &meas)?;
    let nominal = match &mounted {
        // The user's nominal model in the data's frame as given (with the
        // best marker offsets for it), not the start mounted for the fit.
        Some(_) => match for_measurements(given, &meas, &o.lm) {
            Ok(s) => residuals(&s.robot, &s.robot.nominal, &meas)?,
            Err(_) => residuals(&r, &r.nominal, &meas)?,
        },
        None => residuals(&r, &r.nominal, &meas)?,
    };
    let params = trust(&r, &r.nominal, &f.id);
    let compliance = without.map(|w| activecal::identify::compliance::report(&r, &f.id, &meas, w));
    let gravity = |on: bool| o.gravity.clone().filter(|_| on);
    let prep_with = |g: Option<std::sync::Arc<activecal::model::gravity::GravityModel>>| {
        // The geometric model has no compliance to fix or free.
        let geometric = |v: &[String]| -> Vec<String> {
            v.iter()
                .filter(|n| g.is_some() || !n.starts_with("c_"))
                .cloned()
                .collect()
        };
        let (fix, free) = (geometric(o.fix), geometric(o.free));
        move |x: &Robot, t: &activecal::model::ParamTable, m: &Measurements| {
            let x = match &g {
                Some(g) => with_compliance(x, g, m).0,
                None => x.clone(),
            };
            prepare_for_data(&x, t, m, &fix, &free).map(|d| d.robot)
        }
    };
    let ho = match &o.holdout {
        Some(h) => {
            let prep = prep_with(gravity(o.fit_compliance));
            Some(holdout_report(
                *h,
                holdout(robot, given, &meas, &o.lm, o.loss, h, &prep)?,
            ))
        }
        None => None,
    };
    let comparison = match (&o.holdout, o.compare_compliance) {
        (Some(h), true) => {
            let plain = HoldoutSettings { prune: false, ..*h };
            let geo = holdout(robot, given, &meas, &o.lm, o.loss, &plain, &prep_with(None))?;
            let com = holdout(
                robot,
                given,
                &meas,
                &o.lm,
                o.loss,
                &plain,
                &prep_with(gravity(true)),
            )?;
            Some(super::compliance::compare(&geo, &com))
        }
        _ => None,
    };
    let mut base = activecal::report::MeasuredCalibrationReport::new(
        &r,
        &f.id,
        path.display().to_string(),
        meas.len(),
    );
    base.elapsed_seconds = elapsed();
    let report = MeasuredReport {
        base,
        loss: o.loss,
        residuals: res,
        nominal_residuals: nominal,
        parameters: params,
        fixed: det.fixed,
        downweighted: f.downweighted(),
        holdout: ho,
        notes,
        frames: None,
        compliance,
        compliance_comparison: comparison,
    };
    Ok((r, f, report))
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
    s += &format!("fitted:  {}\n", r.residuals.summary());
    s += &format!("nominal: {}\n", r.nominal_residuals.summary());
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
        s += &format!(
            "\ncompliance on the same splits:\n{}",
            super::compliance::comparison_text(c)
        );
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
    if !(a.point_distance.is_empty() && a.plane.is_empty()) {
        anyhow::bail!(
            "--point-distance and --plane are for contact files (a CSV with a point or plane column); {} is not one",
            a.measurements.display()
        );
    }
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

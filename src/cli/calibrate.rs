//! `calibrate`: simulate measurements at a design's poses, identify the
//! unknowns from the nominal parameters, validate on held-out poses, and
//! optionally repeat over noise realisations (Monte-Carlo); or identify from
//! a file of real measurements. Either way the calibrated robot can be
//! written as a description file.

use super::{emit, write_new};
use activecal::frames::CalibratedFrames;
use activecal::frames::report::{FitBlock, FramesReport};
use activecal::identify::{Identification, LmSettings, MonteCarloSettings, MonteCarloSummary};
use activecal::io::calibrated::Format;
use activecal::io::design::DesignFile;
use activecal::model::Robot;
use activecal::report::{IdentificationReport, SimulatedCalibrationReport};
use anyhow::{Result, bail};
use clap::Args;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Arguments of the command.
#[derive(Args)]
pub struct CalibrateArgs {
    /// Robot: a built-in name, or a .toml description or .urdf file; append
    /// `:pose` for full-pose measurements.
    #[arg(long, default_value = "puma560", value_parser = super::parse_robot)]
    pub robot: activecal::io::RobotRef,
    /// Design file (JSON with robot, levels, poses), as written by `select`:
    /// measurements are simulated there.
    #[arg(long, required_unless_present = "measurements")]
    pub design: Option<PathBuf>,
    /// Measurement file: identify from these real measurements instead of
    /// simulating a design. CSV (`x1,y1,z1`, `x2,y2,z2`… for several
    /// markers, optional `phix1,phiy1,phiz1` roll-pitch-yaw or
    /// `qw1,qx1,qy1,qz1`, one column per joint named as in the URDF; metres
    /// and radians) or JSON (`qs`, `points`, optional `orientations` or
    /// `quaternions`, `markers`). Several markers per pose calibrate a
    /// marker sensor with one offset per marker; orientations a full pose.
    /// The simulation's options (`--noise`, `--validation`, `--trials`,
    /// `--save-measurements`) do not apply to measured data: refused.
    #[arg(
        long,
        conflicts_with_all = ["design", "trials", "save_measurements", "noise", "validation"]
    )]
    pub measurements: Option<PathBuf>,
    /// Write the simulated measurements (trial 0 of the seed) to this JSON
    /// file, in the format `--measurements` reads.
    #[arg(long)]
    pub save_measurements: Option<PathBuf>,
    /// Write the calibrated robot, by extension (repeatable): .urdf — your
    /// URDF with only the chain's joint origins changed (a built-in or TOML
    /// robot: its chain as URDF); .yaml — the frames file (measurement
    /// frame, tool or markers, joint origins with σ); .toml — activecal's
    /// description whose tables are the estimate. Written only when the fit
    /// converged.
    #[arg(long)]
    pub out: Vec<PathBuf>,
    /// Replace existing output files.
    #[arg(long)]
    pub force: bool,
    /// Measurement noise σ per coordinate, metres (the default, 0.01, is
    /// 1 cm). A full-pose robot's orientation noise is σ / orientation_scale
    /// radians per axis.
    #[arg(long, default_value_t = DEFAULT_NOISE, allow_negative_numbers = true)]
    pub noise: f64,
    /// Seed of the noise and of the validation poses (default 0); with
    /// --measurements, of the --holdout splits only.
    #[arg(long, value_parser = super::parse_seed, allow_negative_numbers = true)]
    pub seed: Option<u64>,
    /// Noise realisations; more than 1 adds a Monte-Carlo summary.
    #[arg(long, default_value_t = 1, allow_negative_numbers = true)]
    pub trials: usize,
    /// Held-out lattice poses (not in the design) for the validation RMS.
    #[arg(long, default_value_t = 500, allow_negative_numbers = true)]
    pub validation: usize,
    /// Levenberg–Marquardt iteration limit.
    #[arg(long, default_value_t = 200, allow_negative_numbers = true)]
    pub max_iterations: usize,
    /// Plain Levenberg–Marquardt steps, without geodesic acceleration.
    #[arg(long)]
    pub no_geodesic: bool,
    /// Loss of the fit (with --measurements): l2, or huber / cauchy with
    /// --loss-scale; poses the robust loss down-weights are named.
    #[arg(long, value_enum, default_value = "l2", requires = "measurements")]
    pub loss: super::measured::LossKind,
    /// Scale of a robust loss: a pose's residual norm (metres) where it
    /// turns robust.
    #[arg(long, requires = "measurements")]
    pub loss_scale: Option<f64>,
    /// Unknowns to fix at their nominal values (comma-separated names, as
    /// in the estimate), with --measurements.
    #[arg(long, value_delimiter = ',', requires = "measurements")]
    pub fix: Vec<String>,
    /// Parameters to estimate besides the chosen unknowns (names such as
    /// `d_arm_3_joint`), with --measurements.
    #[arg(long, value_delimiter = ',', requires = "measurements")]
    pub free: Vec<String>,
    /// Held-out validation: fit on a random 1 − F of the poses, evaluate on
    /// the rest (with --measurements; --splits times, seeded by --seed).
    #[arg(long, value_name = "F", requires = "measurements")]
    pub holdout: Option<f64>,
    /// Random splits of --holdout.
    #[arg(long, default_value_t = 4, requires = "holdout")]
    pub splits: usize,
    /// With --holdout: also fit a model pruned to the parameters with
    /// |t| >= 2 and compare held-out errors.
    #[arg(long, requires = "holdout")]
    pub compare_pruned: bool,
    /// A distance known between two contact points (a file with a `point`
    /// column): `A,B=METRES`, repeatable.
    #[arg(long, value_name = "A,B=METRES", requires = "measurements")]
    pub point_distance: Vec<String>,
    /// A known contact plane (a file with a `plane` column): `NAME=nx,ny,nz,d`
    /// (base frame, `n · x = d` in metres; the normal is normalised),
    /// repeatable. Planes not given are unknown and estimated.
    #[arg(long, value_name = "NAME=nx,ny,nz,d", requires = "measurements")]
    pub plane: Vec<String>,
    /// Contacts held out by placement (the part of a point's name before
    /// '/'): fit on all placements but one, judge on that one, for each.
    #[arg(long, value_enum, requires = "measurements")]
    pub holdout_by: Option<super::contact::HoldoutBy>,
    /// Contacts: fit on this placement alone, judge on each other one.
    #[arg(long, value_name = "PLACEMENT", requires = "measurements")]
    pub train_on: Option<String>,
    /// Also fit a compliance per revolute joint whose gravity torque (from
    /// the URDF's inertials) varies over the data: the joint deflects by
    /// c·τ(q); reports c, σ, t, k = −1/c and the largest deflection.
    #[arg(long, requires = "measurements")]
    pub compliance: bool,
    /// With --holdout: fit with and without compliances on the same splits
    /// and compare held-out errors.
    #[arg(long, requires = "holdout")]
    pub compare_compliance: bool,
    /// Take the links' masses and centres of mass from this URDF (same link
    /// names) instead of the robot's own.
    #[arg(long, value_name = "FILE")]
    pub inertia: Option<PathBuf>,
    /// A payload on the tip link: KG, or KG@X,Y,Z (metres, tip link frame).
    #[arg(long, value_name = "KG[@X,Y,Z]", value_parser = super::compliance::parse_payload, allow_hyphen_values = true)]
    pub payload: Option<activecal::io::inertia::Payload>,
    /// Write a report directory: report.md, report.json and figures (PNG
    /// and SVG) of the errors before and after, the held-out splits, the
    /// parameter changes with ±σ and their correlations. An existing
    /// non-empty directory needs --force.
    #[arg(long, value_name = "DIR")]
    pub report: Option<PathBuf>,
    /// Units of the --measurements file.
    #[command(flatten)]
    pub units: super::units::UnitOpts,
    /// Print one JSON object.
    #[arg(long)]
    pub json: bool,
}

/// The simulated measurement noise σ when `--noise` is not given, metres.
pub const DEFAULT_NOISE: f64 = 0.01;

/// The header of a calibrated TOML description.
fn toml_header(id: &Identification, source: &str) -> String {
    format!(
        "# Calibrated by activecal from {source}: nominal = real = the estimate\n# ({:?}, {} iterations, σ̂ = {}).\n",
        id.status,
        id.iterations,
        id.sigma_hat.map_or("-".into(), |v| format!("{v:.6e}"))
    )
}

/// The calibrated frames of a URDF robot at the estimate (`None` for other
/// robots), with σ from the fit's covariance.
fn frames_of(
    robot: &Robot,
    id: &Identification,
    fit: Option<FitBlock>,
) -> Result<Option<(CalibratedFrames, FramesReport)>> {
    let cov = id.covariance.as_ref().map(|c| c.matrix.as_slice());
    Ok(activecal::frames::calibrated(robot, &id.table, cov, fit)?)
}

/// Writes the calibrated robot to every `--out` when identification
/// converged (by extension, [`Format`]); returns the files written. A
/// non-converged estimate is never written as a robot model (see
/// [`refuse_unconverged`]).
fn write_calibrated(
    a: &CalibrateArgs,
    robot: &Robot,
    id: &Identification,
    source: &str,
    frames: Option<&(CalibratedFrames, FramesReport)>,
) -> Result<Vec<String>> {
    if !id.converged() {
        return Ok(Vec::new());
    }
    let mut written = Vec::new();
    for out in &a.out {
        let text = activecal::io::calibrated::render(
            Format::of(out)?,
            robot,
            &id.table,
            frames.map(|(f, r)| (f, r)),
            &toml_header(id, source),
        )
        .map_err(|e| anyhow::anyhow!("--out {}: {e}", out.display()))?;
        write_new(out, &text, a.force)?;
        written.push(out.display().to_string());
    }
    Ok(written)
}

/// The exit status of a calibration whose fit did not converge or is rank
/// deficient (0: converged, 1: an error, 2: a usage error).
pub const EXIT_NOT_CONVERGED: i32 = 3;

/// A calibration that ran but whose fit did not converge: the report is
/// printed, and the process exits with [`EXIT_NOT_CONVERGED`].
#[derive(Debug)]
pub struct NotConverged(pub String);

impl std::fmt::Display for NotConverged {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for NotConverged {}

/// The exit status a calibration ends with: 0 or [`EXIT_NOT_CONVERGED`].
fn exit_status(id: &Identification) -> i32 {
    if id.converged() {
        0
    } else {
        EXIT_NOT_CONVERGED
    }
}

/// After the report is printed: a [`NotConverged`] error (exit status
/// [`EXIT_NOT_CONVERGED`]) with the reason when the estimate did not
/// converge, so that no script mistakes it for a calibrated model; with
/// `--out`, the message says that nothing was written.
fn refuse_unconverged(a: &CalibrateArgs, id: &Identification) -> Result<()> {
    if id.converged() {
        return Ok(());
    }
    let mut why = format!(
        "identification ended {:?} ({:?}) after {} iterations",
        id.status, id.stop, id.iterations
    );
    if !id.unidentifiable.is_empty() {
        why += &format!(
            "; not determined by the data: {}",
            id.unidentifiable.join(", ")
        );
    }
    if !a.out.is_empty() {
        let names: Vec<String> = a.out.iter().map(|p| p.display().to_string()).collect();
        why += &format!(
            "; {} {} not written",
            names.join(", "),
            if names.len() == 1 { "was" } else { "were" }
        );
    }
    Err(NotConverged(why).into())
}

impl CalibrateArgs {
    /// `--seed`, 0 when not given.
    fn seed(&self) -> u64 {
        self.seed.unwrap_or(0)
    }
}

/// Runs `calibrate`.
pub fn cmd_calibrate(a: CalibrateArgs) -> Result<()> {
    if let (Some(seed), Some(_), None) = (a.seed, &a.measurements, a.holdout) {
        bail!(
            "--seed {seed}: with --measurements the seed only draws the --holdout splits, and --holdout is not given (the fit of measured data has no randomness)"
        );
    }
    if !(a.noise.is_finite() && a.noise >= 0.0) {
        bail!(
            "--noise {}: the noise σ must be a finite number >= 0 (metres)",
            a.noise
        );
    }
    if a.design.is_some() && a.validation == 0 {
        bail!(
            "--validation 0: the validation RMS needs at least 1 held-out pose (the RMS error of no poses would read 0)"
        );
    }
    let outputs: Vec<(&str, &std::path::Path)> = a
        .out
        .iter()
        .map(|p| ("--out", p.as_path()))
        .chain(
            a.save_measurements
                .as_deref()
                .map(|p| ("--save-measurements", p)),
        )
        .collect();
    let robot_path = std::path::Path::new(&a.robot.name);
    let inputs: Vec<&std::path::Path> = [
        a.design.as_deref(),
        a.measurements.as_deref(),
        Some(robot_path),
    ]
    .into_iter()
    .flatten()
    .collect();
    super::check_outputs(&outputs, &inputs, a.force)?;
    if let Some(dir) = &a.report {
        super::report_dir::check(dir, a.force)?;
    }
    for out in &a.out {
        Format::of(out).map_err(|e| anyhow::anyhow!("--out {e}"))?;
    }
    let desc = super::load_description(&a.robot)?;
    let robot = &desc.robot;
    match (&a.design, &a.measurements) {
        (_, Some(m)) if super::contact::is_contact_file(m) => {
            let c = super::contact::ContactArgs {
                holdout: a.holdout.is_some(),
                out: !a.out.is_empty(),
                point_distance: &a.point_distance,
                plane: &a.plane,
                setup: &desc.contacts,
                holdout_by: a.holdout_by,
                train_on: a.train_on.as_deref(),
                loss: a.loss,
                loss_scale: a.loss_scale,
                free: &a.free,
                max_iterations: a.max_iterations,
                no_geodesic: a.no_geodesic,
                units: a.units.units(),
                json: a.json,
                report: a.report.as_deref(),
            };
            match super::contact::calibrate_contacts(&c, robot, m)? {
                Some(why) => Err(NotConverged(why).into()),
                None => Ok(()),
            }
        }
        (_, Some(m)) => {
            if !a.point_distance.is_empty()
                || !a.plane.is_empty()
                || a.holdout_by.is_some()
                || a.train_on.is_some()
            {
                bail!(
                    "--point-distance, --plane, --holdout-by and --train-on are for contact files (a CSV with a 'point' or 'plane' column); {} has none",
                    m.display()
                );
            }
            from_measurements(&a, robot, m)
        }
        (Some(d), None) => from_design(&a, robot, desc.visibility.as_ref(), d),
        (None, None) => bail!("give --design (simulate) or --measurements (real data)"),
    }
}

/// Identification from a measurement file.
fn from_measurements(a: &CalibrateArgs, robot: &Robot, path: &Path) -> Result<()> {
    let t0 = Instant::now();
    let lm = LmSettings::default()
        .with_max_iterations(a.max_iterations)
        .with_geodesic(!a.no_geodesic);
    let o = super::measured::MeasuredOptions {
        lm,
        loss: super::measured::loss_choice(a.loss, a.loss_scale)?,
        fix: &a.fix,
        free: &a.free,
        holdout: a
            .holdout
            .map(|fraction| activecal::identify::HoldoutSettings {
                fraction,
                splits: a.splits,
                seed: a.seed(),
                prune: a.compare_pruned,
            }),
        json: a.json,
        units: a.units.units(),
        gravity: if a.compliance || a.compare_compliance {
            Some(super::compliance::gravity_for(
                robot,
                a.inertia.as_deref(),
                a.payload,
            )?)
        } else {
            if a.inertia.is_some() || a.payload.is_some() {
                bail!("--inertia and --payload are for --compliance or --compare-compliance");
            }
            None
        },
        fit_compliance: a.compliance,
        compare_compliance: a.compare_compliance,
    };
    let (fitted, f, mut report) =
        super::measured::calibrate_measured(robot, path, &o, &|| t0.elapsed().as_secs_f64())?;
    let id = &f.id;
    let fit = FitBlock {
        poses: report.base.poses,
        position_rms_mm: report.residuals.position_rms_mm,
        orientation_rms_deg: report.residuals.orientation_rms_deg,
    };
    let frames = frames_of(&fitted, id, Some(fit))?;
    report.frames = frames.as_ref().map(|(_, r)| r.clone());
    report.base.out =
        write_calibrated(a, &fitted, id, &path.display().to_string(), frames.as_ref())?;
    let mut v = serde_json::to_value(&report)?;
    v["exit_status"] = exit_status(id).into();
    if let Some(dir) = &a.report {
        super::report_dir::calibration(dir, &measured_summary(&fitted, id, path, &report, &v))?;
    }
    super::emit(a.json, &v, || {
        let mut s = super::measured::measured_text(&report, id, &status_text(id));
        for out in &report.base.out {
            s += &format!("\ncalibrated robot written to {out}\n");
        }
        s
    });
    refuse_unconverged(a, id)
}

/// What `--report` shows of a calibration from measurements.
fn measured_summary<'a>(
    robot: &'a Robot,
    id: &'a Identification,
    path: &Path,
    r: &super::measured::MeasuredReport,
    json: &serde_json::Value,
) -> super::report_dir::CalibrationSummary<'a> {
    let pos = |e: &activecal::identify::ModelErrors| -> Vec<f64> {
        e.per_sample
            .iter()
            .flat_map(|s| s.position_mm.iter().copied())
            .collect()
    };
    let ori = |e: &activecal::identify::ModelErrors| -> Option<Vec<f64>> {
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
    super::report_dir::CalibrationSummary {
        robot,
        id,
        source: format!("measurements `{}`, {} poses", path.display(), r.base.poses),
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
    }
}

fn status_text(id: &Identification) -> String {
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

/// Simulated calibration at a design's poses.
///
/// The measurements are simulated at the design's stored joint values (after
/// the existing poses a design chosen with `select --existing` stores); the
/// held-out validation poses come from the design's own pool (the same pool,
/// filters included, that `select` chose it from), outside the design.
fn from_design(
    a: &CalibrateArgs,
    robot: &Robot,
    described: Option<&activecal::measure::Visibility>,
    design_path: &Path,
) -> Result<()> {
    let t0 = Instant::now();
    let in_file = |e: activecal::Error| anyhow::anyhow!("{}: {e}", design_path.display());
    let design = DesignFile::read(design_path)?;
    design.check_robot(robot).map_err(in_file)?;
    let mut spec = design.spec().map_err(in_file)?;
    if design.pool.is_none() {
        // An old file names only its lattice: the pool `select` used had the
        // robot description's visibility region.
        spec.filters = super::filters(None, described)?;
    }
    let lm = LmSettings::default()
        .with_max_iterations(a.max_iterations)
        .with_geodesic(!a.no_geodesic);
    let settings = MonteCarloSettings::default()
        .with_trials(a.trials)
        .with_sigma(a.noise)
        .with_seed(a.seed())
        .with_validation_poses(a.validation);
    let settings = MonteCarloSettings { lm, ..settings };
    let name = design_path
        .file_stem()
        .map_or("design".into(), |s| s.to_string_lossy().into_owned());
    let sim =
        activecal::experiment::simulated::calibrate_design(robot, &design, &spec, &name, &settings)
            .map_err(|e| anyhow::anyhow!("{}: {e}", design_path.display()))?;
    let (pool, qs, tables, validation) = (&sim.pool, &sim.qs, &sim.tables, &sim.validation);
    let (before, after) = (sim.rms_before, sim.rms_after);
    let (rot_before, rot_after) = (sim.orientation_rms_before, sim.orientation_rms_after);
    let (mc, mc_seconds) = (sim.monte_carlo.clone(), sim.monte_carlo_seconds);
    let id = &tables.identification;
    if let Some(path) = &a.save_measurements {
        let text = serde_json::to_string_pretty(&tables.measurements)? + "\n";
        write_new(path, &text, a.force)?;
    }
    let source = format!("simulated measurements at {}", design_path.display());
    let frames = frames_of(robot, id, None)?;
    write_calibrated(a, robot, id, &source, frames.as_ref())?;
    let truth = robot.unknown_values(&robot.real);
    let residual: Vec<f64> = truth.iter().zip(&id.estimate).map(|(t, e)| t - e).collect();
    let full = activecal::measure::sensor_for(robot).observes_orientation();

    let report = SimulatedCalibrationReport {
        identification: IdentificationReport::from(id),
        robot: robot.name.clone(),
        chain: activecal::report::chain(robot),
        design: design_path.display().to_string(),
        pool: pool.spec.clone(),
        pool_size: pool.len(),
        poses: qs.len(),
        measurement: robot.measurement,
        noise: a.noise,
        orientation_noise: full.then(|| a.noise / robot.orientation_scale),
        seed: a.seed(),
        residual: id
            .names
            .iter()
            .cloned()
            .zip(residual.iter().copied())
            .collect(),
        validation_poses: validation.len(),
        validation_rms_before: before,
        validation_rms_after: after,
        validation_orientation_rms_before: rot_before,
        validation_orientation_rms_after: rot_after,
        monte_carlo_seconds: mc.as_ref().map(|_| mc_seconds),
        monte_carlo: mc.clone(),
        frames: frames.map(|(_, r)| r),
        elapsed_seconds: t0.elapsed().as_secs_f64(),
    };
    let mut v = serde_json::to_value(&report)?;
    v["exit_status"] = exit_status(id).into();
    if let Some(dir) = &a.report {
        simulated_report_dir(a, robot, design_path, &sim, dir, &v)?;
    }
    emit(a.json, &v, || {
        simulated_text(a, robot, design_path, &sim, &report)
    });
    refuse_unconverged(a, id)
}

/// `--report DIR` of a simulated calibration: the errors at the held-out
/// poses before and after, the parameter changes, notes on the simulation.
fn simulated_report_dir(
    a: &CalibrateArgs,
    robot: &Robot,
    design_path: &Path,
    sim: &activecal::experiment::simulated::SimulatedCalibration,
    dir: &Path,
    v: &serde_json::Value,
) -> Result<()> {
    let (qs, tables, validation) = (&sim.qs, &sim.tables, &sim.validation);
    let id = &tables.identification;
    let full = activecal::measure::sensor_for(robot).observes_orientation();
    let mc = &sim.monte_carlo;
    let to_mm = |v: Vec<f64>| v.into_iter().map(|x| x * 1e3).collect::<Vec<_>>();
    let to_deg = |v: Vec<f64>| v.into_iter().map(f64::to_degrees).collect::<Vec<_>>();
    let nominal = robot.unknown_values(&robot.nominal);
    let std = id.covariance.as_ref().map(|c| c.std.clone());
    let mut notes = vec![format!(
        "Simulated measurements at the design's {} poses with noise σ = {} mm per coordinate{} (seed {}); errors at {} held-out poses of the design's pool.",
        qs.len(),
        a.noise * 1e3,
        if a.noise == 0.01 {
            " (the default of --noise)"
        } else {
            ""
        },
        a.seed(),
        validation.len()
    )];
    if let Some(mc) = &mc {
        notes.push(format!(
            "Monte-Carlo over {} trials: validation RMS after calibration median {} mm, predicted {} mm.",
            mc.trials,
            mc.validation_rms_after.as_ref().map_or("-".into(), |v| format!("{:.4}", v.median * 1e3)),
            mc.validation_rms_predicted.map_or("-".into(), |p| format!("{:.4}", p * 1e3))
        ));
    }
    let s = super::report_dir::CalibrationSummary {
        robot,
        id,
        source: format!("simulated, design `{}`", design_path.display()),
        what: "held-out pose",
        position_mm: (
            to_mm(validation.position_errors(robot, &robot.nominal)),
            to_mm(validation.position_errors(robot, &id.table)),
        ),
        orientation_deg: full.then(|| {
            (
                to_deg(validation.orientation_errors(robot, &robot.nominal)),
                to_deg(validation.orientation_errors(robot, &id.table)),
            )
        }),
        params: id
            .names
            .iter()
            .enumerate()
            .map(|(k, n)| {
                (
                    n.clone(),
                    id.estimate[k] - nominal[k],
                    std.as_ref().map(|s| s[k]),
                )
            })
            .collect(),
        splits: None,
        notes,
        json: v.clone(),
    };
    super::report_dir::calibration(dir, &s)?;
    Ok(())
}

/// The text report of a simulated calibration.
fn simulated_text(
    a: &CalibrateArgs,
    robot: &Robot,
    design_path: &Path,
    sim: &activecal::experiment::simulated::SimulatedCalibration,
    report: &SimulatedCalibrationReport,
) -> String {
    let (qs, tables, validation) = (&sim.qs, &sim.tables, &sim.validation);
    let id = &tables.identification;
    let full = activecal::measure::sensor_for(robot).observes_orientation();
    let (before, after) = (sim.rms_before, sim.rms_after);
    let (rot_before, rot_after) = (sim.orientation_rms_before, sim.orientation_rms_after);
    let (mc, mc_seconds) = (&sim.monte_carlo, sim.monte_carlo_seconds);
    let noise = if full {
        format!(
            "σ = {} m and {:.3e} rad (full poses)",
            a.noise,
            a.noise / robot.orientation_scale
        )
    } else {
        format!("σ = {} m", a.noise)
    };
    let noise = if a.noise == DEFAULT_NOISE {
        format!("{noise}, the default of --noise")
    } else {
        noise
    };
    let mut s = format!(
        "{}: {} poses, {noise}, seed {}\n{}",
        design_path.display(),
        qs.len(),
        a.seed(),
        status_text(id)
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
        "\nvalidation ({} held-out poses): RMS position error {before:.6} m before, {after:.6} m after\n",
        validation.len()
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

/// Human-readable Monte-Carlo summary.
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

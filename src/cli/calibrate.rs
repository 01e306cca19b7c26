//! `calibrate`: the choice between simulated (`--design`, rendered in
//! `simulated.rs`), measured (`--measurements` or a ROS 2 bag's `--bag`,
//! here; the bag's pipeline is the library's `experiment::bag`), contact
//! (`contact.rs`) and camera (`--observations`, `camera.rs`) calibration. Its arguments are in `calibrate_args.rs`,
//! what the three share on the way out (the calibrated robot, exit
//! statuses) in `calibrated.rs`.

pub use super::calibrate_args::{CalibrateArgs, DEFAULT_NOISE};
pub use super::calibrated::{EXIT_NOT_CONVERGED, NotConverged};
use super::calibrated::{not_written, write_calibrated};
use activecal::model::Robot;
use activecal::options::LmSettings;
use activecal::render::measured_text::{full_model_gain_text, measured_text, status_text};
use activecal::write::calibrated::Format;
use anyhow::{Context, Result, bail};
use std::path::Path;
use std::time::Instant;

/// Runs `calibrate`.
pub fn cmd_calibrate(a: CalibrateArgs) -> Result<()> {
    if let (Some(seed), true, None) = (
        a.seed,
        a.measurements.is_some() || a.bag.is_some(),
        a.holdout,
    ) {
        bail!(
            "--seed {seed}: with --measurements the seed only draws the --holdout splits, and --holdout is not given (the fit of measured data has no randomness)"
        );
    }
    if !(a.noise().is_finite() && a.noise() >= 0.0) {
        bail!(
            "--noise {}: the noise σ must be a finite number >= 0 (metres)",
            a.noise()
        );
    }
    a.check_stated_noises()?;
    if a.design.is_some() && a.validation == 0 {
        bail!(
            "--validation 0: the validation RMS needs at least 1 held-out pose (the RMS error of no poses would read 0)"
        );
    }
    super::run_files::check(&calibrate_files(&a), a.force)?;
    for out in &a.out {
        Format::of(out).map_err(|e| anyhow::anyhow!("--out {e}"))?;
    }
    let desc = super::load_description(&a.robot)?;
    let robot = &desc.robot;
    if a.observations.is_some() || a.images.is_some() {
        return match super::camera::calibrate_camera(&a, robot)? {
            Some(why) => Err(NotConverged(why).into()),
            None => Ok(()),
        };
    }
    match (&a.design, &a.measurements) {
        (_, Some(m)) if super::contact::is_contact_file(m) => {
            match super::contact::calibrate_contacts(&a, robot, &desc.contacts, m)? {
                Some(why) => Err(NotConverged(why).into()),
                None => Ok(()),
            }
        }
        (_, Some(m)) => from_measurements(&a, robot, m),
        (_, None) if a.bag.is_some() => from_bag(&a, robot),
        (Some(d), None) => super::simulated::from_design(&a, robot, desc.visibility.as_ref(), d),
        (None, None) => {
            bail!("give --design (simulate), --measurements or --bag (real data)")
        }
    }
}

/// Every file of a `calibrate` run: the robot's (description, frames
/// file), `--design`, `--measurements`, `--observations`, `--images` (each
/// image), `--joints`, `--camera-info`,
/// `--target`, `--inertia`; the `--out` files, `--save-measurements`,
/// `--save-observations`,
/// `--out-camera-info` and the `--report` directory. Checked once, before
/// any work ([`super::run_files::RunFiles::check`]).
fn calibrate_files(a: &CalibrateArgs) -> super::run_files::RunFiles {
    let mut f = super::run_files::RunFiles::new();
    super::run_files::robot(&mut f, &a.robot)
        .input("--design", a.design.as_deref())
        .input("--measurements", a.measurements.as_deref())
        .input("--bag", a.bag.as_deref())
        .input("--bag-design", a.bag_design.as_deref())
        .input("--observations", a.observations.as_deref())
        .inputs("--images", &image_inputs(a))
        .input("--joints", a.joints.as_deref())
        .input(
            "--camera-info",
            a.camera_info.as_deref().filter(|_| a.bag.is_none()),
        )
        .input("--target", a.target.as_deref())
        .input("--inertia", a.inertia.as_deref())
        .outputs("--out", &a.out)
        .output("--save-measurements", a.save_measurements.as_deref())
        .output("--out-camera-info", a.out_camera_info.as_deref())
        .output("--save-observations", a.save_observations.as_deref())
        .dir("--report", a.report.as_deref());
    f
}

/// The image files `--images` names (none when it names none: the
/// reader says why; none with `--bag`, where it is a topic).
fn image_inputs(a: &CalibrateArgs) -> Vec<std::path::PathBuf> {
    a.images
        .as_deref()
        .filter(|_| a.bag.is_none())
        .and_then(|s| activecal::io::images::files::image_files(s).ok())
        .unwrap_or_default()
}

/// `robot` with `--orientation-scale` applied.
fn scaled_robot(a: &CalibrateArgs, robot: &Robot) -> Result<Robot> {
    let mut scaled = robot.clone();
    match a.orientation_scale {
        Some(w) if !(w.is_finite() && w > 0.0) => {
            bail!("--orientation-scale {w}: must be a finite number > 0 (metres per radian)")
        }
        Some(w) => scaled.orientation_scale = w,
        None => {}
    }
    Ok(scaled)
}

/// Identification from a measurement file.
fn from_measurements(a: &CalibrateArgs, robot: &Robot, path: &Path) -> Result<()> {
    let t0 = Instant::now();
    let robot = &scaled_robot(a, robot)?;
    let o = measured_settings(a, robot)?;
    let mut print_note = |n: &str| {
        if !a.json {
            super::diag(&format!("note: {n}"));
        }
    };
    let (meas, read_notes) =
        activecal::experiment::measured::read_measurement_file(path, robot, o.units)?;
    // Points and full poses told apart: the options of the other refused.
    let sensor = if meas.orientations().is_empty() {
        super::acts_on::Sensor::Points
    } else {
        super::acts_on::Sensor::Poses
    };
    super::acts_on::check(super::acts_on::CALIBRATE, &a.given, &[sensor])?;
    let c = activecal::experiment::measured::calibrate_read(
        robot,
        &meas,
        &path.display().to_string(),
        read_notes,
        &o,
        &mut print_note,
    )?;
    let source = Source {
        name: path.display().to_string(),
        described: format!("measurements `{}`", path.display()),
    };
    render_measured(a, &meas, c, &source, t0)
}

/// The joint topic when `--joints` is not given.
const DEFAULT_JOINTS: &str = "/joint_states";

/// Calibrates `robot` from `--bag`.
fn from_bag(a: &CalibrateArgs, robot: &Robot) -> Result<()> {
    let t0 = Instant::now();
    let bag = a.bag.as_deref().context("--bag: not given")?;
    let robot = &scaled_robot(a, robot)?;
    let o = measured_settings(a, robot)?;
    let joints = a
        .joints
        .as_deref()
        .map_or(DEFAULT_JOINTS.into(), |j| j.to_string_lossy());
    let mut x = a.from_bag.settings(&joints, a.design_tolerance)?;
    if let Some(d) = &a.bag_design {
        x.design = Some(activecal::io::bag::design::read_design(d, robot)?);
    }
    let mut print_note = |n: &str| {
        if !a.json {
            super::diag(&format!("note: {n}"));
        }
    };
    let got = activecal::experiment::bag::calibrate_bag(bag, robot, &x, &o, &mut print_note)?;
    let source = Source {
        name: bag.display().to_string(),
        described: format!("ROS 2 bag `{}`", bag.display()),
    };
    render_measured(a, &got.measurements, got.calibration, &source, t0)
}

/// Where the measurements of a fit came from, as the output shows it.
struct Source {
    /// Its name in the calibrated files' header (a path).
    name: String,
    /// In the report folder's summary.
    described: String,
}

/// The settings of a fit of measured data from the options.
fn measured_settings(
    a: &CalibrateArgs,
    robot: &Robot,
) -> Result<activecal::experiment::measured::MeasuredSettings> {
    let lm = LmSettings::builder()
        .max_iterations(a.max_iterations)
        .geodesic(!a.no_geodesic)
        .build()?;
    let o = activecal::experiment::measured::MeasuredSettings {
        lm,
        loss: activecal::options::LossChoice::of(a.loss, a.loss_scale)?,
        fix: a.fix.clone(),
        restriction: a.restriction(),
        free: a.free.clone(),
        holdout: a
            .holdout
            .map(|fraction| {
                activecal::options::HoldoutSettings::builder()
                    .fraction(fraction)
                    .splits(a.splits)
                    .seed(a.seed())
                    .prune(a.compare_pruned)
                    .weights(weights_of(a))
                    .build()
            })
            .transpose()?,
        weights: weights_of(a),
        outliers: a.outlier_choice()?,
        stated_noise: a.noise,
        stated_orientation_noise: a.orientation_noise,
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
    o.validate()?;
    Ok(o)
}

/// Writes and prints a fit of measured data (`c`, of `meas` from `source`),
/// with `t0` its start: the calibrated robot when the
/// library's verdict allows, the report folder, the text or JSON, and the
/// exit status.
fn render_measured(
    a: &CalibrateArgs,
    meas: &activecal::data::Measurements,
    c: activecal::experiment::measured::MeasuredCalibration,
    source: &Source,
    t0: Instant,
) -> Result<()> {
    let activecal::experiment::measured::MeasuredCalibration {
        robot: fitted,
        fit: f,
        frames,
        mut report,
        verdict,
    } = c;
    report.base.elapsed_seconds = t0.elapsed().as_secs_f64();
    for w in &report.warnings {
        super::diag(&format!("warning: {w}"));
    }
    let id = &f.id;
    // The library's verdict: a fit that did not converge, or converged to
    // another robot, is not written.
    if verdict.refusal().is_none() {
        report.base.out = write_calibrated(a, &fitted, id, &source.name, frames.as_ref())?;
    }
    let v = serde_json::to_value(&report)?;
    if let Some(dir) = &a.report {
        let described = format!("{}, {} poses", source.described, report.base.poses);
        let s = activecal::experiment::measured::summary::measured(
            &fitted, id, described, &report, &v, meas,
        );
        activecal::render::folder::calibration(dir, &s)?;
    }
    super::emit(a.json, &v, || {
        let mut s = report
            .bag
            .as_ref()
            .map_or(String::new(), activecal::render::bag_text::bag_section_text);
        s += &measured_text(&report, id, &status_text(id));
        if let Some(g) = &report.full_model_gain {
            let held_out = report.holdout.as_ref().map(|h| h.position_rms_mm.mean);
            s += &full_model_gain_text(g, held_out);
        }
        for out in &report.base.out {
            s += &format!("\ncalibrated robot written to {out}\n");
        }
        s
    })?;
    match verdict.refusal() {
        Some(why) => Err(NotConverged(why.to_string() + &not_written(a)).into()),
        None => Ok(()),
    }
}

/// The weights of `--weights` (fixed whenever `--orientation-scale` is given).
fn weights_of(a: &CalibrateArgs) -> activecal::options::Weights {
    use super::calibrate_args::WeightsKind;
    match (a.weights, a.orientation_scale) {
        (WeightsKind::Fixed, _) | (_, Some(_)) => activecal::options::Weights::Fixed,
        (WeightsKind::Estimated, None) => activecal::options::Weights::Estimated,
    }
}

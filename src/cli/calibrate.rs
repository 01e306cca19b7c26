//! `calibrate`: the choice between simulated (`--design`, rendered in
//! `simulated.rs`), measured (`--measurements`, here), contact
//! (`contact.rs`) and camera (`--observations`, `camera.rs`) calibration. Its arguments are in `calibrate_args.rs`,
//! what the three share on the way out (the calibrated robot, exit
//! statuses) in `calibrated.rs`.

pub use super::calibrate_args::{CalibrateArgs, DEFAULT_NOISE};
pub use super::calibrated::{EXIT_NOT_CONVERGED, NotConverged};
use super::calibrated::{
    exit_status, frames_of, not_written, refuse_unconverged, status_text, write_calibrated,
};
use activecal::frames::report::FitBlock;
use activecal::identify::{Identification, LmSettings};
use activecal::io::calibrated::Format;
use activecal::model::Robot;
use anyhow::{Result, bail};
use std::path::Path;
use std::time::Instant;

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
        a.observations.as_deref(),
        a.camera_info.as_deref(),
        a.target.as_deref(),
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
    if let Some(obs) = &a.observations {
        return match super::camera::calibrate_camera(&a, robot, obs)? {
            Some(why) => Err(NotConverged(why).into()),
            None => Ok(()),
        };
    }
    match (&a.design, &a.measurements) {
        (_, Some(m)) if super::contact::is_contact_file(m) => {
            let c = super::contact::ContactArgs {
                holdout: a.holdout.is_some(),
                out: &a.out,
                force: a.force,
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
        (_, Some(m)) => from_measurements(&a, robot, m),
        (Some(d), None) => super::simulated::from_design(&a, robot, desc.visibility.as_ref(), d),
        (None, None) => bail!("give --design (simulate) or --measurements (real data)"),
    }
}

/// Identification from a measurement file.
fn from_measurements(a: &CalibrateArgs, robot: &Robot, path: &Path) -> Result<()> {
    let t0 = Instant::now();
    let mut scaled;
    let robot = match a.orientation_scale {
        Some(w) if !(w.is_finite() && w > 0.0) => {
            bail!("--orientation-scale {w}: must be a finite number > 0 (metres per radian)")
        }
        Some(w) => {
            scaled = robot.clone();
            scaled.orientation_scale = w;
            &scaled
        }
        None => robot,
    };
    let lm = LmSettings::builder()
        .max_iterations(a.max_iterations)
        .geodesic(!a.no_geodesic)
        .build()?;
    let o = activecal::experiment::measured::MeasuredSettings {
        lm,
        loss: super::measured::loss_choice(a.loss, a.loss_scale)?,
        fix: a.fix.clone(),
        free: a.free.clone(),
        holdout: a
            .holdout
            .map(|fraction| {
                activecal::identify::HoldoutSettings::builder()
                    .fraction(fraction)
                    .splits(a.splits)
                    .seed(a.seed())
                    .prune(a.compare_pruned)
                    .weights(weights_of(a))
                    .build()
            })
            .transpose()?,
        weights: weights_of(a),
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
    let activecal::experiment::measured::MeasuredCalibration {
        robot: fitted,
        fit: f,
        mut report,
    } = activecal::experiment::measured::calibrate_read(
        robot,
        &meas,
        &path.display().to_string(),
        read_notes,
        &o,
        &mut print_note,
    )?;
    report.base.elapsed_seconds = t0.elapsed().as_secs_f64();
    let id = &f.id;
    let fit = FitBlock {
        poses: report.base.poses,
        position_rms_mm: report.residuals.position_rms_mm,
        orientation_rms_deg: report.residuals.orientation_rms_deg,
    };
    let frames = frames_of(&fitted, id, Some(fit))?;
    report.frames = frames.as_ref().map(|(_, r)| r.clone());
    // A converged fit that made another robot of this one is not written.
    let implausible = id
        .converged()
        .then(|| {
            let f = frames.as_ref().map(|(f, _)| f);
            activecal::frames::plausible::implausible(&fitted, &id.table, f)
        })
        .flatten();
    if implausible.is_none() {
        report.base.out =
            write_calibrated(a, &fitted, id, &path.display().to_string(), frames.as_ref())?;
    }
    let mut v = serde_json::to_value(&report)?;
    v["exit_status"] = if implausible.is_some() {
        EXIT_NOT_CONVERGED
    } else {
        exit_status(id)
    }
    .into();
    if let Some(dir) = &a.report {
        super::report_dir::calibration(dir, &measured_summary(&fitted, id, path, &report, &v))?;
    }
    super::emit(a.json, &v, || {
        let mut s = super::measured::measured_text(&report, id, &status_text(id));
        for out in &report.base.out {
            s += &format!("\ncalibrated robot written to {out}\n");
        }
        s
    })?;
    // Too few poses for the unknowns: the cause, ahead of what it led to.
    let few = too_few_rows(&fitted, &report);
    let cause = |why: String| match &few {
        Some(f) => format!("{f}\n  {why}"),
        None => why,
    };
    if let Some(why) = implausible {
        return Err(NotConverged(cause(why) + &not_written(a)).into());
    }
    refuse_unconverged(a, id).map_err(|e| match e.downcast::<NotConverged>() {
        Ok(NotConverged(why)) => NotConverged(cause(why)).into(),
        Err(e) => e,
    })
}

/// `N poses give R measurement rows for U unknowns: too few …` when the
/// data have fewer rows than the fit had unknowns (estimated and fixed).
fn too_few_rows(
    fitted: &Robot,
    r: &activecal::experiment::measured::MeasuredReport,
) -> Option<String> {
    let per_pose = fitted.rows_per_pose().max(1);
    let rows = r.base.poses * per_pose;
    let unknowns = r.parameters.len() + r.fixed.len();
    (rows < unknowns).then(|| {
        format!(
            "{} poses give {rows} measurement rows for {unknowns} unknowns: too few to determine the model (at least {} poses)",
            r.base.poses,
            unknowns.div_ceil(per_pose)
        )
    })
}

/// What `--report` shows of a calibration from measurements.
fn measured_summary<'a>(
    robot: &'a Robot,
    id: &'a Identification,
    path: &Path,
    r: &activecal::experiment::measured::MeasuredReport,
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

/// The weights of `--weights` (fixed whenever `--orientation-scale` is given).
fn weights_of(a: &CalibrateArgs) -> activecal::identify::Weights {
    use super::calibrate_args::WeightsKind;
    match (a.weights, a.orientation_scale) {
        (WeightsKind::Fixed, _) | (_, Some(_)) => activecal::identify::Weights::Fixed,
        (WeightsKind::Estimated, None) => activecal::identify::Weights::Estimated,
    }
}

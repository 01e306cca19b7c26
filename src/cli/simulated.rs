//! `calibrate --design`: measurements simulated at a design's poses,
//! identified from the nominal parameters, validated on held-out poses of
//! the design's pool, optionally repeated over noise realisations
//! (Monte-Carlo); the work is in `activecal::experiment::simulated`, this
//! file renders it (text, JSON, report directory).

use super::calibrate_args::CalibrateArgs;
use super::calibrated::{exit_status, frames_of, refuse_unconverged, write_calibrated};
use super::{emit, write_new};
use activecal::identify::{LmSettings, MonteCarloSettings, MonteCarloSummary};
use activecal::io::design::DesignFile;
use activecal::model::Robot;
use activecal::report::SimulatedCalibrationReport;
use anyhow::Result;
use std::path::Path;
use std::time::Instant;

/// Simulated calibration at a design's poses.
///
/// The measurements are simulated at the design's stored joint values (after
/// the existing poses a design chosen with `select --existing` stores); the
/// held-out validation poses come from the design's own pool (the same pool,
/// filters included, that `select` chose it from), outside the design.
pub fn from_design(
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
    let lm = LmSettings::builder()
        .max_iterations(a.max_iterations)
        .geodesic(!a.no_geodesic)
        .build()?;
    let settings = MonteCarloSettings::builder()
        .trials(a.trials)
        .sigma(a.noise())
        .seed(a.seed())
        .validation_poses(a.validation)
        .lm(lm)
        .build()?;
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
        // A .csv as a tracker's export (what `--measurements` reads back);
        // anything else JSON.
        let csv = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("csv"));
        let text = if csv {
            activecal::io::measurements::to_csv(&tables.measurements, robot)
        } else {
            serde_json::to_string_pretty(&tables.measurements)? + "\n"
        };
        write_new(path, &text, a.force)?;
    }
    let source = format!("simulated measurements at {}", design_path.display());
    let frames = frames_of(robot, id, None)?;
    write_calibrated(a, robot, id, &source, frames.as_ref())?;
    let truth = robot.unknown_values(&robot.real);
    let residual: Vec<f64> = truth.iter().zip(&id.estimate).map(|(t, e)| t - e).collect();
    let full = activecal::measure::sensor_for(robot).observes_orientation();

    let report = SimulatedCalibrationReport {
        identification: id.clone(),
        robot: robot.name.clone(),
        chain: activecal::report::chain(robot),
        design: design_path.display().to_string(),
        pool: pool.spec.clone(),
        pool_size: pool.len(),
        poses: qs.len(),
        measurement: robot.measurement,
        noise: a.noise(),
        orientation_noise: full.then(|| a.noise() / robot.orientation_scale),
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
    })?;
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
        a.noise() * 1e3,
        if a.noise.is_none() {
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
    let s = activecal::render::folder::CalibrationSummary {
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
        poses: Some(activecal::render::pages::FitPoses {
            qs: qs.clone(),
            measured: None,
            flagged: Vec::new(),
        }),
    };
    activecal::render::folder::calibration(dir, &s)?;
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
            a.noise(),
            a.noise() / robot.orientation_scale
        )
    } else {
        format!("σ = {} m", a.noise())
    };
    let noise = if a.noise.is_none() {
        format!("{noise}, the default of --noise")
    } else {
        noise
    };
    let mut s = format!(
        "{}: {} poses, {noise}, seed {}\n{}",
        design_path.display(),
        qs.len(),
        a.seed(),
        activecal::render::measured_text::status_text(id)
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
        s += &activecal::render::frames_text::frames_text(f);
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

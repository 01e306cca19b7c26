//! `calibrate --design`: measurements simulated at a design's poses,
//! identified from the nominal parameters, validated on held-out poses of
//! the design's pool, optionally repeated over noise realisations
//! (Monte-Carlo); the work is in `activecal::experiment::simulated`, this
//! file renders it (text, JSON, report directory).

use super::calibrate_args::CalibrateArgs;
use super::calibrated::{refuse_unconverged, write_calibrated};
use super::{emit, write_new};
use activecal::io::design::DesignFile;
use activecal::model::Robot;
use activecal::options::{LmSettings, MonteCarloSettings};
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
    described: Option<&activecal::options::Visibility>,
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
    let tables = &sim.tables;
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
    write_calibrated(a, robot, id, &source, sim.frames.as_ref())?;
    let noise_note = if a.noise.is_none() {
        ", the default of --noise"
    } else {
        ""
    };
    let report = sim.report(
        robot,
        &design_path.display().to_string(),
        a.noise(),
        a.seed(),
        t0.elapsed().as_secs_f64(),
    );
    let v = serde_json::to_value(&report)?;
    if let Some(dir) = &a.report {
        let s = activecal::experiment::simulated::summary(
            robot,
            &sim,
            &design_path.display().to_string(),
            (a.noise(), noise_note),
            a.seed(),
            &v,
        );
        activecal::render::folder::calibration(dir, &s)?;
    }
    emit(a.json, &v, || {
        activecal::render::simulated_text::text(&report, &sim.tables, noise_note)
    })?;
    refuse_unconverged(a, id)
}

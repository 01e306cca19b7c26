//! `--report DIR` of `calibrate` and `select`: a directory with report.md,
//! report.json and the figures (PNG and SVG, [`super::report_plots`]). The
//! directory is checked before any work with the command's files
//! ([`super::run_files`]: an existing non-empty one needs `--force`), built
//! aside and swapped in whole.

use super::plots::{self as plots, CurveRow, JointRow, ParamBar};
pub use super::summary::CalibrationSummary;
use super::summary::is_angle;
use crate::error::Result;
use crate::how_many::PoseCountCurve;
use crate::identify::Identification;
use crate::io::atomic::{StagedDir, write_atomic};
use crate::model::{JointKind, Robot};
use crate::report::SelectReport;
use std::fmt::Write as _;
use std::path::Path;

/// report.json's text: `v` pretty-printed.
fn json_text<T: serde::Serialize + ?Sized>(v: &T) -> Result<String> {
    serde_json::to_string_pretty(v).map_err(json_error)
}

/// A report that does not serialise (a non-finite map key, say).
fn json_error(e: serde_json::Error) -> crate::Error {
    crate::Error::Invalid(format!("report.json: {e}"))
}

/// Writes `text` into the staged directory as `name`.
fn put(staged: &StagedDir, name: &str, text: &str) -> Result<()> {
    write_atomic(&staged.path().join(name), text.as_bytes())?;
    Ok(())
}

/// Parameter changes and σ (SI units) as bars: lengths in mm, angles in
/// degrees.
fn bars(rows: &[(String, f64, Option<f64>)]) -> (Vec<ParamBar>, Vec<ParamBar>) {
    let (mut lengths, mut angles) = (Vec::new(), Vec::new());
    for (name, change, sigma) in rows {
        let (to, into) = if is_angle(name) {
            (180.0 / std::f64::consts::PI, &mut angles)
        } else {
            (1e3, &mut lengths)
        };
        into.push(ParamBar {
            name: name.clone(),
            change: change * to,
            sigma: sigma.map(|s| s * to),
        });
    }
    (lengths, angles)
}

/// The figures every calibration report has: errors sorted and their
/// histograms, parameter changes, correlations. Returns the figure list of
/// report.md (file stem, caption).
fn calibration_figures(
    out: &Path,
    what: &str,
    pos: (&[f64], &[f64]),
    ori: Option<(&[f64], &[f64])>,
    params: &[(String, f64, Option<f64>)],
    id: &Identification,
) -> Result<Vec<(String, String)>> {
    let mut figs = Vec::new();
    plots::sorted_errors(
        &out.join("position_errors_sorted"),
        &format!("Position error per {what}, sorted"),
        "mm",
        pos.0,
        pos.1,
    )?;
    figs.push((
        "position_errors_sorted".into(),
        format!(
            "position error at each {what} (mm), nominal and calibrated, each sorted increasing"
        ),
    ));
    plots::histograms(
        &out.join("position_errors_histogram"),
        &format!("Position error per {what}: histogram"),
        "mm",
        pos.0,
        pos.1,
    )?;
    figs.push((
        "position_errors_histogram".into(),
        "histogram of the position errors (mm)".into(),
    ));
    if let Some((b, a)) = ori {
        plots::sorted_errors(
            &out.join("orientation_errors_sorted"),
            &format!("Orientation error per {what}, sorted"),
            "degrees",
            b,
            a,
        )?;
        figs.push((
            "orientation_errors_sorted".into(),
            format!("orientation error angle at each {what} (degrees), sorted"),
        ));
        plots::histograms(
            &out.join("orientation_errors_histogram"),
            &format!("Orientation error per {what}: histogram"),
            "degrees",
            b,
            a,
        )?;
        figs.push((
            "orientation_errors_histogram".into(),
            "histogram of the orientation errors (degrees)".into(),
        ));
    }
    let (lengths, angles) = bars(params);
    plots::parameter_changes(&out.join("parameter_changes"), &lengths, &angles)?;
    figs.push((
        "parameter_changes".into(),
        "each parameter's change from nominal with ±σ (lengths in mm, angles in degrees)".into(),
    ));
    if let Some(c) = &id.covariance {
        plots::correlation(
            &out.join("correlation"),
            &c.correlation.names,
            &c.correlation.matrix,
        )?;
        figs.push((
            "correlation".into(),
            "correlation of the parameter estimates (−1 blue, +1 red)".into(),
        ));
    }
    Ok(figs)
}

/// The report.md figure section.
fn figure_section(figs: &[(String, String)]) -> String {
    let mut s = String::from("\n## Figures\n\nEach figure is in PNG and SVG.\n\n");
    for (stem, caption) in figs {
        let _ = writeln!(
            s,
            "- {caption}: `{stem}.png`, `{stem}.svg`\n\n  ![{caption}]({stem}.png)\n"
        );
    }
    s
}

/// The parameter table of report.md.
fn parameter_table(params: &[(String, f64, Option<f64>)]) -> String {
    let mut s =
        String::from("\n## Parameters\n\n| parameter | change | σ | t |\n|---|---|---|---|\n");
    for (name, change, sigma) in params {
        let (to, unit) = if is_angle(name) {
            (180.0 / std::f64::consts::PI, "°")
        } else {
            (1e3, " mm")
        };
        let _ = writeln!(
            s,
            "| {name} | {:.4}{unit} | {} | {} |",
            change * to,
            sigma.map_or("-".into(), |v| format!("{:.4}{unit}", v * to)),
            sigma
                .filter(|v| *v > 0.0)
                .map_or("-".into(), |v| format!("{:.2}", change / v))
        );
    }
    s
}

/// Writes `calibrate --report DIR`.
pub fn calibration(dir: &Path, s: &CalibrationSummary<'_>) -> Result<()> {
    let staged = StagedDir::new(dir)?;
    let out = staged.path();
    let ori = s
        .orientation_deg
        .as_ref()
        .map(|(b, a)| (b.as_slice(), a.as_slice()));
    let mut figs = calibration_figures(
        out,
        s.what,
        (&s.position_mm.0, &s.position_mm.1),
        ori,
        &s.params,
        s.id,
    )?;
    if let Some((nom, cal)) = &s.splits {
        plots::splits(&out.join("holdout_splits"), nom, cal)?;
        figs.push((
            "holdout_splits".into(),
            "held-out position RMS of each split (mm): nominal against calibrated".into(),
        ));
    }
    let rms = |v: &[f64]| (v.iter().map(|x| x * x).sum::<f64>() / v.len().max(1) as f64).sqrt();
    let mut md = format!(
        "# Calibration report\n\nRobot: `{}` (chain {}). Data: {}.\n\nFit: {:?} ({:?}) after {} iterations, rank {} of {}.\n\n",
        s.robot.name,
        crate::report::chain(s.robot).join(" → "),
        s.source,
        s.id.status,
        s.id.stop,
        s.id.iterations,
        s.id.rank,
        s.id.names.len()
    );
    let _ = writeln!(
        md,
        "Position error over {} {}s: RMS {:.3} mm nominal, {:.3} mm calibrated.",
        s.position_mm.0.len(),
        s.what,
        rms(&s.position_mm.0),
        rms(&s.position_mm.1)
    );
    if let Some((b, a)) = &s.orientation_deg {
        let _ = writeln!(
            md,
            "\nOrientation error: RMS {:.4}° nominal, {:.4}° calibrated.",
            rms(b),
            rms(a)
        );
    }
    for n in &s.notes {
        let _ = writeln!(md, "\n{n}");
    }
    md += &figure_section(&figs);
    md += &parameter_table(&s.params);
    super::pages::calibration(out, s, &figs)?;
    put(&staged, "report.md", &md)?;
    put(&staged, "report.json", &(json_text(&s.json)? + "\n"))?;
    staged.commit()?;
    Ok(())
}

/// The joint rows of the limits figure: each joint's values as fractions of
/// its range, labelled with its limits (degrees, or mm for prismatic).
fn joint_rows(robot: &Robot, names: &[String], qs: &[Vec<f64>]) -> Vec<JointRow> {
    let scale = joint_scale(robot);
    robot
        .limits
        .iter()
        .enumerate()
        .map(|(j, &[lo, hi])| {
            let unit = if scale[j] == 1e3 { " mm" } else { "°" };
            let span = (hi - lo).max(f64::MIN_POSITIVE);
            JointRow {
                label: format!(
                    "{} [{:.0}{unit}, {:.0}{unit}]",
                    names
                        .get(j)
                        .filter(|n| n.parse::<f64>().is_err())
                        .map_or_else(|| format!("q{}", j + 1), Clone::clone),
                    lo * scale[j],
                    hi * scale[j]
                ),
                fractions: qs.iter().map(|q| (q[j] - lo) / span).collect(),
            }
        })
        .collect()
}

/// The report's "How many poses" section: what the curve is, every size
/// it computed with its figures, and the size it recommends.
fn how_many_text(curve: &PoseCountCurve, noise_is_default: bool) -> String {
    let hi = 3 * curve.n_min;
    let asked: Vec<String> = curve
        .points
        .iter()
        .filter(|p| p.n > hi)
        .map(|p| p.n.to_string())
        .collect();
    let mut md = format!(
        "\n## How many poses\n\nFor N from the fewest whose rows can determine the {} unknowns ({}) to three times that ({hi}), {}{}, the best design the selection finds, its D-efficiency ((det M / det M*)^(1/p), M* the certified bound of every N-pose design of the pool), and the position error predicted after calibrating with it, from its covariance σ² (XᵀX)⁻¹ (no fitting), at {} random configurations within the joint limits (seed {}): the RMS over them, the 95th percentile of the error {} shows (over the configurations and the noise), and the 95th percentile of the RMS at one configuration. Sensor noise σ = {}{}.\n\n",
        curve.p,
        curve.n_min,
        if curve.step <= 1 {
            "every N".to_string()
        } else {
            format!(
                "in steps of up to {} (the table is thinned to 20 sizes)",
                curve.step
            )
        },
        if asked.is_empty() {
            String::new()
        } else {
            format!(", and N = {} (asked)", asked.join(", "))
        },
        curve.configurations,
        curve.seed,
        if curve.noise_px.is_some() {
            "the moving one's origin (the target's, or a camera's on the flange)"
        } else {
            "a measured point"
        },
        noise_text(curve),
        if noise_is_default && curve.noise_px.is_some() {
            format!(" ({})", crate::names::phrase::DEFAULT_PIXEL_NOISE)
        } else if noise_is_default {
            format!(" ({})", crate::names::phrase::DEFAULT_NOISE)
        } else {
            String::new()
        }
    );
    md += "| N | D-efficiency | predicted RMS (mm) | 95th percentile of the error (mm) | 95th percentile of a configuration's RMS (mm) |\n|---|---|---|---|---|\n";
    for p in &curve.points {
        let e = &p.predicted;
        let _ = writeln!(
            md,
            "| {} | {:.4} | {:.4} | {:.4} | {:.4} |",
            p.n, p.d_efficiency, e.position_rms_mm, e.position_error_p95_mm, e.position_p95_mm
        );
    }
    if let Some(r) = &curve.recommended {
        md += "\n";
        md += &recommendation_text(r);
    }
    md
}

/// The curve's noise σ with its unit: "0.01 mm per coordinate" or
/// "0.3 px".
pub fn noise_text(curve: &PoseCountCurve) -> String {
    match (curve.noise_m, curve.noise_px) {
        (_, Some(px)) => format!("{px} px"),
        (m, None) => format!("{} mm per coordinate", m.unwrap_or(f64::NAN) * 1e3),
    }
}

/// The "how many poses" figure of a report: writes it into `out` and
/// returns its (stem, caption); `chosen` the design's size.
fn how_many_figure(out: &Path, curve: &PoseCountCurve, chosen: usize) -> Result<(String, String)> {
    let rows: Vec<CurveRow> = curve
        .points
        .iter()
        .map(|p| CurveRow {
            n: p.n,
            d_efficiency: p.d_efficiency,
            rms_mm: p.predicted.position_rms_mm,
            p95_mm: p.predicted.position_error_p95_mm,
        })
        .collect();
    let noise = noise_text(curve);
    let short = noise.trim_end_matches(" per coordinate");
    plots::how_many(&out.join("how_many_poses"), &rows, chosen, short)?;
    Ok((
        "how_many_poses".to_string(),
        format!(
            "the best design found at each N: D-efficiency against the certified bound, and the position error predicted at {} random configurations (mm) for σ = {short}",
            curve.configurations
        ),
    ))
}

/// One line: the size a curve recommends, and why.
pub fn recommendation_text(r: &crate::how_many::Recommendation) -> String {
    use crate::how_many::{KNEE_GAIN, KNEE_MORE_PERCENT, Recommendation as R};
    match r {
        R::Target {
            n,
            target_mm,
            predicted_mm,
        } => format!(
            "how many poses: N = {n} recommended, the fewest predicted to reach {target_mm} mm (position RMS {predicted_mm:.4} mm)\n"
        ),
        R::TargetNotReached {
            n,
            target_mm,
            predicted_mm,
        } => format!(
            "how many poses: no N of the curve is predicted to reach {target_mm} mm; the closest is N = {n} (position RMS {predicted_mm:.4} mm): a less noisy sensor, or more poses than the curve's range\n"
        ),
        R::Knee {
            n,
            next_n,
            predicted_mm,
            gain,
        } => format!(
            "how many poses: N = {n} recommended (position RMS {predicted_mm:.4} mm), the knee of the curve: {KNEE_MORE_PERCENT} % more poses (N = {next_n}) gain {:.1} %, under {:.0} % ({TARGET_ERROR})\n",
            gain * 100.0,
            KNEE_GAIN * 100.0,
            TARGET_ERROR = crate::names::phrase::TARGET_ERROR
        ),
        R::NoKnee { n, predicted_mm } => format!(
            "how many poses: N = {n} recommended (position RMS {predicted_mm:.4} mm), the curve's largest: {KNEE_MORE_PERCENT} % more poses still gain {:.0} % or more up to its end ({TARGET_ERROR})\n",
            KNEE_GAIN * 100.0,
            TARGET_ERROR = crate::names::phrase::TARGET_ERROR
        ),
    }
}

/// Writes `select --report DIR`: the "how many poses" curve, the selected
/// poses against the joint limits, the tour when ordered.
pub fn selection(
    dir: &Path,
    robot: &Robot,
    report: &SelectReport,
    curve: &PoseCountCurve,
    noise_is_default: bool,
) -> Result<()> {
    let staged = StagedDir::new(dir)?;
    let out = staged.path();
    let mut figs = vec![how_many_figure(out, curve, report.poses.len())?];
    let qs: Vec<Vec<f64>> = report.configurations.iter().map(|c| c.q.clone()).collect();
    plots::joints_vs_limits(
        &out.join("joints_vs_limits"),
        &joint_rows(robot, &report.joint_names, &qs),
    )?;
    figs.push((
        "joints_vs_limits".into(),
        "the selected poses' joint values within each joint's limits".into(),
    ));
    if let Some(t) = report.tour.as_ref().filter(|t| t.reordered) {
        let times = crate::select::tour::arrival_times(&t.speeds, t.home.as_deref(), &qs)?;
        let deg: Vec<Vec<f64>> = qs
            .iter()
            .map(|q| {
                q.iter()
                    .zip(&joint_scale(robot))
                    .map(|(v, s)| v * s)
                    .collect()
            })
            .collect();
        plots::tour(&out.join("tour"), &report.joint_names, &times, &deg)?;
        figs.push(("tour".into(), format!("the poses in visiting order: each joint's value against the time the tour reaches the pose (s); {:.2} s in all against {:.2} s in selection order", t.visiting_order.time_s, t.selection_order.time_s)));
    }
    let mut md = format!(
        "# Pose selection report\n\nRobot: `{}` (chain {}), {} unknowns, {} rows per pose; pool of {} poses.\n\nSelected: {} poses, log10 OI_D {:.4} (OI_D = det XᵀX, the information of the design).\n",
        robot.name,
        crate::report::chain(robot).join(" → "),
        curve.p,
        curve.rows_per_pose,
        report.pool_size,
        report.poses.len(),
        report.log10_oid
    );
    md += &how_many_text(curve, noise_is_default);
    if let Some(m) = &report.moves {
        let _ = writeln!(
            md,
            "\nMoves of the tour checked for collision ({} moves, at most {} mm of link motion between checks): {}.",
            m.moves_checked,
            m.resolution_m * 1e3,
            if m.colliding.is_empty() {
                "every move is free".to_string()
            } else {
                format!(
                    "{} move(s) collide, see report.json's selection.moves",
                    m.colliding.len()
                )
            }
        );
    }
    super::pages::selection(out, robot, report, curve, &figs)?;
    let report = serde_json::to_value(report).map_err(json_error)?;
    finish_selection(staged, md, &figs, &report, curve)
}

/// Writes `select --camera-info … --report DIR`: report.md (the text
/// report, the "how many poses" curve on the pixel Jacobian, the figures),
/// report.json (`{"selection": the --json object, "how_many_poses": the
/// curve}`), the curve's figure and the chosen poses against the joint
/// limits (`names` the robot's joints, `page`'s design the poses), and the
/// 3D page ([`super::page_camera`]).
#[allow(clippy::too_many_arguments)]
pub fn camera_selection(
    dir: &Path,
    robot: &Robot,
    names: &[String],
    page: &super::page_camera::CameraPage<'_>,
    text: &str,
    json: &serde_json::Value,
    curve: &PoseCountCurve,
    noise_is_default: bool,
) -> Result<()> {
    let staged = StagedDir::new(dir)?;
    let out = staged.path();
    let qs = &page.design.qs;
    let mut figs = vec![how_many_figure(out, curve, qs.len())?];
    plots::joints_vs_limits(&out.join("joints_vs_limits"), &joint_rows(robot, names, qs))?;
    figs.push((
        "joints_vs_limits".into(),
        "the selected poses' joint values within each joint's limits".into(),
    ));
    let mut md = format!(
        "# Pose selection report (camera)\n\nRobot: `{}` (chain {}), {} unknowns; a pose's pixel rows compressed to the {} of their information's rank.\n\n```text\n{}```\n",
        robot.name,
        crate::report::chain(robot).join(" → "),
        curve.p,
        curve.rows_per_pose,
        text
    );
    md += &how_many_text(curve, noise_is_default);
    super::page_camera::camera_selection(out, page, curve, &figs)?;
    finish_selection(staged, md, &figs, json, curve)
}

/// The end of a selection report: the sizes the curve skipped and the
/// figures appended to `md`, report.md and report.json (`{"selection":
/// selection, "how_many_poses": curve}`) written, the directory swapped in.
fn finish_selection(
    staged: StagedDir,
    mut md: String,
    figs: &[(String, String)],
    selection: &serde_json::Value,
    curve: &PoseCountCurve,
) -> Result<()> {
    for (n, why) in &curve.skipped {
        let _ = writeln!(md, "\nN = {n}: no identifying design ({why}).");
    }
    md += &figure_section(figs);
    put(&staged, "report.md", &md)?;
    let json = serde_json::json!({ "selection": selection, "how_many_poses": curve });
    put(&staged, "report.json", &(json_text(&json)? + "\n"))?;
    staged.commit()?;
    Ok(())
}

/// Per joint, the factor from radians (metres) to the figures' degrees (mm).
fn joint_scale(robot: &Robot) -> Vec<f64> {
    let mut k = vec![180.0 / std::f64::consts::PI; robot.dof()];
    for f in &robot.frames {
        if let (Some(j), JointKind::Prismatic) = (f.joint, f.joint_kind) {
            k[j] = 1e3;
        }
    }
    k
}

/// Writes `calibrate --report DIR` for a contact file: report.md (the text
/// report: the fit, in-sample and held-out consistency, in mm, and the
/// figures), report.json (the `--json` object), the figures of `r`
/// ([`super::contact_figures::draw`]) and the 3D page of the robot at each
/// contact's configuration (`poses`, labelled) with the fit's sockets and
/// planes ([`super::page_contacts`]).
pub fn contacts(
    dir: &Path,
    r: &super::contact_figures::ContactReport<'_>,
    text: &str,
    json: &serde_json::Value,
    poses: &[(String, Vec<f64>)],
) -> Result<()> {
    let robot = r.robot;
    let staged = StagedDir::new(dir)?;
    let figs = super::contact_figures::draw(staged.path(), r)?;
    super::page_contacts::contacts(staged.path(), r, text, poses, &figs)?;
    let md = format!(
        "# Calibration report (contacts)\n\nRobot: `{}` (chain {}).\n\n```text\n{}```\n{}",
        robot.name,
        crate::report::chain(robot).join(" → "),
        text,
        figure_section(&figs)
    );
    put(&staged, "report.md", &md)?;
    put(&staged, "report.json", &(json_text(json)? + "\n"))?;
    staged.commit()?;
    Ok(())
}

/// Writes `calibrate --images … --report DIR` (replaced whole,
/// atomically): `contact_sheet.png` (the sheet's `images`) and
/// `images.json` (what became of each image, `reports`).
pub fn camera_images(
    dir: &Path,
    images: &[super::contact_sheet::SheetImage],
    reports: &[crate::io::images::ImageReport],
) -> Result<()> {
    let staged = StagedDir::new(dir)?;
    super::contact_sheet::write_contact_sheet(&staged.path().join("contact_sheet.png"), images)?;
    put(&staged, "images.json", &json_text(reports)?)?;
    staged.commit()
}

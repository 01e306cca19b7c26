//! `calibrate --observations pixels.csv --camera-info cam.yaml --target
//! board.yaml --mounting …` (or `--camera-link LINK` for a camera on the
//! robot's own link, `activecal::io::urdf_branch`): calibration from a
//! camera's pixels. Reads the files, fits (`activecal::identify::camera`), renders the fit and writes
//! `--out` (the URDF with the calibrated joint origins, the frames file
//! with the camera's and target's placements). Written only when the fit
//! converged, each file atomically and never over an existing one without
//! `--force`.

use super::calibrate_args::CalibrateArgs;
use activecal::frames::camera::camera_frames;
use activecal::identify::LmSettings;
use activecal::identify::camera::{CameraFit, fit_camera};
use activecal::io::calibrated::{Format, render};
use activecal::io::camera_info::read_camera_info;
use activecal::io::camera_observations::read_observations;
use activecal::io::camera_target::read_target;
use activecal::io::urdf_branch::camera_branch;
use activecal::measure::camera::{CameraSensor, Mounting};
use activecal::model::Robot;
use anyhow::{Context, Result, bail};
use nalgebra::{Isometry3, Translation3, UnitQuaternion};
use serde_json::json;
use std::fmt::Write as _;
use std::path::Path;

/// Parses `X,Y,Z,ROLL,PITCH,YAW` (metres, radians; rpy as in URDF).
fn parse_placement(flag: &str, s: &str) -> Result<Isometry3<f64>> {
    let v = super::parse_list::<f64>(s, flag)?;
    if v.len() != 6 || v.iter().any(|x| !x.is_finite()) {
        bail!("{flag} {s}: expected six finite numbers X,Y,Z,ROLL,PITCH,YAW (metres and radians)");
    }
    Ok(Isometry3::from_parts(
        Translation3::new(v[0], v[1], v[2]),
        UnitQuaternion::from_euler_angles(v[3], v[4], v[5]),
    ))
}

/// Refuses an output a camera calibration cannot be written as, before
/// any work.
fn check_out(a: &CalibrateArgs, robot: &Robot) -> Result<()> {
    for path in &a.out {
        if Format::of(path)? == Format::Toml || robot.source.is_none() {
            bail!(
                "--out {}: a camera calibration is written as .urdf (your URDF with the calibrated joint origins) and .yaml (the frames file with the camera's and target's placements), for a robot imported from a URDF",
                path.display()
            );
        }
    }
    Ok(())
}

/// Calibrates from a camera's observations; `Ok(Some(why))` when the fit
/// did not converge (the report is printed, nothing written).
pub fn calibrate_camera(
    a: &CalibrateArgs,
    robot: &Robot,
    obs_path: &Path,
) -> Result<Option<String>> {
    check_out(a, robot)?;
    check_camera_info_out(a, obs_path)?;
    let (Some(info), Some(target), Some(cp), Some(tp)) =
        (&a.camera_info, &a.target, &a.camera_pose, &a.target_pose)
    else {
        bail!("--observations needs --camera-info, --target, --camera-pose and --target-pose");
    };
    let (branch, mounting) = match (&a.camera_link, a.mounting) {
        (Some(link), _) => (
            Some(camera_branch(robot, link).with_context(|| format!("--camera-link {link}"))?),
            Mounting::EyeToHand,
        ),
        (None, Some(m)) => (None, m.into()),
        (None, None) => bail!("--observations needs --mounting or --camera-link"),
    };
    let robot = branch.as_ref().unwrap_or(robot);
    let label = a
        .camera_link
        .as_ref()
        .map_or_else(|| mounting.name().to_string(), |l| format!("camera on {l}"));
    let intrinsics = read_camera_info(info).context("--camera-info")?;
    let target = read_target(target).context("--target")?;
    let obs = read_observations(obs_path, robot, &target, &intrinsics, a.units.units())?;
    let (cam0, tgt0) = (
        parse_placement("--camera-pose", cp)?,
        parse_placement("--target-pose", tp)?,
    );
    let sensor = CameraSensor::new(intrinsics, mounting, target.points.clone(), &cam0, &tgt0)
        .with_face(target.face)
        .with_intrinsics_refined(a.refine_intrinsics);
    let lm = LmSettings::builder()
        .max_iterations(a.max_iterations)
        .geodesic(!a.no_geodesic)
        .build()?;
    let fit = fit_camera(
        robot,
        &sensor,
        &CameraSensor::start_own(&cam0, &tgt0),
        &obs,
        &lm,
    )?;
    let mut frames = camera_frames(&fit)?;
    if let Some(c) = frames.as_mut().and_then(|f| f.1.camera.as_mut()) {
        c.camera_link.clone_from(&a.camera_link);
    }
    let mut written = Vec::new();
    if fit.converged
        && let Some(f) = &frames
    {
        for path in &a.out {
            let text = render(
                Format::of(path)?,
                &fit.robot,
                &fit.table,
                Some((&f.0, &f.1)),
                "",
            )
            .map_err(|e| anyhow::anyhow!("--out {}: {e}", path.display()))?;
            super::write_new(path, &text, a.force)?;
            written.push(path.display().to_string());
        }
    }
    if fit.converged
        && let Some(o) = &a.out_camera_info
    {
        write_camera_info(o, &fit, obs_path, a.force)?;
        written.push(o.display().to_string());
    }
    let v = json!({
        "robot": robot.name,
        "observations": obs_path.display().to_string(),
        "mounting": fit.sensor.mounting(),
        "camera_link": a.camera_link,
        "poses": obs.qs.len(),
        "points_seen": obs.n_seen(),
        "names": fit.names,
        "estimate": fit.estimate,
        "std": fit.std,
        "start_rms_px": fit.given_rms_px,
        "rigid_rms_px": fit.rigid_rms_px,
        "rms_px": fit.rms_px,
        "sigma_px": fit.sigma_px,
        "redundancy": fit.redundancy,
        "converged": fit.converged,
        "fixed_intrinsics": fit.fixed_intrinsics,
        "stop": format!("{:?}", fit.stop),
        "camera": frames.as_ref().and_then(|f| f.1.camera.clone()),
        "intrinsics": a.refine_intrinsics.then(|| fit.intrinsics()),
        "out": written,
    });
    super::emit(a.json, &v, || {
        text(
            &fit,
            &label,
            obs_path,
            obs.qs.len(),
            frames.as_ref().map(|f| &f.1),
            &written,
        )
    })?;
    Ok((!fit.converged).then(|| {
        format!(
            "the camera fit did not converge ({:?} after {} iterations)",
            fit.stop, fit.iterations
        )
    }))
}

/// Refuses an `--out-camera-info` that is not a `.yaml` or exists (without
/// `--force`), before any work.
fn check_camera_info_out(a: &CalibrateArgs, obs_path: &Path) -> Result<()> {
    if let Some(o) = &a.out_camera_info {
        let yaml = o
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("yaml") || e.eq_ignore_ascii_case("yml"));
        if !yaml {
            bail!(
                "--out-camera-info {}: the refined intrinsics are written as a ROS camera_info .yaml",
                o.display()
            );
        }
        let mut outs: Vec<(&str, &Path)> = vec![("--out-camera-info", o.as_path())];
        outs.extend(a.out.iter().map(|p| ("--out", p.as_path())));
        let ins: Vec<&Path> = [
            a.camera_info.as_deref(),
            a.target.as_deref(),
            Some(obs_path),
        ]
        .into_iter()
        .flatten()
        .collect();
        super::check_outputs(&outs, &ins, a.force)?;
    }
    Ok(())
}

/// Writes the refined intrinsics of `fit` to `o` as a ROS camera_info.
fn write_camera_info(o: &Path, fit: &CameraFit, obs_path: &Path, force: bool) -> Result<()> {
    let name = o
        .file_stem()
        .map_or_else(|| "camera".into(), |s| s.to_string_lossy());
    let comment = format!(
        "intrinsics refined by activecal calibrate --refine-intrinsics from {}",
        obs_path.display()
    );
    let text = activecal::io::camera_info::render_camera_info(&fit.intrinsics(), &name, &comment);
    super::write_new(o, &text, force)
}

/// The human-readable report.
fn text(
    fit: &CameraFit,
    label: &str,
    path: &Path,
    poses: usize,
    frames: Option<&activecal::frames::report::FramesReport>,
    written: &[String],
) -> String {
    let mut s = String::new();
    let n_kin = fit.robot.n_unknowns();
    let _ = writeln!(
        s,
        "camera calibration ({label}) from {}: {poses} poses, {} pixel rows ({} points seen)",
        path.display(),
        fit.rows,
        fit.rows / 2
    );
    let refined = fit.sensor.refines_intrinsics() || !fit.fixed_intrinsics.is_empty();
    let _ = writeln!(
        s,
        "unknowns: {} = {n_kin} of the robot + 6 of the camera + 6 of the target{}",
        fit.names.len(),
        if refined {
            format!(" + {} intrinsics", fit.names.len() - n_kin - 12)
        } else {
            String::new()
        }
    );
    let _ = writeln!(
        s,
        "pixel error RMS: {:.3} px at the given placements, {:.3} px after fitting them alone, {:.3} px calibrated",
        fit.given_rms_px, fit.rigid_rms_px, fit.rms_px
    );
    match fit.sigma_px {
        Some(sg) => {
            let _ = writeln!(
                s,
                "pixel σ (variance component): {sg:.3} px, {} degrees of freedom",
                fit.redundancy
            );
        }
        None => s.push_str("pixel σ: not estimated\n"),
    }
    if let Some(c) = frames.and_then(|f| f.camera.as_ref()) {
        for (what, b) in [("camera (optical frame)", &c.camera), ("target", &c.target)] {
            let _ = write!(
                s,
                "{what} in {}: xyz [{:.5}, {:.5}, {:.5}] m, rpy [{:.4}, {:.4}, {:.4}] deg",
                b.parent, b.xyz[0], b.xyz[1], b.xyz[2], b.rpy_deg[0], b.rpy_deg[1], b.rpy_deg[2]
            );
            if let (Some(t), Some(r)) = (b.sigma_xyz_mm, b.sigma_rotation_deg) {
                let _ = write!(
                    s,
                    ", σ {} mm, {} deg",
                    super::frames_text::s3(t, 3),
                    super::frames_text::s3(r, 4)
                );
            }
            s.push('\n');
        }
    }
    if refined {
        intrinsics_text(fit, &mut s);
    }
    s.push_str("robot unknowns (change from nominal, σ):\n");
    for k in 0..n_kin {
        let unit = if fit.names[k].starts_with("a_") || fit.names[k].starts_with("d_") {
            (1e3, "mm")
        } else {
            (180.0 / std::f64::consts::PI, "deg")
        };
        let change = (fit.estimate[k] - fit.start[k]) * unit.0;
        let sd = fit.std.as_ref().map_or(f64::NAN, |sd| sd[k] * unit.0);
        let _ = writeln!(
            s,
            "  {:<28} {change:+.4} {u}  σ {sd:.4} {u}",
            fit.names[k],
            u = unit.1
        );
    }
    if !fit.converged {
        let _ = writeln!(
            s,
            "NOT CONVERGED ({:?} after {} iterations): nothing written",
            fit.stop, fit.iterations
        );
    }
    for w in written {
        let _ = writeln!(s, "wrote {w}");
    }
    s
}

/// The refined intrinsics with their change from the given ones and σ,
/// and those held at their given values with the reason.
fn intrinsics_text(fit: &CameraFit, s: &mut String) {
    let k0 = fit.robot.n_unknowns() + activecal::measure::camera::OWN_PARAMS;
    s.push_str("intrinsics (refined, change from given, σ):\n");
    let mask = fit.sensor.free_intrinsics();
    let free = (0..mask.len()).filter(|&j| mask[j]);
    for (k, j) in (k0..).zip(free) {
        let name = fit.sensor.intrinsics().names()[j];
        let unit = if j < 4 { " px" } else { "" };
        let sd = fit.std.as_ref().map_or(f64::NAN, |sd| sd[k]);
        let _ = writeln!(
            s,
            "  {name:<3} {:.6}{unit}  ({:+.6})  σ {sd:.6}{unit}",
            fit.estimate[k],
            fit.estimate[k] - fit.start[k]
        );
    }
    for f in &fit.fixed_intrinsics {
        let _ = writeln!(s, "  {} held at {}: {}", f.name, f.value, f.reason);
    }
}

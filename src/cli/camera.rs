//! `calibrate --observations pixels.csv --camera-info cam.yaml --target
//! board.yaml --mounting …` (or `--camera-link LINK` for a camera on the
//! robot's own link, `activecal::io::urdf_branch`): calibration from a
//! camera's pixels. Reads the files, fits (`activecal::experiment::camera`), renders the fit and writes
//! `--out` (the URDF with the calibrated joint origins, the frames file
//! with the camera's and target's placements). Written only when the fit
//! converged, each file atomically and never over an existing one without
//! `--force`.

use super::calibrate_args::CalibrateArgs;
use activecal::data::CameraObservations;
use activecal::experiment::camera::files;
use activecal::experiment::camera::{CameraCalibrationError, CameraSetup, CameraSource};
use activecal::io::atomic::Output;
use activecal::io::camera_info::read_camera_info;
use activecal::io::camera_observations::read_observations;
use activecal::io::camera_target::read_target;
use activecal::io::urdf_branch::camera_branch;
use activecal::model::Robot;
use activecal::options::Intrinsics;
use activecal::options::LmSettings;
use activecal::options::Mounting;
use activecal::options::placement;
use activecal::render::camera_text::CameraText;
use activecal::write::calibrated::Format;
use anyhow::{Context, Result, bail};
use std::path::Path;

/// Calibrates from a camera's observations; `Ok(Some(why))` when the
/// library refuses the fit (it did not converge or cannot be right,
/// `activecal::experiment::camera::verdict`: the report is printed,
/// nothing written).
pub fn calibrate_camera(a: &CalibrateArgs, robot: &Robot) -> Result<Option<String>> {
    let outs: Vec<_> = a.out.iter().map(|p| super::out_file(p)).collect();
    files::check_robot_outputs(&outs, robot)?;
    let info_out = a.out_camera_info.as_deref().map(|path| Output {
        label: "--out-camera-info",
        path,
    });
    info_out
        .as_ref()
        .map(files::check_camera_info_output)
        .transpose()?;
    let (Some(info), Some(target)) = (&a.camera_info, &a.target) else {
        bail!("--observations needs --camera-info and --target");
    };
    if a.images.is_some() && a.bag.is_none() && a.joints.is_none() {
        bail!("--images needs --joints (the joint values of each image)");
    }
    let (branch, mounting) = match (&a.camera_link, a.mounting) {
        (Some(link), _) => (
            Some(camera_branch(robot, link).with_context(|| format!("--camera-link {link}"))?),
            Mounting::EyeToHand,
        ),
        (None, Some(m)) => (None, m),
        (None, None) => bail!("--observations needs --mounting or --camera-link"),
    };
    let robot = branch.as_ref().unwrap_or(robot);
    let label = a
        .camera_link
        .as_ref()
        .map_or_else(|| mounting.to_string(), |l| format!("camera on {l}"));
    let target_origin = target.display().to_string();
    let target = read_target(target).context("--target")?;
    let (intrinsics, obs_path, obs, images, bag) = camera_data(a, robot, info, &target)?;
    let parse = |flag: &str, s: &Option<String>| {
        s.as_ref()
            .map(|s| super::six(flag, s).map(|v| placement(&v)))
            .transpose()
    };
    let setup = CameraSetup {
        intrinsics,
        target,
        target_origin,
        mounting,
        camera_link: a.camera_link.clone(),
        camera: parse("--camera-pose", &a.camera_pose)?,
        target_pose: parse("--target-pose", &a.target_pose)?,
        refine_intrinsics: a.refine_intrinsics,
        outliers: a.outlier_choice()?,
        pixel_noise: a.pixel_noise,
    };
    let lm = LmSettings::builder()
        .max_iterations(a.max_iterations)
        .geodesic(!a.no_geodesic)
        .build()?;
    let source = match (&images, &bag) {
        (Some(read), _) => CameraSource::Images(read.images.clone()),
        (None, Some(r)) => CameraSource::Bag(r.clone()),
        (None, None) => CameraSource::Pixels,
    };
    let cal = activecal::experiment::camera::calibrate_camera(robot, obs, &setup, &lm)
        .map_err(|e| match e {
            CameraCalibrationError::Start { origin, error } => anyhow::Error::new(error).context(
                format!("{origin}: no start computed from the pixels; give --camera-pose and --target-pose"),
            ),
            e => e.into(),
        })?
        .with_source(source);
    let (fit, frames) = (&cal.fit, &cal.frames);
    let mut written = Vec::new();
    // The library's verdict: a fit that did not converge or cannot be
    // right is not written.
    let ok = cal.verdict.refusal().is_none();
    if ok && frames.is_some() {
        for out in &outs {
            cal.write_robot(Format::of(out.path)?, *out, a.force, &[])?;
            written.push(out.path.display().to_string());
        }
    }
    if ok && let Some(o) = info_out {
        cal.write_camera_info(o, &obs_path.display().to_string(), a.force, &[])?;
        written.push(o.path.display().to_string());
    }
    if let (Some(dir), Some(read)) = (&a.report, &images) {
        // The directory was checked with the command's files, before any work.
        activecal::experiment::camera::images::write_sheet_folder(dir, read, &cal, &setup.target)?;
        written.push(dir.join("contact_sheet.png").display().to_string());
    }
    let v = serde_json::to_value(cal.report(written.clone()))?;
    super::emit(a.json, &v, || {
        activecal::render::camera_text::text(&CameraText {
            fit,
            label: &label,
            source: &obs_path.display().to_string(),
            poses: cal.observations.qs.len(),
            frames: frames.as_ref().map(|f| &f.1),
            written: &written,
            start: cal.start.as_ref(),
            labels: &cal.labels,
            notes: &cal.notes,
            noise_test: cal.noise_test.as_ref(),
            refusal: cal.verdict.refusal(),
        })
    })?;
    Ok(cal.verdict.refusal().map(str::to_string))
}

/// The camera's data: the intrinsics, where the pixels are from, the
/// observations, and the images read (files, or a bag's topic with its
/// report).
type CameraData<'a> = (
    Intrinsics,
    &'a Path,
    CameraObservations,
    Option<activecal::io::images::ImageObservations>,
    Option<activecal::io::bag::camera::BagImagesReport>,
);

/// Reads `--observations`, `--images` or a bag's `--images` topic (with
/// `--camera-info` the file or, with `--bag`, the topic).
fn camera_data<'a>(
    a: &'a CalibrateArgs,
    robot: &Robot,
    info: &Path,
    target: &activecal::io::camera_target::Target,
) -> Result<CameraData<'a>> {
    Ok(match (&a.observations, &a.images, &a.bag) {
        (Some(p), _, _) => {
            let intrinsics = read_camera_info(info).context("--camera-info")?;
            let obs = read_observations(p, robot, target, &intrinsics, a.units.units())?;
            (intrinsics, p.as_path(), obs, None, None)
        }
        (None, Some(topic), Some(bag)) => {
            let got = super::camera_images::read_bag(a, robot, bag, topic, info, target)?;
            (
                got.intrinsics,
                bag.as_path(),
                got.observations,
                None,
                Some(got.report),
            )
        }
        (None, Some(spec), None) => {
            let intrinsics = read_camera_info(info).context("--camera-info")?;
            let read = super::camera_images::read(a, robot, spec, target, &intrinsics)?;
            let obs = read.observations.clone();
            (intrinsics, spec.as_path(), obs, Some(read), None)
        }
        (None, None, _) => bail!("give --observations (pixels) or --images"),
    })
}

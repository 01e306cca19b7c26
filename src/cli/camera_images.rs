//! `calibrate --images DIR|GLOB --joints joints.csv`: the images read into
//! the camera's observations by the library (`activecal::io::images`),
//! `--save-observations` written before the fit (with `--report DIR` the
//! library writes the contact sheet after it,
//! `activecal::experiment::camera::images::write_sheet_folder`).

use super::calibrate_args::CalibrateArgs;
use activecal::io::bag::camera::{BagImages, read_bag_images};
use activecal::io::camera_observations::observations_csv;
use activecal::io::camera_target::Target;
use activecal::io::images::joints::read_image_joints;
use activecal::io::images::{ImageObservations, read_images};
use activecal::model::Robot;
use activecal::options::Intrinsics;
use anyhow::{Context, Result, bail};
use std::path::Path;

/// Reads the images of `spec` with `--joints`' values, prints a line per
/// image (without `--json`: the report has them); writes
/// `--save-observations` (atomically, never over an existing file without
/// `--force`; the command's files were checked against each other before).
pub fn read(
    a: &CalibrateArgs,
    robot: &Robot,
    spec: &Path,
    target: &Target,
    intrinsics: &Intrinsics,
) -> Result<ImageObservations> {
    let Some(joints) = &a.joints else {
        bail!("--images needs --joints (the joint values of each image)");
    };
    let joints = read_image_joints(joints, robot, a.units.units()).context("--joints")?;
    let read = read_images(spec, &joints, target, intrinsics).context("--images")?;
    // What became of each image, before the fit (which may refuse them).
    if !a.json {
        for line in activecal::render::camera_text::image_lines(&read.images) {
            println!("{line}");
        }
    }
    if let Some(path) = &a.save_observations {
        let text = observations_csv(&read.observations, robot, target);
        super::write_new(path, &text, a.force).context("--save-observations")?;
    }
    Ok(read)
}

/// Reads the camera of `--bag` (`topic`: `--images`, `info`:
/// `--camera-info`, both topics) with the rest options, prints a line per
/// rest (without `--json`) and writes `--save-observations`.
pub fn read_bag(
    a: &CalibrateArgs,
    robot: &Robot,
    bag: &Path,
    topic: &Path,
    info: &Path,
    target: &Target,
) -> Result<BagImages> {
    let joints = a
        .joints
        .as_deref()
        .map_or("/joint_states".into(), |j| j.to_string_lossy());
    let s =
        a.from_bag
            .image_settings(&joints, &topic.to_string_lossy(), &info.to_string_lossy())?;
    let got = read_bag_images(bag, robot, target, &s)?;
    if !a.json {
        print!(
            "{}",
            activecal::render::bag_text::bag_images_text(&got.report, None)
        );
    }
    if let Some(path) = &a.save_observations {
        let text = observations_csv(&got.observations, robot, target);
        super::write_new(path, &text, a.force).context("--save-observations")?;
    }
    Ok(got)
}

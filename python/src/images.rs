//! `activecal.detect`: a camera's images read into the observations
//! `calibrate_camera` takes, as `activecal calibrate --images DIR --joints
//! FILE --save-observations F` writes them.

use crate::camera::{named, read_intrinsics, read_target, yaml_source};
use crate::convert::{Fail, arg_err, detached};
use crate::robot::Robot;
use pyo3::prelude::*;
use std::path::PathBuf;

/// Detects the target's points in a camera's images, as `activecal
/// calibrate --images IMAGES --joints JOINTS --save-observations F` does.
///
/// images: a folder of PNG images, a glob pattern (`DIR/*.png`) or one
/// file. target: a target YAML path or a dict (a `checkerboard` or a
/// `charuco` board with its `dictionary`). camera_info: a ROS camera_info
/// or OpenCV YAML path, or a dict (the images must be its size). robot: the
/// robot whose joint values the joints file holds; joints: a CSV with an
/// `image` column (each image's file name) and a column per joint.
/// Returns a pandas DataFrame with the observations CSV's columns `pose,
/// <joint names>, feature, u, v` (pixels; a pose per image used, its id the
/// image's place in the sorted list), which `calibrate_camera` takes as its
/// observations; `df.attrs["images"]` lists every image with what became
/// of it (`status` "found" with its figures, or "left_out" with its
/// `reason`).
#[pyfunction]
#[pyo3(signature = (images, target, camera_info, *, robot, joints))]
pub fn detect(
    py: Python<'_>,
    images: PathBuf,
    target: &Bound<'_, PyAny>,
    camera_info: &Bound<'_, PyAny>,
    robot: &Robot,
    joints: PathBuf,
) -> PyResult<Py<PyAny>> {
    let info_src = yaml_source(py, camera_info, "camera_info")?;
    let target_src = yaml_source(py, target, "target")?;
    if !images.exists() && !images.to_string_lossy().contains(['*', '?', '[']) {
        return Err(arg_err(
            "images",
            format!("{}: no such folder or file", images.display()),
        ));
    }
    let inner = robot.inner.clone();
    let (csv, report) = detached(py, move || {
        let intrinsics = read_intrinsics(&info_src)?;
        let target = read_target(&target_src)?;
        let units = activecal::units::Units::default();
        let j = activecal::io::images::joints::read_image_joints(&joints, &inner, units)
            .map_err(|e| named("joints", e))?;
        let read = activecal::io::images::read_images(&images, &j, &target, &intrinsics)
            .map_err(|e| named("images", e))?;
        let csv = activecal::io::camera_observations::observations_csv(
            &read.observations,
            &inner,
            &target,
        );
        let report = serde_json::to_string(&read.images).map_err(Fail::input)?;
        Ok::<_, Fail>((csv, report))
    })?;
    let io = py.import("io")?;
    let df = py
        .import("pandas")?
        .call_method1("read_csv", (io.call_method1("StringIO", (csv,))?,))?;
    let listed = py.import("json")?.call_method1("loads", (report,))?;
    df.getattr("attrs")?.set_item("images", listed)?;
    Ok(df.unbind())
}

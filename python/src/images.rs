//! `activecal.detect`: a camera's images read into the observations
//! `calibrate_camera` takes, as `activecal calibrate --images DIR --joints
//! FILE --save-observations F` writes them.

use crate::camera::{Source, named, read_intrinsics, read_target, yaml_source};
use crate::convert::{Fail, arg_err, detached};
use crate::robot::Robot;
use pyo3::prelude::*;
use std::path::PathBuf;

/// Detects the target's points in a camera's images, as `activecal
/// calibrate --images IMAGES --joints JOINTS --save-observations F` does.
///
/// images: a folder of PNG or JPEG images, a glob pattern (`DIR/*.png`) or one
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

/// Where `calibrate_camera`'s pixels come from: an observations CSV or
/// DataFrame, or images with their joint values.
pub(crate) enum PixelsSource {
    /// `observations=`.
    Observations(Source),
    /// `images=` and `joints=`.
    Images {
        /// The images as given (a folder, a pattern), for messages.
        origin: String,
        /// A folder or pattern to list, or the files given.
        spec: ImagesSpec,
        /// The joints CSV or DataFrame.
        joints: Source,
    },
}

/// The `images=` argument.
pub(crate) enum ImagesSpec {
    /// A folder, a glob pattern or one file (listed as the command line's
    /// `--images` lists it).
    Spec(PathBuf),
    /// A list of image files, in that order.
    Files(Vec<PathBuf>),
}

/// `calibrate_camera`'s pixels from its arguments: observations, or
/// images with joints (a CSV path or a DataFrame with an `image` column
/// and a column per joint); both, neither, or images without joints is an
/// error naming the argument.
pub(crate) fn pixels_source(
    py: Python<'_>,
    observations: Option<&Bound<'_, PyAny>>,
    images: Option<&Bound<'_, PyAny>>,
    joints: Option<&Bound<'_, PyAny>>,
) -> PyResult<PixelsSource> {
    match (observations, images, joints) {
        (Some(o), None, None) => Ok(PixelsSource::Observations(
            crate::camera::observations_source(o)?,
        )),
        (Some(_), Some(_), _) => Err(arg_err(
            "images",
            "give the pixels (observations) or the images (images and joints), not both",
        )),
        (Some(_), None, Some(_)) => Err(arg_err(
            "joints",
            "it gives the joint values of images=; observations carry their own",
        )),
        (None, None, _) => Err(arg_err(
            "observations",
            "none given: a camera's pixels (a CSV path or DataFrame), or images= with joints=",
        )),
        (None, Some(_), None) => Err(arg_err(
            "joints",
            "none given: images= needs each image's joint values (a CSV path or DataFrame with an 'image' column and a column per joint)",
        )),
        (None, Some(i), Some(j)) => {
            let (origin, spec) = images_spec(i)?;
            let joints = table_source(py, j)?;
            Ok(PixelsSource::Images {
                origin,
                spec,
                joints,
            })
        }
    }
}

fn images_spec(obj: &Bound<'_, PyAny>) -> PyResult<(String, ImagesSpec)> {
    if let Ok(p) = obj.extract::<PathBuf>() {
        if !p.exists() && !p.to_string_lossy().contains(['*', '?', '[']) {
            return Err(arg_err(
                "images",
                format!("{}: no such folder or file", p.display()),
            ));
        }
        return Ok((p.display().to_string(), ImagesSpec::Spec(p)));
    }
    let files: Vec<PathBuf> = obj.extract().map_err(|_| {
        arg_err(
            "images",
            "expected a folder, a glob pattern, an image file or a list of image files",
        )
    })?;
    if files.is_empty() {
        return Err(arg_err("images", "an empty list"));
    }
    Ok((
        format!("a list of {} images", files.len()),
        ImagesSpec::Files(files),
    ))
}

/// A CSV argument: a path, or a pandas DataFrame written as CSV.
fn table_source(_py: Python<'_>, obj: &Bound<'_, PyAny>) -> PyResult<Source> {
    if obj.hasattr("to_csv")? && obj.hasattr("columns")? {
        let kw = pyo3::types::PyDict::new(obj.py());
        kw.set_item("index", false)?;
        let text: String = obj.call_method("to_csv", (), Some(&kw))?.extract()?;
        return Ok(Source::Text(text));
    }
    let path: PathBuf = obj.extract().map_err(|_| {
        arg_err(
            "joints",
            "expected a CSV path (str or os.PathLike) or a pandas DataFrame with an 'image' column and a column per joint",
        )
    })?;
    Ok(Source::File(path))
}

impl PixelsSource {
    /// The files read (never written over).
    pub(crate) fn files(&self) -> Vec<PathBuf> {
        let mut out = Vec::new();
        match self {
            PixelsSource::Observations(Source::File(p)) => out.push(p.clone()),
            PixelsSource::Observations(Source::Text(_)) => {}
            PixelsSource::Images { spec, joints, .. } => {
                if let Source::File(p) = joints {
                    out.push(p.clone());
                }
                match spec {
                    ImagesSpec::Files(f) => out.extend(f.iter().cloned()),
                    ImagesSpec::Spec(s) => {
                        out.extend(
                            activecal::io::images::files::image_files(s).unwrap_or_default(),
                        );
                    }
                }
            }
        }
        out
    }
}

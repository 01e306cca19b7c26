//! `activecal.calibrate_camera`: calibration from a camera's pixels of a
//! target, as `activecal calibrate --observations FILE` does, and the
//! `CameraCalibration` it returns.

use crate::convert::{Fail, arg_err, detached, float_array, json_to_py, ndarray};
use crate::images::{ImagesSpec, PixelsSource};
use crate::robot::Robot;
use activecal::experiment::camera::{CameraCalibration as Calibrated, CameraSetup};
use activecal::options::Intrinsics;
use activecal::options::LmSettings;
use activecal::options::Mounting;
use activecal::write::calibrated::Format;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::{Path, PathBuf};

/// The command line's Levenberg–Marquardt limit (`--max-iterations`).
const MAX_ITERATIONS: usize = 200;

/// An input given as a file or in memory: the text and where it is from.
pub(crate) enum Source {
    /// A file's path.
    File(PathBuf),
    /// Text in the file's format, named `origin` in messages.
    Text(String),
}

/// A library error about input `name`: its kind, the message starting
/// with the input's name (unless the library's already does).
pub(crate) fn named(name: &str, e: impl Into<Fail>) -> Fail {
    let prefix = |m: String| {
        if m.starts_with(&format!("{name}: ")) {
            m
        } else {
            format!("{name}: {m}")
        }
    };
    match e.into() {
        Fail::Input(m) => Fail::Input(prefix(m)),
        Fail::File(m) => Fail::File(prefix(m)),
        Fail::Resource(m) => Fail::Resource(prefix(m)),
        Fail::Compute(m) => Fail::Compute(prefix(m)),
    }
}

/// A YAML input (`camera_info`, `target`): a path, or a dict of the
/// file's content (written as JSON, which YAML reads).
pub(crate) fn yaml_source(py: Python<'_>, obj: &Bound<'_, PyAny>, name: &str) -> PyResult<Source> {
    if obj.cast::<PyDict>().is_ok() {
        let text: String = py
            .import("json")?
            .call_method1("dumps", (obj,))
            .map_err(|e| arg_err(name, format!("a dict that is not JSON-serialisable ({e})")))?
            .extract()?;
        return Ok(Source::Text(text));
    }
    let path: PathBuf = obj
        .extract()
        .map_err(|_| arg_err(name, "expected a path (str or os.PathLike) or a dict"))?;
    Ok(Source::File(path))
}

/// The observations argument: a CSV path, or a pandas DataFrame with the
/// file's columns (written as CSV by pandas, floats round-tripping).
pub(crate) fn observations_source(obj: &Bound<'_, PyAny>) -> PyResult<Source> {
    if obj.hasattr("to_csv")? && obj.hasattr("columns")? {
        let kw = PyDict::new(obj.py());
        kw.set_item("index", false)?;
        let text: String = obj.call_method("to_csv", (), Some(&kw))?.extract()?;
        return Ok(Source::Text(text));
    }
    let path: PathBuf = obj.extract().map_err(|_| {
        arg_err(
            "observations",
            "expected a CSV path (str or os.PathLike) or a pandas DataFrame with columns pose, the joints, feature, u, v",
        )
    })?;
    Ok(Source::File(path))
}

/// Reads the intrinsics of `camera_info`.
pub(crate) fn read_intrinsics(s: &Source) -> Result<Intrinsics, Fail> {
    use activecal::io::camera_info::{parse_camera_info, read_camera_info};
    match s {
        Source::File(p) => read_camera_info(p),
        Source::Text(t) => parse_camera_info(t, "the dict"),
    }
    .map_err(|e| named("camera_info", e))
}

/// Reads the target's points.
pub(crate) fn read_target(s: &Source) -> Result<activecal::io::camera_target::Target, Fail> {
    use activecal::io::camera_target::{parse_target, read_target};
    match s {
        Source::File(p) => read_target(p),
        Source::Text(t) => parse_target(t, "the dict"),
    }
    .map_err(|e| named("target", e))
}

/// A placement argument: six numbers X, Y, Z, ROLL, PITCH, YAW.
pub(crate) fn six(py: Python<'_>, obj: &Bound<'_, PyAny>, name: &str) -> PyResult<[f64; 6]> {
    let (v, _) = float_array(
        py,
        obj,
        name,
        &[Some(6)],
        "X, Y, Z, ROLL, PITCH, YAW: metres and radians, rpy as in URDF",
    )?;
    Ok([v[0], v[1], v[2], v[3], v[4], v[5]])
}

/// The mounting and camera link arguments: the mounting they give.
pub(crate) fn mounting_of(mounting: Option<&str>, camera_link: Option<&str>) -> PyResult<Mounting> {
    match (mounting, camera_link) {
        (Some(_), Some(_)) => Err(arg_err(
            "camera_link",
            "a camera on the robot's own link is mounted on it: give mounting or camera_link, not both",
        )),
        (None, Some(_)) => Ok(Mounting::EyeToHand),
        (Some(m), None) => <Mounting as activecal::names::Choice>::from_name(m).ok_or_else(|| {
            arg_err(
                "mounting",
                format!("unknown mounting '{m}': \"eye-to-hand\" or \"eye-in-hand\""),
            )
        }),
        (None, None) => Err(arg_err(
            "mounting",
            "none given: \"eye-to-hand\" (the camera fixed, the target on the tip link), \"eye-in-hand\" (the camera on the tip link), or camera_link=LINK for a camera on the robot's own link",
        )),
    }
}

/// The chain a camera sees: `robot`'s, or for a camera on the robot's own
/// link the chain from it to the tip.
pub(crate) fn chain_of(
    robot: &activecal::model::Robot,
    camera_link: Option<&str>,
) -> Result<Option<activecal::model::Robot>, Fail> {
    camera_link
        .map(|l| {
            activecal::io::urdf_branch::camera_branch(robot, l)
                .map_err(|e| named("camera_link", Fail::Input(format!("{l}: {e}"))))
        })
        .transpose()
}

/// A calibration from a camera's pixels: the estimate with its σ, the
/// camera's and the target's placements, the pixel noise, the calibrated
/// robot and the refined intrinsics to write.
#[pyclass(module = "activecal", name = "CameraCalibration", frozen)]
pub struct CameraCalibration {
    cal: Calibrated,
    report: serde_json::Value,
    /// The files the call read.
    inputs: Vec<PathBuf>,
    /// How it was made, for pickling.
    recipe: crate::pickling::Recipe,
}

/// Calibrates the robot from a camera's pixels of a target, as `activecal
/// calibrate --observations FILE --json` does with the same files (or
/// `--images DIR --joints FILE` with images=, joints=).
///
/// observations: a CSV path or a pandas DataFrame with the file's columns
/// `pose, <joint names>, feature, u, v` (a row per point seen; pixels).
/// Or images: a folder of PNG or JPEG images, a glob pattern, one file or a list
/// of files (each a pose, in the folder's sorted order or the list's),
/// with joints: a CSV path or a DataFrame with an `image` column (each
/// image's file name) and a column per joint; the target's points are
/// detected by the library (as `detect` does) and `report["images"]` lists
/// what became of each image.
/// camera_info: a ROS camera_info or OpenCV YAML path, or a dict of a ROS
/// camera_info's content. target: a target YAML path, or a dict
/// ({"checkerboard": {"rows", "cols", "square"}} or {"points": [...]}).
/// mounting: "eye-to-hand" or "eye-in-hand"; or camera_link: the robot's
/// link a camera is on (a head). camera_pose, target_pose: the rough
/// placements X, Y, Z, ROLL, PITCH, YAW (metres, radians), the fit's
/// start; one left out (None) is computed from the pixels (PnP and the
/// closed-form hand-eye, the report's `start`). refine_intrinsics: fit the intrinsics too.
/// outliers: "drop" (default: a pose with a gross error, a shifted board,
/// or one point of it, a misdetected corner, found by Baarda's data
/// snooping at family-wise rate outlier_rate, left out one at a time and
/// listed in `report["outliers"]`) or "keep", as `--outliers`.
/// pixel_noise: the detector's stated σ per pixel coordinate (px), as
/// `--pixel-noise`: σ̂ is tested against it (`report["noise_test"]`), a
/// rejection warns (`UserWarning`), and the outlier test uses it. progress
/// as `calibrate` takes it.
#[pyfunction]
#[pyo3(signature = (robot, observations=None, camera_info=None, target=None, *, images=None, joints=None, camera_pose=None, target_pose=None, mounting=None, camera_link=None, refine_intrinsics=false, outliers="drop", outlier_rate=0.01, pixel_noise=None, progress=None))]
#[allow(clippy::too_many_arguments)]
pub fn calibrate_camera(
    py: Python<'_>,
    robot: &Bound<'_, Robot>,
    observations: Option<&Bound<'_, PyAny>>,
    camera_info: Option<&Bound<'_, PyAny>>,
    target: Option<&Bound<'_, PyAny>>,
    images: Option<&Bound<'_, PyAny>>,
    joints: Option<&Bound<'_, PyAny>>,
    camera_pose: Option<&Bound<'_, PyAny>>,
    target_pose: Option<&Bound<'_, PyAny>>,
    mounting: Option<&str>,
    camera_link: Option<String>,
    refine_intrinsics: bool,
    outliers: &str,
    outlier_rate: f64,
    pixel_noise: Option<f64>,
    progress: Option<&Bound<'_, PyAny>>,
) -> PyResult<CameraCalibration> {
    use crate::pickling::kept;
    let recipe = crate::recipe!(py, "calibrate_camera";
        robot = robot, observations = kept(observations)?,
        camera_info = kept(camera_info)?, target = kept(target)?,
        images = kept(images)?, joints = kept(joints)?,
        camera_pose = kept(camera_pose)?, target_pose = kept(target_pose)?, mounting = mounting,
        camera_link = &camera_link, refine_intrinsics = refine_intrinsics, outliers = outliers,
        outlier_rate = outlier_rate, pixel_noise = pixel_noise);
    let robot = robot.get();
    let m = mounting_of(mounting, camera_link.as_deref())?;
    let given: Vec<&str> = [
        ("camera_pose", camera_pose.is_some()),
        ("target_pose", target_pose.is_some()),
        ("mounting", mounting.is_some()),
        ("camera_link", camera_link.is_some()),
        ("refine_intrinsics", refine_intrinsics),
        ("outliers", outliers != "drop"),
        ("outlier_rate", outlier_rate != 0.01),
        ("pixel_noise", pixel_noise.is_some()),
    ]
    .into_iter()
    .filter_map(|(k, g)| g.then_some(k))
    .collect();
    let sensor = if images.is_some() {
        activecal::experiment::acts_on::Sensor::Images
    } else {
        activecal::experiment::acts_on::Sensor::Pixels
    };
    crate::calibrate::refuse_unused(activecal::experiment::acts_on::CALIBRATE, &given, sensor)?;
    let (Some(camera_info), Some(target)) = (camera_info, target) else {
        return Err(arg_err(
            if camera_info.is_none() {
                "camera_info"
            } else {
                "target"
            },
            "none given: the camera's intrinsics (a camera_info YAML or dict) and the target (a YAML or dict) are needed",
        ));
    };
    let data = crate::images::pixels_source(py, observations, images, joints)?;
    let outliers = crate::calibrate::outliers_of(outliers, outlier_rate)?;
    if let Some(s) = pixel_noise
        && !(s.is_finite() && s > 0.0)
    {
        return Err(pyo3::exceptions::PyValueError::new_err(format!(
            "pixel_noise={s}: the detector's stated σ per pixel coordinate must be a number > 0 (px)"
        )));
    }
    let (cam0, tgt0) = (
        camera_pose.map(|c| six(py, c, "camera_pose")).transpose()?,
        target_pose.map(|t| six(py, t, "target_pose")).transpose()?,
    );
    let info_src = yaml_source(py, camera_info, "camera_info")?;
    let target_src = yaml_source(py, target, "target")?;
    let mut inputs: Vec<PathBuf> = [&info_src, &target_src]
        .into_iter()
        .filter_map(|s| match s {
            Source::File(p) => Some(p.clone()),
            Source::Text(_) => None,
        })
        .collect();
    inputs.extend(data.files());
    let inner = robot.inner.clone();
    let (cal, report) = crate::progress::with_callback(progress, || {
        detached(py, move || {
            let branch = chain_of(&inner, camera_link.as_deref())?;
            let r = branch.as_ref().unwrap_or(&inner);
            let intrinsics = read_intrinsics(&info_src)?;
            let target_origin = match &target_src {
                Source::File(p) => p.display().to_string(),
                Source::Text(_) => "target".to_string(),
            };
            let target = read_target(&target_src)?;
            let (obs, images) = read_pixels(&data, r, &target, &intrinsics)?;
            let setup = CameraSetup {
                intrinsics,
                target,
                target_origin,
                mounting: m,
                camera_link,
                camera: cam0.map(|c| activecal::options::placement(&c)),
                target_pose: tgt0.map(|t| activecal::options::placement(&t)),
                refine_intrinsics,
                outliers,
                pixel_noise,
            };
            let lm = LmSettings::builder()
                .max_iterations(MAX_ITERATIONS)
                .geodesic(true)
                .build()?;
            let cal = activecal::experiment::camera::calibrate_camera(r, obs, &setup, &lm)
                .map_err(Fail::input)?
                .with_source(images);
            let report = serde_json::to_value(cal.report(Vec::new()))?;
            Ok((cal, report))
        })
    })?;
    // What the command line prints as a note or a warning reaches Python
    // as one.
    let warnings = report["warnings"].as_array().cloned().unwrap_or_default();
    for n in cal
        .notes
        .iter()
        .map(String::as_str)
        .chain(warnings.iter().filter_map(|w| w.as_str()))
    {
        crate::convert::warn(py, n)?;
    }
    Ok(CameraCalibration {
        cal,
        report,
        inputs,
        recipe,
    })
}

/// Reads the observations for the chain `robot`.
pub(crate) fn read_observations(
    s: &Source,
    robot: &activecal::model::Robot,
    target: &activecal::io::camera_target::Target,
    intrinsics: &Intrinsics,
) -> Result<activecal::data::CameraObservations, Fail> {
    use activecal::io::camera_observations::{parse_observations, read_observations};
    let units = activecal::units::Units::default();
    match s {
        Source::File(p) => read_observations(p, robot, target, intrinsics, units),
        Source::Text(t) => parse_observations(t, "observations", robot, target, intrinsics, units),
    }
    .map_err(|e| named("observations", e))
}

/// The camera's observations for the chain `robot`: read, or detected
/// in the images by the library (as `calibrate --images` does), with
/// where they came from (for images, what became of each: the report's
/// `images`).
pub(crate) fn read_pixels(
    data: &PixelsSource,
    robot: &activecal::model::Robot,
    target: &activecal::io::camera_target::Target,
    intrinsics: &activecal::options::Intrinsics,
) -> Result<
    (
        activecal::data::CameraObservations,
        activecal::experiment::camera::CameraSource,
    ),
    Fail,
> {
    let (origin, spec, joints) = match data {
        PixelsSource::Observations(s) => {
            return read_observations(s, robot, target, intrinsics)
                .map(|o| (o, activecal::experiment::camera::CameraSource::Pixels));
        }
        PixelsSource::Images {
            origin,
            spec,
            joints,
        } => (origin, spec, joints),
    };
    use activecal::io::images::joints::{parse_image_joints, read_image_joints};
    let units = activecal::units::Units::default();
    let j = match joints {
        Source::File(p) => read_image_joints(p, robot, units),
        Source::Text(t) => parse_image_joints(t, "the DataFrame", robot, units),
    }
    .map_err(|e| named("joints", e))?;
    let files = match spec {
        ImagesSpec::Spec(s) => {
            activecal::io::images::files::image_files(s).map_err(|e| named("images", e))?
        }
        ImagesSpec::Files(f) => f.clone(),
    };
    let read = activecal::io::images::read_image_list(origin, files, &j, target, intrinsics)
        .map_err(|e| named("images", e))?;
    Ok((
        read.observations,
        activecal::experiment::camera::CameraSource::Images(read.images),
    ))
}

impl CameraCalibration {
    /// The files the call read (observations, camera_info, target given as
    /// paths): never written over.
    fn inputs(&self) -> Vec<&Path> {
        self.inputs.iter().map(PathBuf::as_path).collect()
    }

    /// Refuses to write what the library refuses (a fit that did not
    /// converge or cannot be right), with its reason.
    fn check_converged(&self, path: &Path) -> PyResult<()> {
        match self.cal.verdict.refusal() {
            None => Ok(()),
            Some(why) => {
                Err(Fail::Compute(format!("{}: not written: {why}", path.display())).into_py())
            }
        }
    }

    /// Writes the calibrated robot to `path` ([`CameraCalibration::write_robot`]).
    fn write_as(&self, format: Format, path: &Path, overwrite: bool) -> PyResult<()> {
        self.check_converged(path)?;
        let out = activecal::io::atomic::Output {
            label: "path",
            path,
        };
        self.cal
            .write_robot(format, out, overwrite, &self.inputs())
            .map_err(|e| Fail::from(e).into_py())
    }

    /// A placement of the `camera` block (`which`: "camera" or "target")
    /// as a 4×4 homogeneous matrix.
    fn placement<'py>(&self, py: Python<'py>, which: &str) -> PyResult<Option<Bound<'py, PyAny>>> {
        let Some(c) = self.cal.frames.as_ref().and_then(|f| f.1.camera.as_ref()) else {
            return Ok(None);
        };
        let b = if which == "camera" {
            &c.camera
        } else {
            &c.target
        };
        let (t, r) = (b.xyz, b.rpy);
        let m =
            activecal::options::placement(&[t[0], t[1], t[2], r[0], r[1], r[2]]).to_homogeneous();
        let rows: Vec<f64> = (0..4)
            .flat_map(|i| (0..4).map(move |j| (i, j)))
            .map(|(i, j)| m[(i, j)])
            .collect();
        ndarray(py, &rows, &[4, 4]).map(Some)
    }
}

#[pymethods]
impl CameraCalibration {
    /// Pickling: the call that made it, made again on loading.
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, pyo3::types::PyTuple>> {
        self.recipe.reduce(py)
    }

    /// Whether the fit converged.
    #[getter]
    fn converged(&self) -> bool {
        self.cal.fit.converged
    }

    /// Why the calibration may not be written (None when it may): the
    /// same reason the command line refuses it with (exit status 3).
    #[getter]
    fn refused(&self) -> Option<String> {
        self.cal.verdict.refusal().map(str::to_string)
    }

    /// The estimate {name: value}: the robot's unknowns (metres, radians),
    /// `camera_x … target_rz`, and the refined intrinsics (px, unitless).
    #[getter]
    fn estimate(&self) -> std::collections::BTreeMap<String, f64> {
        let f = &self.cal.fit;
        f.names
            .iter()
            .cloned()
            .zip(f.estimate.iter().copied())
            .collect()
    }

    /// Standard deviations of the estimate {name: σ}; None without a
    /// covariance.
    #[getter]
    fn sigma(&self) -> Option<std::collections::BTreeMap<String, f64>> {
        let f = &self.cal.fit;
        f.std
            .as_ref()
            .map(|s| f.names.iter().cloned().zip(s.iter().copied()).collect())
    }

    /// The pixel noise σ the fit estimated from its residuals, px (None
    /// without degrees of freedom).
    #[getter]
    fn sigma_px(&self) -> Option<f64> {
        self.cal.fit.sigma_px
    }

    /// The RMS pixel error calibrated, px.
    #[getter]
    fn rms_px(&self) -> f64 {
        self.cal.fit.rms_px
    }

    /// The camera's optical frame (x right, y down, z forward) in its link
    /// (`report["camera"]["camera"]["parent"]`: the base link, the tip
    /// link or the camera's own link), a 4×4 matrix (metres); None for a
    /// robot not imported from a URDF.
    #[getter]
    fn camera<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.placement(py, "camera")
    }

    /// The target's frame in its link (`report["camera"]["target"]
    /// ["parent"]`), a 4×4 matrix (metres); None as for `camera`.
    #[getter]
    fn target<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.placement(py, "target")
    }

    /// The whole report: the dict `activecal calibrate --observations FILE
    /// --json` prints (`out` empty: files are written by the methods).
    #[getter]
    fn report<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, &self.report)
    }

    /// Writes your URDF with the calibrated joint origins (URDF robots;
    /// refused when the fit did not converge).
    #[pyo3(signature = (path, overwrite=true))]
    fn write_urdf(&self, path: PathBuf, overwrite: bool) -> PyResult<()> {
        self.write_as(Format::Urdf, &path, overwrite)
    }

    /// Writes the frames file (YAML) with the `camera` block: the
    /// camera's and the target's placements with σ, the pixel σ and RMS.
    #[pyo3(signature = (path, overwrite=true))]
    fn write_frames(&self, path: PathBuf, overwrite: bool) -> PyResult<()> {
        self.write_as(Format::Yaml, &path, overwrite)
    }

    /// Writes the refined intrinsics as a ROS camera_info YAML (only with
    /// refine_intrinsics=True and a converged fit), as `--out-camera-info`
    /// does: the camera named by the file's stem.
    #[pyo3(signature = (path, overwrite=true))]
    fn write_camera_info(&self, path: PathBuf, overwrite: bool) -> PyResult<()> {
        if !self.cal.refine_intrinsics {
            return Err(arg_err(
                "path",
                format!(
                    "{}: the intrinsics were not refined (calibrate_camera(..., refine_intrinsics=True))",
                    path.display()
                ),
            ));
        }
        self.check_converged(&path)?;
        let out = activecal::io::atomic::Output {
            label: "path",
            path: &path,
        };
        self.cal
            .write_camera_info(
                out,
                &self.cal.observations.origin,
                overwrite,
                &self.inputs(),
            )
            .map_err(|e| Fail::from(e).into_py())
    }

    fn __repr__(&self) -> String {
        format!(
            "CameraCalibration({:?}, {} poses, rms {:.3} px, converged={})",
            self.cal.robot_name,
            self.cal.observations.qs.len(),
            self.cal.fit.rms_px,
            self.cal.fit.converged
        )
    }
}

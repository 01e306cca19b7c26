//! `activecal.select_camera`: poses chosen for a camera, as `activecal
//! select --camera-info ...` chooses them (without collision filters or a
//! line of sight), and the `CameraDesign` it returns.

use crate::camera::{chain_of, mounting_of, read_intrinsics, read_target, six, yaml_source};
use crate::convert::{Fail, detached, json_to_py, ndarray, non_negative};
use crate::robot::Robot;
use activecal::model::robot_ref::RobotRef;
use activecal::pool::camera_view::CameraView;
use activecal::report::{CameraDesignReport, CameraPoolInfo};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// A design for a camera: the chosen configurations, the points each will
/// see, and the report.
#[pyclass(module = "activecal", name = "CameraDesign", frozen)]
pub struct CameraDesign {
    joint_names: Vec<String>,
    report: serde_json::Value,
    qs: Vec<Vec<f64>>,
    candidates: Vec<usize>,
    seen: Vec<usize>,
}

/// The robot as its reference names it (`robot`, `chain` of the report):
/// the name a robot is loaded under is its reference's text form.
fn reference(
    robot: &activecal::model::Robot,
) -> (String, activecal::model::robot_ref::ChainChoice) {
    RobotRef::parse(&robot.name).map_or_else(
        |_| (robot.name.clone(), Default::default()),
        |r| (r.head(), r.chain),
    )
}

/// Chooses `n` poses for a camera that sees a target, as `activecal select
/// --camera-info ... --json` does with the same files and options
/// (without collision filters or a line of sight).
///
/// camera_info, target, mounting, camera_link, camera_pose, target_pose
/// as `calibrate_camera` takes them (the placements are where the camera
/// and the target are, not rough guesses). count: joint-space samples
/// (pool_seed their seed); a sample is kept where at least min_visible of
/// the target's points are image_margin px inside the image, the target
/// faces the camera within max_view_angle degrees and lies within
/// distance (lo, hi) metres. n of them are chosen D-optimally on the pixel
/// Jacobian (seed: the search's, default 1 as the command line's). gap:
/// score the design against its visible pool's certified bound (slow: a
/// minute or two on large pools). progress as `select` takes it.
#[pyfunction]
#[pyo3(signature = (robot, camera_info, target, *, n, camera_pose, target_pose, mounting=None, camera_link=None, count=20000, pool_seed=0, seed=1, min_visible=1.0, image_margin=10.0, max_view_angle=60.0, distance=(0.2, 3.0), gap=false, progress=None))]
#[allow(clippy::too_many_arguments)]
pub fn select_camera(
    py: Python<'_>,
    robot: &Robot,
    camera_info: &Bound<'_, PyAny>,
    target: &Bound<'_, PyAny>,
    n: i64,
    camera_pose: &Bound<'_, PyAny>,
    target_pose: &Bound<'_, PyAny>,
    mounting: Option<&str>,
    camera_link: Option<String>,
    count: i64,
    pool_seed: i128,
    seed: i128,
    min_visible: f64,
    image_margin: f64,
    max_view_angle: f64,
    distance: (f64, f64),
    gap: bool,
    progress: Option<&Bound<'_, PyAny>>,
) -> PyResult<CameraDesign> {
    let m = mounting_of(mounting, camera_link.as_deref())?;
    let n = crate::convert::count("n", n, 1)?;
    let samples = crate::convert::count("count", count, 1)?;
    let pool_seed = non_negative("pool_seed", pool_seed)?;
    let seed = non_negative("seed", seed)?;
    let (cam, tgt) = (
        six(py, camera_pose, "camera_pose")?,
        six(py, target_pose, "target_pose")?,
    );
    let info_src = yaml_source(py, camera_info, "camera_info")?;
    let target_src = yaml_source(py, target, "target")?;
    let inner = robot.inner.clone();
    let (d, report, joint_names) = crate::progress::with_callback(progress, || {
        detached(py, move || {
            let branch = chain_of(&inner, camera_link.as_deref())?;
            let r = branch.as_ref().unwrap_or(&inner);
            let board = read_target(&target_src)?;
            let view = CameraView {
                intrinsics: read_intrinsics(&info_src)?,
                mounting: m,
                points: board.points.iter().map(|p| [p.x, p.y, p.z]).collect(),
                face: board.face.into(),
                camera: cam,
                target: tgt,
                min_fraction: min_visible,
                margin_px: image_margin,
                max_view_angle: max_view_angle.to_radians(),
                distance: [distance.0, distance.1],
            };
            view.validate()
                .map_err(|e| Fail::Input(format!("camera view: {e}")))?;
            let candidates =
                activecal::observability::generic_configurations(r, samples, pool_seed);
            let settings = activecal::select::Settings::builder()
                .n(n)
                .seed(seed)
                .build()?;
            let d = activecal::select::camera::camera_design(r, &view, &candidates, &settings)?;
            let g = if gap {
                Some(d.gap(&activecal::bound::BoundSettings::default())?)
            } else {
                None
            };
            let (name, chain) = reference(&inner);
            let pool = CameraPoolInfo {
                robot: name,
                chain,
                camera_link,
                candidates: candidates.len(),
                pool_seed,
                collision_removed: None,
                pixel_noise: None,
            };
            let names = activecal::units::joint_names(r);
            let report = CameraDesignReport::new(&d, pool, m, names.clone(), g);
            let mut v = serde_json::to_value(&report)?;
            v["out"] = serde_json::json!([]);
            Ok((d, v, names))
        })
    })?;
    Ok(CameraDesign {
        joint_names,
        report,
        qs: d.qs,
        candidates: d.candidates,
        seen: d.seen,
    })
}

#[pymethods]
impl CameraDesign {
    /// The chosen configurations, an (n, dof) array (radians, metres), in
    /// the order chosen.
    #[getter]
    fn q<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let v: Vec<f64> = self.qs.iter().flatten().copied().collect();
        ndarray(py, &v, &[self.qs.len(), self.joint_names.len()])
    }

    /// Each chosen configuration's index in the samples.
    #[getter]
    fn candidates(&self) -> Vec<usize> {
        self.candidates.clone()
    }

    /// The target points each chosen configuration will see.
    #[getter]
    fn points_seen(&self) -> Vec<usize> {
        self.seen.clone()
    }

    /// The joints' names, the columns of `q`.
    #[getter]
    fn joint_names(&self) -> Vec<String> {
        self.joint_names.clone()
    }

    /// The chosen poses as a pandas DataFrame, the columns of `select
    /// --out design.csv`: candidate, the joints, points_seen.
    #[getter]
    fn poses<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let pd = py.import("pandas")?;
        let data = PyDict::new(py);
        data.set_item("candidate", self.candidates.clone())?;
        for (j, name) in self.joint_names.iter().enumerate() {
            let col: Vec<f64> = self.qs.iter().map(|q| q[j]).collect();
            data.set_item(name, col)?;
        }
        data.set_item("points_seen", self.seen.clone())?;
        pd.call_method1("DataFrame", (data,))
    }

    /// The whole report: the dict `activecal select --camera-info ...
    /// --json` prints (`out` empty).
    #[getter]
    fn report<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, &self.report)
    }

    fn __repr__(&self) -> String {
        format!(
            "CameraDesign({} poses, ln det {})",
            self.qs.len(),
            self.report["ln_det"]
        )
    }
}

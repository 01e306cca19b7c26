//! `activecal.select_camera`: poses chosen for a camera, as `activecal
//! select --camera-info ...` chooses them (with its collision filters and
//! line of sight), and the `CameraDesign` it returns.

use crate::camera::{chain_of, mounting_of, read_intrinsics, read_target, six, yaml_source};
use crate::convert::{Fail, arg_err, detached, json_to_py, ndarray, non_negative};
use crate::robot::Robot;
use activecal::experiment::camera_select::{
    CameraSelectPlan, CameraSelection, Candidates, DEFAULT_PIXEL_NOISE,
};
use activecal::model::robot_ref::{ChainChoice, RobotRef};
use activecal::options::CameraView;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// A design for a camera: the chosen configurations, the points each will
/// see, and the report.
#[pyclass(module = "activecal", name = "CameraDesign", frozen)]
pub struct CameraDesign {
    /// The library's design with its report (its visible pool's blocks,
    /// for `how_many`).
    sel: std::sync::Arc<CameraSelection>,
    /// The report as `select --camera-info ... --json` prints it.
    report: serde_json::Value,
}

/// The robot as its reference names it (`robot`, `chain` of the report):
/// the name a robot is loaded under is its reference's text form.
fn reference(robot: &activecal::model::Robot) -> (String, ChainChoice) {
    RobotRef::parse(&robot.name).map_or_else(
        |_| (robot.name.clone(), ChainChoice::default()),
        |r| (r.head(), r.chain),
    )
}

/// Chooses `n` poses for a camera that sees a target, as `activecal select
/// --camera-info ... --json` does with the same files and options.
///
/// camera_info, target, mounting, camera_link, camera_pose, target_pose
/// as `calibrate_camera` takes them (the placements are where the camera
/// and the target are, not rough guesses). count: joint-space samples
/// (pool_seed their seed); a sample is kept where at least min_visible of
/// the target's points are image_margin px inside the image, the target
/// faces the camera within max_view_angle degrees and lies within
/// distance (lo, hi) metres. n of them are chosen D-optimally on the pixel
/// Jacobian (seed: the search's, default 1 as the command line's). gap:
/// score the design against its visible pool's certified bound (about a
/// second: a pose's pixel rows are cut to their rank, 6). pixel_noise: the
/// detected points' σ (px): the report then also predicts the true error
/// at it (`predicted_error_mm`). line_of_sight: keep the configurations
/// whose rays to the points the robot's collision geometry does not block
/// (on with any of self_collision, srdf, floor, obstacles, which also
/// remove colliding samples; meshes in package_dirs). progress as
/// `select` takes it.
#[pyfunction]
#[pyo3(signature = (robot, camera_info, target, *, n, camera_pose, target_pose, mounting=None, camera_link=None, count=20000, pool_seed=0, seed=1, min_visible=1.0, image_margin=10.0, max_view_angle=60.0, distance=(0.2, 3.0), gap=false, pixel_noise=None, line_of_sight=false, self_collision=false, srdf=None, package_dirs=None, floor=None, obstacles=None, progress=None))]
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
    pixel_noise: Option<f64>,
    line_of_sight: bool,
    self_collision: bool,
    srdf: Option<std::path::PathBuf>,
    package_dirs: Option<Vec<std::path::PathBuf>>,
    floor: Option<f64>,
    obstacles: Option<Vec<String>>,
    progress: Option<&Bound<'_, PyAny>>,
) -> PyResult<CameraDesign> {
    check_pixel_noise(pixel_noise)?;
    let choice = crate::pool::collision_choice(
        self_collision,
        srdf.map(|p| p.display().to_string()),
        package_dirs
            .unwrap_or_default()
            .iter()
            .map(|p| p.display().to_string())
            .collect(),
        floor,
        obstacles.unwrap_or_default(),
        0.0,
    )?;
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
    if let Some(l) = camera_link.as_deref() {
        chain_of(&inner, Some(l)).map_err(Fail::into_py)?;
    }
    let sel = crate::progress::with_callback(progress, || {
        detached(py, move || {
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
            let (robot_name, chain) = reference(&inner);
            let plan = CameraSelectPlan {
                view,
                camera_link,
                collision: choice,
                line_of_sight,
                candidates: Candidates::Sampled {
                    count: samples,
                    seed: pool_seed,
                },
                settings: activecal::options::SelectSettings::builder()
                    .n(n)
                    .seed(seed)
                    .build()?,
                gap: gap.then(activecal::options::BoundSettings::default),
                pixel_noise,
                robot_name,
                chain,
            };
            Ok(activecal::experiment::camera_select::select_camera(
                &inner, plan,
            )?)
        })
    })?;
    let mut report = sel.report.clone();
    report.out = Some(Vec::new());
    let report = serde_json::to_value(&report).map_err(|e| Fail::from(e).into_py())?;
    Ok(CameraDesign {
        sel: std::sync::Arc::new(sel),
        report,
    })
}

/// Refuses a pixel noise that is not a finite number > 0.
fn check_pixel_noise(pixel_noise: Option<f64>) -> PyResult<()> {
    match pixel_noise {
        Some(px) if !(px.is_finite() && px > 0.0) => Err(arg_err(
            "pixel_noise",
            format!("{px}: the pixel noise σ must be a finite number > 0 (px)"),
        )),
        _ => Ok(()),
    }
}

/// Refuses a pixel noise that is not a finite number > 0 and a
/// `target_error` that is not a finite number > 0 (mm).
fn check_curve_args(pixel_noise: Option<f64>, target_error: Option<f64>) -> PyResult<()> {
    check_pixel_noise(pixel_noise)?;
    match target_error {
        Some(t) if !(t.is_finite() && t > 0.0) => Err(arg_err(
            "target_error",
            format!("{t}: the position error to reach must be a finite number > 0 (mm)"),
        )),
        _ => Ok(()),
    }
}

impl CameraDesign {
    /// The "how many poses" curve at `pixel_noise` (the design's, else the
    /// default) and `target_error`, as `select --report` computes it.
    fn curve(
        &self,
        pixel_noise: Option<f64>,
        target_error: Option<f64>,
    ) -> Result<activecal::report::PoseCountCurve, Fail> {
        let noise = pixel_noise
            .or(self.sel.pixel_noise)
            .unwrap_or(DEFAULT_PIXEL_NOISE);
        let bound = activecal::options::BoundSettings::default();
        self.sel
            .curve(bound, noise, target_error)
            .map_err(|e| match e {
                activecal::experiment::error::HowManyError::Input(e) => Fail::from(e),
                activecal::experiment::error::HowManyError::Bound(e) => e.into(),
            })
    }

    /// Writes `select --camera-info ... --report`'s folder into `dir`.
    fn folder(
        &self,
        dir: &std::path::Path,
        pixel_noise: Option<f64>,
        target_error: Option<f64>,
    ) -> Result<(), Fail> {
        let curve = self.curve(pixel_noise, target_error)?;
        let noise_is_default = pixel_noise.or(self.sel.pixel_noise).is_none();
        self.sel.write_report(dir, &curve, &[], noise_is_default)?;
        Ok(())
    }
}

#[pymethods]
impl CameraDesign {
    /// The chosen configurations, an (n, dof) array (radians, metres), in
    /// the order chosen.
    #[getter]
    fn q<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let qs = &self.sel.design.qs;
        let v: Vec<f64> = qs.iter().flatten().copied().collect();
        ndarray(py, &v, &[qs.len(), self.sel.joint_names.len()])
    }

    /// Each chosen configuration's index in the samples.
    #[getter]
    fn candidates(&self) -> Vec<usize> {
        self.sel.design.candidates.clone()
    }

    /// The target points each chosen configuration will see.
    #[getter]
    fn points_seen(&self) -> Vec<usize> {
        self.sel.design.seen.clone()
    }

    /// The joints' names, the columns of `q`.
    #[getter]
    fn joint_names(&self) -> Vec<String> {
        self.sel.joint_names.clone()
    }

    /// The chosen poses as a pandas DataFrame, the columns of `select
    /// --out design.csv`: candidate, the joints, points_seen.
    #[getter]
    fn poses<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let pd = py.import("pandas")?;
        let data = PyDict::new(py);
        let d = &self.sel.design;
        data.set_item("candidate", d.candidates.clone())?;
        for (j, name) in self.sel.joint_names.iter().enumerate() {
            let col: Vec<f64> = d.qs.iter().map(|q| q[j]).collect();
            data.set_item(name, col)?;
        }
        data.set_item("points_seen", d.seen.clone())?;
        pd.call_method1("DataFrame", (data,))
    }

    /// "How many poses" on this design's visible pool: the dict `activecal
    /// select --camera-info ... --report DIR` writes as `how_many_poses` in
    /// report.json (`n_min` = ⌈p / 6⌉, `points` with `n`, `d_efficiency`,
    /// `predicted` true errors in mm, `noise_px`, `recommended`), for a
    /// pixel noise σ `pixel_noise` (px; the design's, else 0.3) and, with
    /// `target_error` (mm), the fewest poses predicted to reach it.
    #[pyo3(signature = (pixel_noise=None, target_error=None, progress=None))]
    fn how_many<'py>(
        &self,
        py: Python<'py>,
        pixel_noise: Option<f64>,
        target_error: Option<f64>,
        progress: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        check_curve_args(pixel_noise, target_error)?;
        let v = crate::progress::with_callback(progress, || {
            detached(py, || {
                let curve = self.curve(pixel_noise, target_error)?;
                Ok(serde_json::to_value(&curve)?)
            })
        })?;
        json_to_py(py, &v)
    }

    /// The report folder `activecal select --camera-info ... --report DIR`
    /// writes for this design, written into `path`: report.md,
    /// report.json, the figures (PNG and SVG) and `index.html`, the 3D page
    /// of the poses with the camera's field of view, the board and the
    /// lines of sight checked. Computes the "how many poses" curve (see
    /// `how_many`: pixel_noise, target_error and progress as it takes
    /// them; seconds to minutes). An existing directory is replaced whole;
    /// overwrite=False refuses a non-empty one with `FileError`.
    #[pyo3(signature = (path, overwrite=true, pixel_noise=None, target_error=None, progress=None))]
    fn write_report(
        &self,
        py: Python<'_>,
        path: std::path::PathBuf,
        overwrite: bool,
        pixel_noise: Option<f64>,
        target_error: Option<f64>,
        progress: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        check_curve_args(pixel_noise, target_error)?;
        let inputs = crate::page::robot_inputs(&self.sel.robot);
        crate::progress::with_callback(progress, || {
            crate::page::write_folder(py, &path, overwrite, &inputs, |dir| {
                self.folder(dir, pixel_noise, target_error)
            })
        })
    }

    /// The 3D page of `write_report`'s folder (`index.html`), shown inline
    /// by Jupyter (a `Page`; its `html` is the page's text, byte for byte
    /// the command line's). pixel_noise and progress as `write_report`
    /// takes them.
    #[pyo3(signature = (pixel_noise=None, progress=None))]
    fn show(
        &self,
        py: Python<'_>,
        pixel_noise: Option<f64>,
        progress: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<crate::page::Page> {
        check_curve_args(pixel_noise, None)?;
        crate::progress::with_callback(progress, || {
            crate::page::page_of(py, |dir| self.folder(dir, pixel_noise, None))
        })
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
            self.sel.design.qs.len(),
            self.report["ln_det"]
        )
    }
}

//! `show()` and `write_report()` of `Design` and `Calibration`: the report
//! folder of `select --report` and `calibrate --report` (report.md,
//! report.json, the figures and the 3D page `index.html`), written by the
//! library's renderer (`activecal::render::folder`), and its page shown
//! inline in Jupyter by a `Page`. Nothing of the page is assembled here.

use crate::convert::{Fail, arg_err, detached};
use activecal::experiment::Identification;
use activecal::experiment::error::HowManyError;
use activecal::experiment::select::{CurveOf, how_many_curve};
use activecal::model::ParamSet;
use activecal::model::Robot;
use activecal::options::{Algorithm, CriterionKind, SelectSettings as Settings};
use activecal::render::summary::{CalibrationSummary, FitPoses};
use activecal::report::PoseCountCurve;
use activecal::report::SelectReport;
use pyo3::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

/// Height of the page's frame in a notebook (CSS pixels).
const FRAME_HEIGHT_PX: u32 = 720;

/// A report's 3D page (`index.html` of its report folder): self-contained
/// HTML that opens from a file, and is shown inline by Jupyter.
#[pyclass(module = "activecal", name = "Page", frozen)]
pub struct Page {
    html: String,
}

#[pymethods]
impl Page {
    /// The page's HTML text (what `index.html` of the report folder holds).
    #[getter]
    fn html(&self) -> String {
        self.html.clone()
    }

    /// Jupyter's inline display: the page in a frame (`srcdoc`: the page
    /// needs no file or network).
    fn _repr_html_(&self) -> String {
        let doc = activecal::render::page::encode::html(&self.html);
        format!(
            "<iframe srcdoc=\"{doc}\" style=\"width: 100%; height: {FRAME_HEIGHT_PX}px; border: 0\"></iframe>"
        )
    }

    /// Writes the page alone (`index.html` of the report folder) to `path`.
    /// An existing file is replaced; overwrite=False refuses it with
    /// `FileError`.
    #[pyo3(signature = (path, overwrite=true))]
    fn write(&self, path: PathBuf, overwrite: bool) -> PyResult<()> {
        let outs = [activecal::io::atomic::Output {
            label: "path",
            path: &path,
        }];
        activecal::io::atomic::check_outputs(&outs, &[], overwrite)
            .and_then(|()| activecal::io::atomic::write_atomic(&path, self.html.as_bytes()))
            .map_err(|e| Fail::from(e).into_py())
    }

    fn __repr__(&self) -> String {
        format!("Page({} bytes of HTML)", self.html.len())
    }
}

/// Refuses `dir` (argument `path`) when it is or holds one of `inputs`
/// (labelled: it is replaced whole, even with `overwrite`), is not a
/// directory, or is a non-empty one and `overwrite` is false; its parent
/// must exist.
fn check_dir(dir: &Path, overwrite: bool, inputs: &[(&str, PathBuf)]) -> PyResult<()> {
    let mut files = activecal::io::run_files::RunFiles::new();
    for (label, path) in inputs {
        files.input(label, Some(path));
    }
    files.dir("path", Some(dir));
    files.check(overwrite).map_err(|e| match e {
        activecal::Error::Invalid(m) => Fail::File(m).into_py(),
        e => Fail::from(e).into_py(),
    })
}

/// The files a report folder reads of `robot`: its description.
pub(crate) fn robot_inputs(robot: &Robot) -> Vec<(&'static str, PathBuf)> {
    robot
        .source
        .iter()
        .map(|s| ("the robot's description", PathBuf::from(&s.path)))
        .collect()
}

/// Writes a report folder into `dir` (checked as [`check_dir`] says,
/// against the files it reads, `inputs`).
pub(crate) fn write_folder(
    py: Python<'_>,
    dir: &Path,
    overwrite: bool,
    inputs: &[(&str, PathBuf)],
    write: impl FnOnce(&Path) -> Result<(), Fail> + Send,
) -> PyResult<()> {
    check_dir(dir, overwrite, inputs)?;
    detached(py, || write(dir))
}

/// The page of a report folder written aside (in the temporary directory,
/// removed after).
pub(crate) fn page_of(
    py: Python<'_>,
    write: impl FnOnce(&Path) -> Result<(), Fail> + Send,
) -> PyResult<Page> {
    static CALLS: AtomicUsize = AtomicUsize::new(0);
    let n = CALLS.fetch_add(1, Ordering::Relaxed);
    let aside = std::env::temp_dir().join(format!(".activecal-page-{}-{n}", std::process::id()));
    let html = detached(py, || {
        let dir = aside.join("report");
        let made = std::fs::create_dir_all(&aside)
            .map_err(|e| Fail::File(format!("{}: {e}", aside.display())))
            .and_then(|()| write(&dir))
            .and_then(|()| {
                let index = dir.join("index.html");
                std::fs::read_to_string(&index)
                    .map_err(|e| Fail::File(format!("{}: {e}", index.display())))
            });
        let _ = std::fs::remove_dir_all(&aside);
        made
    })?;
    Ok(Page { html })
}

/// What the how-many curve of a design is computed from (the selection's
/// settings and pool).
pub(crate) struct CurveInputs {
    /// The robot (nominal parameters).
    pub robot: std::sync::Arc<Robot>,
    /// The pool's Jacobian.
    pub x: std::sync::Arc<activecal::experiment::Blocks>,
    /// The pool's ids, by position.
    pub ids: Vec<usize>,
    /// The selection's settings.
    pub settings: Settings,
    /// Its algorithm.
    pub algorithm: Algorithm,
    /// The design's size.
    pub n: usize,
}

/// Checks the curve's `noise` (metres) and `target_error` (mm).
pub(crate) fn check_curve_args(noise: f64, target_error: Option<f64>) -> PyResult<()> {
    if !(noise.is_finite() && noise > 0.0) {
        return Err(arg_err(
            "noise",
            format!("{noise}: the sensor noise σ must be a finite number > 0 (metres)"),
        ));
    }
    if let Some(t) = target_error.filter(|t| !(t.is_finite() && *t > 0.0)) {
        return Err(arg_err(
            "target_error",
            format!("{t}: the position error to reach must be a finite number > 0 (mm)"),
        ));
    }
    Ok(())
}

impl CurveInputs {
    /// The "how many poses" curve, as `select --report` computes it.
    pub(crate) fn curve(
        &self,
        noise: f64,
        target_error: Option<f64>,
    ) -> Result<PoseCountCurve, Fail> {
        let on = CurveOf {
            robot: &self.robot,
            params: ParamSet::Nominal,
            x: &self.x,
            ids: &self.ids,
            settings: &self.settings,
            criterion: CriterionKind::Det,
            algorithm: self.algorithm,
            n: self.n,
        };
        how_many_curve(on, noise, target_error).map_err(|e| match e {
            HowManyError::Input(e) => Fail::from(e),
            HowManyError::Bound(e) => e.into(),
        })
    }

    /// Writes `select --report`'s folder for `report` into `dir`.
    pub(crate) fn selection_folder(
        &self,
        dir: &Path,
        report: &SelectReport,
        noise: Option<f64>,
        default_noise: f64,
        target_error: Option<f64>,
    ) -> Result<(), Fail> {
        let curve = self.curve(noise.unwrap_or(default_noise), target_error)?;
        activecal::render::folder::selection(dir, &self.robot, report, &curve, noise.is_none())?;
        Ok(())
    }
}

/// A calibration's summary kept for its report folder (all but the robot
/// and the fit, which the result keeps).
#[derive(Clone, Debug)]
pub(crate) struct KeptSummary {
    source: String,
    what: &'static str,
    position_mm: (Vec<f64>, Vec<f64>),
    orientation_deg: Option<(Vec<f64>, Vec<f64>)>,
    params: Vec<(String, f64, Option<f64>)>,
    splits: Option<(Vec<f64>, Vec<f64>)>,
    notes: Vec<String>,
    json: serde_json::Value,
    poses: Option<FitPoses>,
}

impl KeptSummary {
    /// Keeps `s`.
    pub(crate) fn keep(s: CalibrationSummary<'_>) -> Self {
        Self {
            source: s.source,
            what: s.what,
            position_mm: s.position_mm,
            orientation_deg: s.orientation_deg,
            params: s.params,
            splits: s.splits,
            notes: s.notes,
            json: s.json,
            poses: s.poses,
        }
    }

    /// Writes `calibrate --report`'s folder into `dir`.
    pub(crate) fn folder(
        &self,
        dir: &Path,
        robot: &Robot,
        id: &Identification,
    ) -> Result<(), Fail> {
        let s = CalibrationSummary {
            robot,
            id,
            source: self.source.clone(),
            what: self.what,
            position_mm: self.position_mm.clone(),
            orientation_deg: self.orientation_deg.clone(),
            params: self.params.clone(),
            splits: self.splits.clone(),
            notes: self.notes.clone(),
            json: self.json.clone(),
            poses: self.poses.clone(),
        };
        activecal::render::folder::calibration(dir, &s)?;
        Ok(())
    }
}

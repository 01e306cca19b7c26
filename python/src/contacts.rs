//! `activecal.calibrate_contacts`: calibration from configurations at which
//! the tool touched named points (sockets), with distances known between
//! some of them, as `activecal calibrate --measurements FILE` does for a
//! contact file; and the `ContactCalibration` it returns.

use crate::convert::{Fail, arg_err, count, detached, float_array, json_to_py, rows};
use crate::robot::Robot;
use activecal::data::{ContactFile, NamedDistance};
use activecal::experiment::contact_run::{ContactOutError, ContactRequest, ContactRun, run};
use activecal::write::calibrated::Format;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::sync::Arc;

/// A calibration from contacts: the estimate with its σ, the fitted points
/// and tool offset, the figures that judge it, and the calibrated robot to
/// write.
#[pyclass(module = "activecal", name = "ContactCalibration", frozen)]
pub struct ContactCalibration {
    robot: Arc<activecal::model::Robot>,
    c: ContactRun,
    report: serde_json::Value,
    /// How it was made, for pickling.
    recipe: crate::pickling::Recipe,
}

/// The distances argument: a dict {(a, b): metres} or pairs (a, b, metres).
fn distances_of(d: &Bound<'_, PyAny>) -> PyResult<Vec<NamedDistance>> {
    let bad = || {
        arg_err(
            "distances",
            "a dict {(a, b): metres} or a list of (a, b, metres): point names and a length in metres",
        )
    };
    let items: Vec<(String, String, f64)> = if let Ok(m) = d.cast::<PyDict>() {
        m.iter()
            .map(|(k, v)| {
                let (a, b): (String, String) = k.extract().map_err(|_| bad())?;
                Ok((a, b, v.extract().map_err(|_| bad())?))
            })
            .collect::<PyResult<_>>()?
    } else {
        d.extract().map_err(|_| bad())?
    };
    Ok(items
        .into_iter()
        .map(|(a, b, metres)| NamedDistance { a, b, metres })
        .collect())
}

/// The rows as a contact file: each configuration of `q` and the point it
/// touches, the points in order of first appearance.
fn contact_file(qs: Vec<Vec<f64>>, touched: Vec<String>) -> ContactFile {
    let mut points: Vec<String> = Vec::new();
    let groups = touched
        .iter()
        .map(|n| {
            points.iter().position(|p| p == n).unwrap_or_else(|| {
                points.push(n.clone());
                points.len() - 1
            })
        })
        .collect();
    ContactFile {
        origin: "the arrays given".into(),
        lines: (1..=qs.len()).collect(),
        qs,
        groups,
        points,
        planes: Vec::new(),
    }
}

/// Calibrates the robot from contacts, as `activecal calibrate
/// --measurements FILE --point-distance A,B=M --json` does with a contact
/// file holding the same rows.
///
/// q: (n, dof) joint values (radians or metres) at which the tool point
/// (the chain's tip, a ball centre) touched a fixed point. points: n point
/// names, the one each row touched (a socket; "placement/k" names group
/// sockets of one block for held-out figures). distances: the lengths known
/// between points (metres), a dict {(a, b): m} or a list of (a, b, m); at
/// least one, since contacts alone leave the scale free. free: parameters
/// never fixed. max_iterations, loss and loss_scale as `calibrate` takes
/// them; progress too. outliers: "drop" (default: rows with a gross error,
/// a ball seated off its socket, found by Baarda's data snooping at
/// family-wise rate outlier_rate, left out one at a time and listed in
/// `report["outliers"]`) or "keep", as `--outliers`; what the test did is
/// in `report["notes"]` and emitted as `warnings.warn`.
#[pyfunction]
#[pyo3(signature = (robot, q, points, distances, free=None, max_iterations=200, loss="l2", loss_scale=None, outliers="drop", outlier_rate=0.01, progress=None))]
#[allow(clippy::too_many_arguments)]
pub fn calibrate_contacts(
    py: Python<'_>,
    robot: &Bound<'_, Robot>,
    q: &Bound<'_, PyAny>,
    points: Vec<String>,
    distances: &Bound<'_, PyAny>,
    free: Option<Vec<String>>,
    max_iterations: i64,
    loss: &str,
    loss_scale: Option<f64>,
    outliers: &str,
    outlier_rate: f64,
    progress: Option<&Bound<'_, PyAny>>,
) -> PyResult<ContactCalibration> {
    use crate::pickling::kept;
    let recipe = crate::recipe!(py, "calibrate_contacts";
        robot = robot, q = kept(Some(q))?, points = &points,
        distances = kept(Some(distances))?, free = &free, max_iterations = max_iterations,
        loss = loss, loss_scale = loss_scale, outliers = outliers, outlier_rate = outlier_rate);
    let robot = robot.get();
    let given: Vec<&str> = [
        ("free", free.is_some()),
        ("max_iterations", max_iterations != 200),
        ("loss", loss != "l2"),
        ("loss_scale", loss_scale.is_some()),
        ("outliers", outliers != "drop"),
        ("outlier_rate", outlier_rate != 0.01),
    ]
    .into_iter()
    .filter_map(|(k, g)| g.then_some(k))
    .collect();
    crate::calibrate::refuse_unused(
        activecal::experiment::acts_on::CALIBRATE,
        &given,
        activecal::experiment::acts_on::Sensor::Contacts,
    )?;
    let outliers = crate::calibrate::outliers_of(outliers, outlier_rate)?;
    let inner = robot.inner.clone();
    let dof = inner.dof();
    let joints = activecal::units::joint_names(&inner);
    let q = &crate::convert::named_columns(q, "q", &joints, "joint")?;
    let (v, shape) = float_array(
        py,
        q,
        "q",
        &[None, Some(dof)],
        "one row of joint values per contact, radians or metres",
    )?;
    if points.len() != shape[0] {
        return Err(arg_err(
            "points",
            format!(
                "{} names for {} rows of q: one point name per row",
                points.len(),
                shape[0]
            ),
        ));
    }
    let mut qs = rows(&v, dof);
    robot.check_joint_values("q", &mut qs)?;
    let given = distances_of(distances)?;
    let request = ContactRequest {
        max_iterations: count("max_iterations", max_iterations, 1)?,
        geodesic: true,
        loss: crate::calibrate::loss_of(loss, loss_scale)?,
        keep: free.unwrap_or_default(),
        outliers,
        holdout: None,
    };
    // The settings checked before the data, as every call checks them.
    request
        .settings()
        .map_err(|e| crate::convert::Fail::from(e).into_py())?;
    let mut file = contact_file(qs, points);
    let known = activecal::experiment::contacts::checked_inputs(
        &inner,
        &mut file,
        &[],
        &given,
        activecal::experiment::contacts::ContactUse::Fit,
    )
    .map_err(|e| match e.input {
        activecal::experiment::contacts::ContactInput::Rows => arg_err("q", e.source),
        _ => arg_err("distances", e.source),
    })?;
    let r = inner.clone();
    let (c, report) = crate::progress::with_callback(progress, || {
        detached(py, move || {
            let c = run(&r, &file, &known, &given, &request).map_err(Fail::input)?;
            let report = serde_json::to_value(c.report(&r.name, &file.origin, true, &[]))?;
            Ok((c, report))
        })
    })?;
    for n in &c.calibration.notes {
        crate::convert::warn(py, n)?;
    }
    Ok(ContactCalibration {
        robot: inner,
        c,
        report,
        recipe,
    })
}

impl ContactCalibration {
    /// Writes the report folder into `dir` (no held-out placements, no
    /// file written beside it).
    fn folder(&self, dir: &std::path::Path) -> Result<(), Fail> {
        let text = self.c.text(&[]);
        self.c.write_report(dir, &self.robot, &self.report, &text)?;
        Ok(())
    }

    fn write_as(&self, format: Format, path: &std::path::Path, overwrite: bool) -> PyResult<()> {
        let out = activecal::io::atomic::Output {
            label: "path",
            path,
        };
        self.c.write_robot(format, out, overwrite).map_err(|e| match e {
            ContactOutError::Refused { .. } => Fail::Compute(e.to_string()).into_py(),
            ContactOutError::NotUrdf { .. } | ContactOutError::Toml { .. } => arg_err(
                "path",
                format!(
                    "{}: robot '{}' was not imported from a URDF: there is no URDF or frames file to write",
                    path.display(),
                    self.robot.name
                ),
            ),
            ContactOutError::Write(e) => Fail::from(e).into_py(),
        })
    }
}

#[pymethods]
impl ContactCalibration {
    /// Pickling: the call that made it, made again on loading.
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, pyo3::types::PyTuple>> {
        self.recipe.reduce(py)
    }

    /// Whether the fit converged.
    #[getter]
    fn converged(&self) -> bool {
        self.c.calibration.fit.converged
    }

    /// The estimate: {parameter name: value}, metres and radians (the
    /// robot's unknowns, the tool offset and each point's coordinates).
    #[getter]
    fn estimate(&self) -> std::collections::BTreeMap<String, f64> {
        let f = &self.c.calibration.fit;
        f.names
            .iter()
            .cloned()
            .zip(f.estimate.iter().copied())
            .collect()
    }

    /// Standard deviations of the estimate {name: σ}; None without a
    /// full-rank Jacobian.
    #[getter]
    fn sigma(&self) -> Option<std::collections::BTreeMap<String, f64>> {
        let f = &self.c.calibration.fit;
        f.std
            .as_ref()
            .map(|s| f.names.iter().cloned().zip(s.iter().copied()).collect())
    }

    /// The fitted points {name: (x, y, z)} in the base frame, metres.
    #[getter]
    fn points(&self) -> std::collections::BTreeMap<String, [f64; 3]> {
        let f = &self.c.calibration.fit;
        f.points
            .iter()
            .cloned()
            .zip(f.point_positions.iter().copied())
            .collect()
    }

    /// The tool point (ball centre) on the tip link, metres.
    #[getter]
    fn tool_offset(&self) -> [f64; 3] {
        self.c.calibration.fit.tool_offset
    }

    /// The tool point's predicted true error at 1000 random configurations
    /// (`rms_mm`, `configurations`): what held-out placements cannot see.
    #[getter]
    fn predicted_true_error<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, &self.report["predicted_true_error"])
    }

    /// The whole report: the dict `activecal calibrate --measurements FILE
    /// --json` prints for a contact file with the same rows.
    #[getter]
    fn report<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, &self.report)
    }

    /// Writes the calibrated robot as URDF (URDF robots; refused when the
    /// fit did not converge or is implausible).
    #[pyo3(signature = (path, overwrite=true))]
    fn write_urdf(&self, path: std::path::PathBuf, overwrite: bool) -> PyResult<()> {
        self.write_as(Format::Urdf, &path, overwrite)
    }

    /// Writes the frames file (YAML) with the ball centre as `point` and
    /// the fitted points under `contacts`.
    #[pyo3(signature = (path, overwrite=true))]
    fn write_frames(&self, path: std::path::PathBuf, overwrite: bool) -> PyResult<()> {
        self.write_as(Format::Yaml, &path, overwrite)
    }

    /// The report folder `activecal calibrate --measurements FILE
    /// --report DIR` writes for a contact file with the same rows, written
    /// into `path`: report.md, report.json, the figures (PNG and SVG) and
    /// `index.html`, the 3D page of the robot at each contact with the
    /// fitted sockets and planes. An existing directory is replaced whole;
    /// overwrite=False refuses a non-empty one with `FileError`.
    #[pyo3(signature = (path, overwrite=true))]
    fn write_report(
        &self,
        py: Python<'_>,
        path: std::path::PathBuf,
        overwrite: bool,
    ) -> PyResult<()> {
        let inputs = crate::page::robot_inputs(&self.robot);
        crate::page::write_folder(py, &path, overwrite, &inputs, |dir| self.folder(dir))
    }

    /// The 3D page of `write_report`'s folder (`index.html`), shown inline
    /// by Jupyter (a `Page`; its `html` is the page's text, the command
    /// line's for the same rows but for the data's source it names).
    fn show(&self, py: Python<'_>) -> PyResult<crate::page::Page> {
        crate::page::page_of(py, |dir| self.folder(dir))
    }

    fn __repr__(&self) -> String {
        format!(
            "ContactCalibration({:?}, {} rows, converged={})",
            self.robot.name, self.report["rows"], self.c.calibration.fit.converged
        )
    }
}

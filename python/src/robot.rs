//! `activecal.Robot`: a robot model (built-in or imported from a URDF), its
//! joints, limits and unknowns, and its forward kinematics.

use crate::convert::{arg_err, detached, float_array, ndarray};
use activecal::io::{ChainChoice, MarkerChoice, RobotRef};
use activecal::model::ParamSet;
use activecal::options::Visibility;
use activecal::report::FkReport;
use pyo3::prelude::*;
use pyo3::types::{PyString, PyTuple};
use std::sync::Arc;

/// A robot model: a serial chain, its joint limits, the unknowns a
/// calibration estimates and the sensor it is measured with. Immutable.
#[pyclass(module = "activecal", name = "Robot", frozen)]
pub struct Robot {
    pub(crate) inner: Arc<activecal::model::Robot>,
    /// The region the description's sensor sees (filters pools).
    pub(crate) visibility: Option<Visibility>,
    /// How it was made, for pickling (none for a calibrated model).
    pub(crate) recipe: Option<crate::pickling::Recipe>,
}

impl Robot {
    /// Loads a robot reference as the command line does (validated, with
    /// at least one joint).
    fn load(py: Python<'_>, r: RobotRef, recipe: crate::pickling::Recipe) -> PyResult<Self> {
        let d = detached(py, move || {
            let d = r.load()?;
            d.robot.validate()?;
            if d.robot.dof() == 0 {
                return Err(crate::convert::Fail::Input(format!(
                    "{r}: this robot has no joints (every frame of its chain is fixed); a robot needs at least one revolute or prismatic joint"
                )));
            }
            Ok(d)
        })?;
        Ok(Self {
            inner: Arc::new(d.robot),
            visibility: d.visibility,
            recipe: Some(recipe),
        })
    }

    /// The joint values `q` of one configuration, checked.
    pub(crate) fn configuration(
        &self,
        py: Python<'_>,
        q: &Bound<'_, PyAny>,
        name: &str,
    ) -> PyResult<Vec<f64>> {
        let dof = self.inner.dof();
        let (v, _) = float_array(
            py,
            q,
            name,
            &[Some(dof)],
            "one value per joint, radians or metres",
        )?;
        let mut qs = vec![v];
        self.check_joint_values(name, &mut qs)?;
        Ok(qs.pop().unwrap_or_default())
    }

    /// Joint values checked as every reader of them is (each within its
    /// joint's limits, values that look like degrees named):
    /// [`activecal::units::joint_values_to_model_units`] in radians and
    /// metres; errors name the argument `name` and the row.
    pub(crate) fn check_joint_values(&self, name: &str, qs: &mut [Vec<f64>]) -> PyResult<()> {
        let rows: Vec<String> = if qs.len() == 1 {
            vec![format!("{name}")]
        } else {
            (0..qs.len()).map(|k| format!("{name}[{k}]")).collect()
        };
        let names = activecal::units::joint_names(&self.inner);
        activecal::units::joint_values_to_model_units(
            &self.inner,
            activecal::units::Units::default(),
            &activecal::units::JointSource {
                file: name,
                rows: &rows,
                columns: &names,
            },
            qs,
        )
        .map_err(|e| crate::errors::new_err(crate::errors::Kind::Input, e.to_string()))
    }
}

/// One marker: `"LINK@X,Y,Z"` or `(link, (x, y, z))`, metres.
fn marker_of(m: &Bound<'_, PyAny>) -> PyResult<MarkerChoice> {
    if let Ok(s) = m.cast::<PyString>() {
        return MarkerChoice::parse(&s.to_cow()?).map_err(|e| arg_err("marker", e));
    }
    let bad = || {
        arg_err(
            "marker",
            "expected \"LINK@X,Y,Z\" or (link, (x, y, z)) with the offset in metres",
        )
    };
    let (link, xyz): (String, Bound<'_, PyAny>) = m.extract().map_err(|_| bad())?;
    let (v, _) = float_array(
        m.py(),
        &xyz,
        "marker",
        &[Some(3)],
        "the offset x, y, z in the link's frame, metres",
    )?;
    Ok(MarkerChoice {
        link,
        offset: [v[0], v[1], v[2]],
    })
}

/// One marker or a list of them.
fn markers_of(m: &Bound<'_, PyAny>) -> PyResult<Vec<MarkerChoice>> {
    let single = m.is_instance_of::<PyString>()
        || m.cast::<PyTuple>().is_ok_and(|t| {
            t.len() == 2
                && t.get_item(0).is_ok_and(|x| x.is_instance_of::<PyString>())
                && t.get_item(1).is_ok_and(|x| !x.is_instance_of::<PyString>())
        });
    if single {
        return Ok(vec![marker_of(m)?]);
    }
    m.try_iter()
        .map_err(|_| arg_err("marker", "expected a marker or a list of markers"))?
        .map(|x| marker_of(&x?))
        .collect()
}

#[pymethods]
impl Robot {
    /// Imports the chain of a URDF file.
    ///
    /// path: the .urdf file. tip, base: the chain's tip and base links
    /// (default: the URDF's root; the tip is required on a tree). marker:
    /// a marker measured on the tip, "LINK@X,Y,Z" or (link, (x, y, z)) with
    /// the offset in metres in the link's frame, or a list of them (each
    /// offset is then estimated). lock: {joint: value} joints held fixed
    /// (radians or metres). frames: a frames file (measurement frame, tool).
    /// kinematics: a kinematics file (Universal Robots'
    /// default_kinematics.yaml or per-joint origins) whose joint origins
    /// replace the URDF's. pose: full-pose measurements (position and
    /// orientation).
    #[staticmethod]
    #[pyo3(signature = (path, tip=None, base=None, marker=None, lock=None, frames=None, pose=false, kinematics=None))]
    #[allow(clippy::too_many_arguments)]
    fn from_urdf(
        py: Python<'_>,
        path: std::path::PathBuf,
        tip: Option<String>,
        base: Option<String>,
        marker: Option<&Bound<'_, PyAny>>,
        lock: Option<std::collections::BTreeMap<String, f64>>,
        frames: Option<std::path::PathBuf>,
        pose: bool,
        kinematics: Option<std::path::PathBuf>,
    ) -> PyResult<Self> {
        let recipe = crate::recipe!(py, "Robot.from_urdf";
            path = &path, tip = &tip, base = &base, marker = crate::pickling::kept(marker)?,
            lock = &lock, frames = &frames, pose = pose, kinematics = &kinematics);
        let markers = marker.map(markers_of).transpose()?.unwrap_or_default();
        let lock: Vec<(String, f64)> = lock.unwrap_or_default().into_iter().collect();
        if let Some((j, v)) = lock.iter().find(|(_, v)| !v.is_finite()) {
            return Err(arg_err("lock", format!("{j}: {v} is not a finite number")));
        }
        if !path.is_file() {
            return Err(crate::errors::new_err(
                crate::errors::Kind::File,
                format!("path: {}: no such file", path.display()),
            ));
        }
        if let Some(f) = frames.as_ref().filter(|f| !f.is_file()) {
            return Err(crate::errors::new_err(
                crate::errors::Kind::File,
                format!("frames: {}: no such file", f.display()),
            ));
        }
        if let Some(f) = kinematics.as_ref().filter(|f| !f.is_file()) {
            return Err(crate::errors::new_err(
                crate::errors::Kind::File,
                format!("kinematics: {}: no such file", f.display()),
            ));
        }
        let r = RobotRef {
            name: path.display().to_string(),
            pose,
            sensor: None,
            chain: ChainChoice {
                base,
                tip,
                lock,
                frames: frames.map(|f| f.display().to_string()),
                kinematics: kinematics.map(|f| f.display().to_string()),
                markers,
            },
        };
        Self::load(py, r, recipe)
    }

    /// A built-in robot: "puma560", "ur5" or "stanford"; append ":pose"
    /// for full-pose measurements.
    #[staticmethod]
    fn builtin(py: Python<'_>, name: &str) -> PyResult<Self> {
        activecal::model::Robot::builtin(name).map_err(|e| arg_err("name", e))?;
        let recipe = crate::recipe!(py, "Robot.builtin"; name = name);
        Self::load(
            py,
            RobotRef::parse(name).map_err(|e| arg_err("name", e))?,
            recipe,
        )
    }

    /// Pickling: the robot is made again from the same call (its files
    /// read again). A calibrated model (inside `evaluate`) has none.
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, pyo3::types::PyTuple>> {
        match &self.recipe {
            Some(r) => r.reduce(py),
            None => Err(pyo3::exceptions::PyTypeError::new_err(
                "this Robot cannot be pickled: pickle the Calibration it came from",
            )),
        }
    }

    /// The robot's name, as design files record it.
    #[getter]
    fn name(&self) -> String {
        self.inner.name.clone()
    }

    /// Number of joints.
    #[getter]
    fn dof(&self) -> usize {
        self.inner.dof()
    }

    /// The joints' names, in configuration order.
    #[getter]
    fn joint_names(&self) -> Vec<String> {
        activecal::units::joint_names(&self.inner)
    }

    /// Joint limits, an (n, 2) float64 array of [lower, upper]: radians for
    /// a revolute joint, metres for a prismatic one.
    #[getter]
    fn limits<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let v: Vec<f64> = self.inner.limits.iter().flatten().copied().collect();
        ndarray(py, &v, &[self.inner.dof(), 2])
    }

    /// Names of the parameters a calibration estimates, in order: the
    /// robot's unknowns, then each marker's offset.
    #[getter]
    fn unknowns(&self) -> Vec<String> {
        self.inner.parameter_names()
    }

    /// Whether orientations are measured too (a full-pose sensor).
    #[getter]
    fn measures_orientation(&self) -> bool {
        activecal::experiment::sensor_for(&self.inner).measures_orientation()
    }

    /// Forward kinematics of the nominal model at joint values q (radians or
    /// metres, shape (dof,)): (R, p), the end frame's orientation (3×3
    /// rotation matrix, base frame) and position (3, metres).
    fn fk<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let q = self.configuration(py, q, "q")?;
        self.inner.check_q(&q).map_err(|e| arg_err("q", e))?;
        let r =
            FkReport::new(&self.inner, ParamSet::Nominal, q, false).map_err(|e| arg_err("q", e))?;
        let rows: Vec<f64> = r.rotation.iter().flatten().copied().collect();
        Ok((
            ndarray(py, &rows, &[3, 3])?,
            ndarray(py, &r.position, &[3])?,
        ))
    }

    /// The identification Jacobian at joint values q (radians or metres,
    /// shape (dof,)) of the nominal model: shape (rows, len(unknowns)), the
    /// change of each measured coordinate (metres; a full pose's
    /// orientation rows in metres as weighed by the robot's orientation
    /// scale) per unit of each parameter (metres or radians), the columns
    /// in the order of `unknowns`; 3 rows for a point, 6 for a pose, 3 per
    /// marker.
    fn jacobian<'py>(&self, py: Python<'py>, q: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
        let q = self.configuration(py, q, "q")?;
        let r = &self.inner;
        let (t, n) = (r.rows_per_pose(), r.n_params());
        let fk = FkReport::new(r, ParamSet::Nominal, q, true).map_err(|e| arg_err("q", e))?;
        let jac: Vec<f64> = fk.jacobian.into_iter().flatten().flatten().collect();
        ndarray(py, &jac, &[t, n])
    }

    fn __repr__(&self) -> String {
        format!(
            "Robot({:?}, dof={}, unknowns={})",
            self.inner.name,
            self.inner.dof(),
            self.inner.n_params()
        )
    }
}

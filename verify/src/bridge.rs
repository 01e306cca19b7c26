//! The embedded Python (feature `live`): loads `bridge.py` once per process
//! into the interpreter pyo3 starts, with the project venv made importable,
//! and calls its Pinocchio and MuJoCo evaluations.
//!
//! The venv is `$ACTIVECAL_VENV` or else `<workspace>/.venv` (made by
//! `scripts/setup`). Build with `PYO3_PYTHON=<venv>/bin/python` so pyo3
//! links the venv's base libpython (build.rs adds its rpath).

use crate::compare::Kinematics;
use crate::fixture::Versions;
use crate::model::ModelSpec;
use activecal::model::JointKind;
use anyhow::{Context, Result, bail};
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::{PyDict, PyModule};
use std::ffi::CString;
use std::path::{Path, PathBuf};

/// The Python half of the bridge, kept as a readable file.
pub const BRIDGE_PY: &str = include_str!("bridge.py");

/// The loaded bridge module and the versions its `init` reported.
struct Loaded {
    module: Py<PyModule>,
    versions: Versions,
}

static LOADED: PyOnceLock<Loaded> = PyOnceLock::new();

/// The project venv: `$ACTIVECAL_VENV` if set, else `<workspace>/.venv`.
#[must_use]
pub fn venv_dir() -> PathBuf {
    match std::env::var_os("ACTIVECAL_VENV") {
        Some(v) if !v.is_empty() => PathBuf::from(v),
        _ => Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("..")
            .join(".venv"),
    }
}

/// `<venv>/lib/pythonX.Y/site-packages` for the running interpreter's X.Y.
fn site_packages(venv: &Path, major: u8, minor: u8) -> Result<PathBuf> {
    let dir = venv
        .join("lib")
        .join(format!("python{major}.{minor}"))
        .join("site-packages");
    if !dir.is_dir() {
        bail!(
            "{} does not exist: the venv is missing or was made for another Python than the \
             embedded {major}.{minor} (run scripts/setup, build with PYO3_PYTHON=<venv>/bin/python, \
             or set ACTIVECAL_VENV)",
            dir.display()
        );
    }
    Ok(dir)
}

/// Loads bridge.py and runs its `init` (once per process; concurrent
/// callers wait for the first).
fn loaded(py: Python<'_>) -> Result<&Loaded> {
    LOADED.get_or_try_init(py, || -> Result<Loaded> {
        let venv = venv_dir();
        let v = py.version_info();
        let site = site_packages(&venv, v.major, v.minor)?;
        let python = venv.join("bin").join("python");
        let code = CString::new(BRIDGE_PY).context("bridge.py contains a NUL byte")?;
        let m = PyModule::from_code(py, &code, c"verify/src/bridge.py", c"activecal_bridge")?;
        let d = m
            .getattr("init")?
            .call1((
                site.to_string_lossy().as_ref(),
                python.to_string_lossy().as_ref(),
            ))
            .with_context(|| format!("importing Pinocchio and MuJoCo from {}", site.display()))?;
        let d = d.cast::<PyDict>().map_err(PyErr::from)?;
        let get = |k: &str| -> Result<String> {
            Ok(d.get_item(k)?
                .with_context(|| format!("bridge.init reported no version of {k}"))?
                .extract::<String>()?)
        };
        let versions = Versions {
            python: get("python")?,
            numpy: get("numpy")?,
            pinocchio: get("pinocchio")?,
            mujoco: get("mujoco")?,
        };
        Ok(Loaded {
            module: m.unbind(),
            versions,
        })
    })
}

fn module(py: Python<'_>) -> Result<&Bound<'_, PyModule>> {
    Ok(loaded(py)?.module.bind(py))
}

/// A handle to the bridge: Pinocchio and MuJoCo evaluations.
#[derive(Clone, Debug)]
pub struct Bridge {
    versions: Versions,
}

impl Bridge {
    /// Starts (or reuses) the embedded interpreter and imports the libraries.
    pub fn new() -> Result<Bridge> {
        Python::attach(|py| {
            Ok(Bridge {
                versions: loaded(py)?.versions.clone(),
            })
        })
    }

    /// Versions of Python, numpy, Pinocchio and MuJoCo in use.
    #[must_use]
    pub fn versions(&self) -> &Versions {
        &self.versions
    }

    /// Pinocchio's positions and joint Jacobians for a model spec.
    pub fn pinocchio(&self, spec: &ModelSpec, qs: &[Vec<f64>]) -> Result<Kinematics> {
        let placements: Vec<_> = spec
            .placements
            .iter()
            .map(|p| (p.rotation, p.translation))
            .collect();
        let kinds: Vec<&str> = spec
            .kinds
            .iter()
            .map(|k| match k {
                JointKind::Revolute => "revolute",
                JointKind::Prismatic => "prismatic",
            })
            .collect();
        let tool = (spec.tool.rotation, spec.tool.translation);
        Python::attach(|py| {
            let r = module(py)?
                .getattr("pinocchio_eval")?
                .call1((placements, kinds, tool, qs.to_vec()))
                .context("Pinocchio evaluation")?;
            unpack(&r, spec.dof(), qs.len())
        })
    }

    /// MuJoCo's positions and joint Jacobians for an MJCF document (joints
    /// named `q1 … qN`, site `ee`).
    pub fn mujoco(&self, mjcf: &str, dof: usize, qs: &[Vec<f64>]) -> Result<Kinematics> {
        Python::attach(|py| {
            let r = module(py)?
                .getattr("mujoco_eval")?
                .call1((mjcf, qs.to_vec()))
                .context("MuJoCo evaluation")?;
            unpack(&r, dof, qs.len())
        })
    }
}

/// Poses of a URDF's leaf link computed by Pinocchio from the file itself.
#[derive(Clone, Debug)]
pub struct UrdfPoses {
    /// The leaf link's name (found by the bridge from the XML, not by us).
    pub tip: String,
    /// Per joint vector: the rotation (row-major) and position of the leaf
    /// link in the root link's frame.
    pub poses: Vec<([[f64; 3]; 3], [f64; 3])>,
}

impl Bridge {
    /// Pinocchio's `buildModelFromUrdf` on `path`, evaluated at `qs` (joint
    /// values in chain order): the leaf link's placement.
    pub fn pinocchio_urdf(&self, path: &Path, qs: &[Vec<f64>]) -> Result<UrdfPoses> {
        Python::attach(|py| {
            let r = module(py)?
                .getattr("pinocchio_urdf_eval")?
                .call1((path.to_string_lossy().as_ref(), qs.to_vec()))
                .with_context(|| format!("Pinocchio loading {}", path.display()))?;
            let (tip, poses): (String, Vec<([[f64; 3]; 3], [f64; 3])>) = r.extract()?;
            if poses.len() != qs.len() {
                bail!(
                    "bridge returned {} poses for {} joint vectors",
                    poses.len(),
                    qs.len()
                );
            }
            Ok(UrdfPoses { tip, poses })
        })
    }
}

fn unpack(r: &Bound<'_, PyAny>, dof: usize, n: usize) -> Result<Kinematics> {
    let (position, jacobian): (Vec<[f64; 3]>, Vec<Vec<f64>>) = r.extract()?;
    if position.len() != n || jacobian.len() != n || jacobian.iter().any(|j| j.len() != 3 * dof) {
        bail!("bridge returned values of the wrong shape");
    }
    Ok(Kinematics { position, jacobian })
}

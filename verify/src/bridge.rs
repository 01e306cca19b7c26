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

/// The workspace's root directory (where `fixtures/` and `verify/` are).
#[must_use]
pub fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("verify/ is inside the workspace")
        .to_path_buf()
}

/// The project venv's Python as a command to run a script with.
#[must_use]
pub fn python() -> std::process::Command {
    std::process::Command::new(venv_dir().join("bin/python"))
}

/// Runs `c` and returns its stdout; panics with its stderr when it fails
/// (the live tests' way of running the binary and the Python checks).
pub fn run(c: &mut std::process::Command) -> String {
    let out = c.output().expect("the command starts");
    assert!(
        out.status.success(),
        "{c:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).expect("UTF-8 output")
}

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

/// Central differences of Pinocchio's end frame over model parameters: per
/// configuration, per parameter, `[∂p/∂θ (3), ω (3)]` — the position rows
/// `(p(θ+h) − p(θ−h)) / 2h` and the orientation rows
/// `log3(R(θ+h) R(θ−h)ᵀ) / 2h` (an angular velocity in the measurement
/// frame, unscaled).
pub type CentralDifferences = Vec<Vec<[f64; 6]>>;

impl Bridge {
    /// [`CentralDifferences`] from the model specs of every parameter at
    /// `θ + h` (`plus[c]`) and `θ − h` (`minus[c]`), which must share their
    /// joint kinds, evaluated at `qs`.
    pub fn pinocchio_central_differences(
        &self,
        plus: &[ModelSpec],
        minus: &[ModelSpec],
        qs: &[Vec<f64>],
        h: f64,
    ) -> Result<CentralDifferences> {
        if plus.len() != minus.len() || plus.is_empty() {
            bail!("{} models at +h, {} at −h", plus.len(), minus.len());
        }
        if plus.iter().chain(minus).any(|s| s.kinds != plus[0].kinds) {
            bail!("the perturbed models do not share their joints");
        }
        type Side = (Vec<PyPlacement>, PyPlacement);
        let side = |s: &ModelSpec| -> Side {
            (
                s.placements
                    .iter()
                    .map(|p| (p.rotation, p.translation))
                    .collect(),
                (s.tool.rotation, s.tool.translation),
            )
        };
        let pairs: Vec<(Side, Side)> = plus
            .iter()
            .zip(minus)
            .map(|(p, m)| (side(p), side(m)))
            .collect();
        let kinds = kind_names(&plus[0].kinds);
        Python::attach(|py| {
            let r = module(py)?
                .getattr("pinocchio_central_differences")?
                .call1((pairs, kinds, qs.to_vec(), h))
                .context("Pinocchio central differences")?;
            let out: CentralDifferences = r.extract()?;
            if out.len() != qs.len() || out.iter().any(|k| k.len() != plus.len()) {
                bail!("bridge returned central differences of the wrong shape");
            }
            Ok(out)
        })
    }
}

/// A placement as the bridge passes it: (rotation row-major, translation).
pub use crate::placement::Placement;

type PyPlacement = ([[f64; 3]; 3], [f64; 3]);

/// activecal's joint kinds as bridge.py's names.
fn kind_names(kinds: &[JointKind]) -> Vec<&'static str> {
    kinds
        .iter()
        .map(|k| match k {
            JointKind::Revolute => "revolute",
            JointKind::Prismatic => "prismatic",
        })
        .collect()
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
            let (tip, poses): (String, Vec<PyPlacement>) = r.extract()?;
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

/// A joint as `urdf_chain` in bridge.py returns it: (name, nq, limits).
type PyJoint = (String, usize, Option<(f64, f64)>);

/// A moving joint of Pinocchio's model of a URDF chain.
#[derive(Clone, Debug, PartialEq)]
pub struct PinJoint {
    /// The URDF joint's name.
    pub name: String,
    /// Configuration size: 1, or 2 for a continuous joint (cos, sin).
    pub nq: usize,
    /// Position limits (`nq = 1` only).
    pub limits: Option<[f64; 2]>,
}

impl Bridge {
    /// The installed `example-robot-data`'s version and its `robots/`
    /// directory.
    pub fn erd_location(&self) -> Result<(String, PathBuf)> {
        Python::attach(|py| {
            let r = module(py)?
                .getattr("erd_location")?
                .call0()
                .context("locating example-robot-data in the venv")?;
            let (version, dir): (String, String) = r.extract()?;
            Ok((version, PathBuf::from(dir)))
        })
    }

    /// The moving joints of Pinocchio's model of the URDF at `path`
    /// (`buildModelFromUrdf`) from the link `base` (`None`: the root) to the
    /// link `tip`, in order.
    pub fn urdf_chain(&self, path: &Path, base: Option<&str>, tip: &str) -> Result<Vec<PinJoint>> {
        Python::attach(|py| {
            let r = module(py)?
                .getattr("urdf_chain")?
                .call1((path.to_string_lossy().as_ref(), base, tip))
                .with_context(|| {
                    format!("Pinocchio's chain {base:?} → {tip} of {}", path.display())
                })?;
            let joints: Vec<PyJoint> = r.extract()?;
            Ok(joints
                .into_iter()
                .map(|(name, nq, limits)| PinJoint {
                    name,
                    nq,
                    limits: limits.map(|(lo, hi)| [lo, hi]),
                })
                .collect())
        })
    }

    /// Pinocchio's placement of the link `tip` in the frame of the link
    /// `base` (`None`: the root) of the URDF at `path`, at each joint vector
    /// (`qs[k][i]` the value of the joint `names[i]`; other joints neutral):
    /// `oMf(base)⁻¹ · oMf(tip)` after `framesForwardKinematics`.
    pub fn urdf_relative_poses(
        &self,
        path: &Path,
        base: Option<&str>,
        tip: &str,
        names: &[String],
        qs: &[Vec<f64>],
    ) -> Result<Vec<Placement>> {
        Python::attach(|py| {
            let r = module(py)?
                .getattr("urdf_relative_poses")?
                .call1((
                    path.to_string_lossy().as_ref(),
                    base,
                    tip,
                    names.to_vec(),
                    qs.to_vec(),
                ))
                .with_context(|| {
                    format!("Pinocchio's placements of {tip} in {}", path.display())
                })?;
            let poses: Vec<PyPlacement> = r.extract()?;
            if poses.len() != qs.len() {
                bail!(
                    "bridge returned {} placements for {} joint vectors",
                    poses.len(),
                    qs.len()
                );
            }
            Ok(poses
                .into_iter()
                .map(|(rotation, position)| Placement { rotation, position })
                .collect())
        })
    }

    /// Pinocchio's generalized gravity (`computeGeneralizedGravity`, fixed
    /// base) of the URDF at `path` at each joint vector (`qs[k][i]` the value
    /// of the joint `names[i]`; other joints neutral): the torques of the
    /// joints `names`, N·m or N.
    pub fn urdf_gravity(
        &self,
        path: &Path,
        names: &[String],
        qs: &[Vec<f64>],
    ) -> Result<Vec<Vec<f64>>> {
        Python::attach(|py| {
            let r = module(py)?
                .getattr("urdf_gravity")?
                .call1((path.to_string_lossy().as_ref(), names.to_vec(), qs.to_vec()))
                .with_context(|| format!("Pinocchio's gravity of {}", path.display()))?;
            let tau: Vec<Vec<f64>> = r.extract()?;
            if tau.len() != qs.len() {
                bail!(
                    "bridge returned {} torque vectors for {} joint vectors",
                    tau.len(),
                    qs.len()
                );
            }
            Ok(tau)
        })
    }
}

/// cvxpy's solution of the relaxation (R) (see `bridge.py`).
#[derive(Clone, Debug, serde::Serialize)]
pub struct CvxSolution {
    /// cvxpy's status (`optimal`, `optimal_inaccurate`, …).
    pub status: String,
    /// The solver's objective, unscaled: its estimate of `max ln det M(w)`.
    pub ln_det: f64,
    /// The weights, clipped to `[0, 1]`.
    pub weights: Vec<f64>,
    /// The solver's own time (cvxpy's `solver_stats.solve_time`), seconds.
    pub solve_seconds: f64,
    /// Wall time of `Problem.solve`, compilation included, seconds.
    pub wall_seconds: f64,
}

/// The certificate of activecal's eq. (C) recomputed in numpy at some weights.
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub struct NumpyCertificate {
    /// `ln det M(w)`.
    pub ln_det: f64,
    /// `S_N`: the sum of the `N` largest variances `d_i = tr(X_i M⁻¹ X_iᵀ)`.
    pub s_n: f64,
    /// `ln det M(w) + p·ln(S_N/p)`: an upper bound on the relaxation's optimum.
    pub bound: f64,
    /// `Σ w_i`.
    pub weight_sum: f64,
}

/// The stacked Jacobian as a flat row-major list.
fn row_major(x: &activecal::blocks::Blocks) -> Vec<f64> {
    let m = x.mat();
    let mut out = Vec::with_capacity(m.nrows() * m.ncols());
    for r in 0..m.nrows() {
        for c in 0..m.ncols() {
            out.push(m[(r, c)]);
        }
    }
    out
}

impl Bridge {
    /// Solves the relaxation `max ln det Σ w_i X_iᵀX_i, 0 ≤ w ≤ 1, Σ w = n`
    /// with cvxpy's `log_det` and `solver` (`"CLARABEL"` or `"SCS"`) at
    /// tolerance `eps`.
    pub fn relaxation_cvxpy(
        &self,
        x: &activecal::blocks::Blocks,
        n: usize,
        solver: &str,
        eps: f64,
    ) -> Result<CvxSolution> {
        let flat = row_major(x);
        Python::attach(|py| {
            let r = module(py)?
                .getattr("relaxation_cvxpy")?
                .call1((flat, x.t(), x.p(), n, solver, eps))
                .with_context(|| format!("cvxpy with {solver}"))?;
            let (status, ln_det, weights, solve_seconds, wall_seconds): (
                String,
                f64,
                Vec<f64>,
                f64,
                f64,
            ) = r.extract()?;
            if weights.len() != x.n_poses() {
                bail!(
                    "cvxpy returned {} weights for {} poses",
                    weights.len(),
                    x.n_poses()
                );
            }
            Ok(CvxSolution {
                status,
                ln_det,
                weights,
                solve_seconds,
                wall_seconds,
            })
        })
    }

    /// The certificate (eq. C) at `weights`, computed in numpy.
    pub fn relaxation_certificate(
        &self,
        x: &activecal::blocks::Blocks,
        weights: &[f64],
        n: usize,
    ) -> Result<NumpyCertificate> {
        let flat = row_major(x);
        Python::attach(|py| {
            let r = module(py)?
                .getattr("relaxation_certificate")?
                .call1((flat, x.t(), x.p(), weights.to_vec(), n))
                .context("numpy certificate")?;
            let (ln_det, s_n, bound, weight_sum): (f64, f64, f64, f64) = r.extract()?;
            Ok(NumpyCertificate {
                ln_det,
                s_n,
                bound,
                weight_sum,
            })
        })
    }
}

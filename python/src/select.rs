//! `activecal.select`: a D-optimal design from a pool of candidate poses,
//! as `activecal select` chooses it, and the `Design` it returns.

use crate::convert::{arg_err, count, detached, json_to_py, ndarray, non_negative};
use crate::robot::Robot;
use activecal::io::design::DesignFile;
use activecal::names::Choice;
use activecal::pool::{PoolFilter, PoolSource, PoolSpec};
use activecal::report::{PredictedAfter, SelectReport};
use activecal::select::{Algorithm, CriterionKind, Settings};
use pyo3::prelude::*;
use std::sync::Arc;

/// A design: the chosen poses, their joint values and the selection's
/// report.
#[pyclass(module = "activecal", name = "Design", frozen)]
pub struct Design {
    robot: Arc<activecal::model::Robot>,
    file: DesignFile,
    report: serde_json::Value,
    q: Vec<Vec<f64>>,
    ids: Vec<usize>,
    ln_oid: f64,
}

/// The pool source named by `pool` and its size options.
fn pool_source(
    pool: &str,
    count_: Option<i64>,
    levels: Option<i64>,
    pool_seed: Option<i128>,
) -> PyResult<PoolSource> {
    let sampled = matches!(pool, "random" | "sobol");
    if levels.is_some() && pool != "lattice" {
        return Err(arg_err("levels", "applies to pool=\"lattice\" only"));
    }
    if !sampled && count_.is_some() {
        return Err(arg_err(
            "count",
            "applies to pool=\"random\" or \"sobol\" only",
        ));
    }
    if !sampled && pool_seed.is_some() {
        return Err(arg_err(
            "pool_seed",
            "applies to pool=\"random\" or \"sobol\" only",
        ));
    }
    let n = count_.map_or(Ok(4096), |c| count("count", c, 1))?;
    let seed = pool_seed
        .map(|s| non_negative("pool_seed", s))
        .transpose()?;
    Ok(match pool {
        "lattice" => PoolSource::Lattice {
            levels: levels.map_or(Ok(5), |l| count("levels", l, 2))?,
        },
        "random" => PoolSource::Random {
            count: n,
            seed: seed.unwrap_or(0),
        },
        "sobol" => PoolSource::Sobol { count: n, seed },
        other => {
            return Err(arg_err(
                "pool",
                format!("unknown pool '{other}': use \"random\", \"sobol\" or \"lattice\""),
            ));
        }
    })
}

/// Chooses `n` poses to measure from a pool of candidates by D-optimal
/// design (maximising ln det XᵀX of the identification Jacobian X at the
/// nominal parameters), as `activecal select` does with the same options
/// and `--order none`.
///
/// pool: "random" or "sobol" (count samples inside the joint limits, default
/// 4096; pool_seed: the random stream's seed, default 0, or the Sobol
/// scramble's, default none) or "lattice" (levels values per joint, default
/// 5). margin: degrees kept inside every revolute joint's limits (default:
/// 2 for a URDF robot's generated pool, else 0). algorithm: "eae" (default),
/// "fedorov", "detmax", "random" … as the command line names them. seed:
/// seed of every random choice of the search (default 1, the command
/// line's). starts: independent starts (default 2). ils: rounds of iterated
/// local search (default: the command line's, by pool size). noise: the
/// sensor's σ per coordinate, metres: the design then carries the position
/// error predicted after calibrating with it (`predicted`).
#[pyfunction]
#[pyo3(signature = (robot, n, pool="random", count=None, levels=None, pool_seed=None, margin=None, algorithm="eae", seed=1, starts=2, ils=None, kick=3, noise=None))]
#[allow(clippy::too_many_arguments)]
pub fn select(
    py: Python<'_>,
    robot: &Robot,
    n: i64,
    pool: &str,
    count: Option<i64>,
    levels: Option<i64>,
    pool_seed: Option<i128>,
    margin: Option<f64>,
    algorithm: &str,
    seed: i128,
    starts: i64,
    ils: Option<i64>,
    kick: i64,
    noise: Option<f64>,
) -> PyResult<Design> {
    let n = crate::convert::count("n", n, 1)?;
    let source = pool_source(pool, count, levels, pool_seed)?;
    let algorithm = Algorithm::from_name(algorithm).ok_or_else(|| {
        let names: Vec<&str> = Algorithm::ALL.iter().map(|a| a.name()).collect();
        arg_err(
            "algorithm",
            format!(
                "unknown algorithm '{algorithm}': one of {}",
                names.join(", ")
            ),
        )
    })?;
    let seed = non_negative("seed", seed)?;
    let starts = crate::convert::count("starts", starts, 1)?;
    let kick = crate::convert::count("kick", kick, 1)?;
    let ils = ils
        .map(|i| crate::convert::count("ils", i, 0))
        .transpose()?;
    if let Some(m) = margin.filter(|m| !(m.is_finite() && *m >= 0.0)) {
        return Err(arg_err("margin", format!("{m}: an angle >= 0 degrees")));
    }
    if let Some(s) = noise.filter(|s| !(s.is_finite() && *s > 0.0)) {
        return Err(arg_err(
            "noise",
            format!("{s}: the sensor noise σ must be a finite number > 0 (metres)"),
        ));
    }
    let inner = robot.inner.clone();
    let margin_deg = margin
        .unwrap_or_else(|| activecal::pool::default_margin_deg(inner.source.is_some(), &source));
    let spec = PoolSpec {
        source,
        filters: robot
            .visibility
            .iter()
            .map(|v| PoolFilter::Visibility(v.clone()))
            .collect(),
        margin: margin_deg.to_radians(),
    };
    let r = inner.clone();
    let (file, report, ids, q, ln_oid) = detached(py, move || {
        let e = |e: activecal::Error| e.to_string();
        let table = &r.nominal;
        let pool = spec.build(&r, table).map_err(e)?;
        let x = pool.try_jacobian(&r, table).map_err(e)?;
        let s = Settings {
            n,
            initial: Settings::default().initial.min(n),
            starts,
            ils: ils.unwrap_or_else(|| activecal::select::default_ils_rounds(x.n_poses(), x.t())),
            kick,
            seed,
            ..Settings::default()
        };
        let t0 = std::time::Instant::now();
        let sel = activecal::select::select(&x, CriterionKind::Det, algorithm, &s).map_err(e)?;
        let mut report = SelectReport::new(
            &r,
            &pool,
            &sel,
            CriterionKind::Det,
            &s,
            t0.elapsed().as_secs_f64(),
        );
        if let Some(noise) = noise {
            report.predicted = PredictedAfter::of_design(&r, table, &x, &sel.poses, noise);
        }
        let mut file = DesignFile::from_pool(&r, &pool, &sel.poses);
        file.extra.extend(report.design_keys());
        let q: Vec<Vec<f64>> = sel.poses.iter().map(|&k| pool.q(k)).collect();
        let ids = pool.ids_of(&sel.poses);
        let v = serde_json::to_value(&report).map_err(|e| e.to_string())?;
        Ok((file, v, ids, q, sel.ln_oid))
    })?;
    Ok(Design {
        robot: inner,
        file,
        report,
        q,
        ids,
        ln_oid,
    })
}

#[pymethods]
impl Design {
    /// Joint values of the chosen poses, an (n, dof) float64 array in
    /// selection order (radians or metres).
    #[getter]
    fn q<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let flat: Vec<f64> = self.q.iter().flatten().copied().collect();
        ndarray(py, &flat, &[self.q.len(), self.robot.dof()])
    }

    /// The poses' ids in the pool (a lattice index, a sample's number).
    #[getter]
    fn ids(&self) -> Vec<usize> {
        self.ids.clone()
    }

    /// The joints' names (the columns of `q`).
    #[getter]
    fn joint_names(&self) -> Vec<String> {
        activecal::units::joint_names(&self.robot)
    }

    /// ln OI_D = ln det XᵀX of the design (X: the identification Jacobian,
    /// metres per parameter unit).
    #[getter]
    fn ln_oid(&self) -> f64 {
        self.ln_oid
    }

    /// The errors predicted after calibrating with these poses (given
    /// `noise`): `noise_m`, `configurations`, `position_rms_mm`,
    /// `position_p95_mm`, …; None without `noise` or for a singular design.
    #[getter]
    fn predicted<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, &self.report["predicted"])
    }

    /// The selection's report: the dict `activecal select --json` prints.
    #[getter]
    fn report<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, &self.report)
    }

    /// Writes the design by the extension of `path`: .json (the design
    /// file), .csv (joint values, one pose a row) or .yaml (named joint
    /// configurations), as `activecal select --out` does. An existing file
    /// is replaced only with overwrite=True.
    #[pyo3(signature = (path, overwrite=false))]
    fn write(&self, path: std::path::PathBuf, overwrite: bool) -> PyResult<()> {
        activecal::io::design_formats::write(&self.file, &path, overwrite)
            .map_err(|e| arg_err("path", e))
    }

    fn __len__(&self) -> usize {
        self.q.len()
    }

    fn __repr__(&self) -> String {
        format!(
            "Design({} poses of {:?}, ln_oid={:.6})",
            self.q.len(),
            self.robot.name,
            self.ln_oid
        )
    }
}

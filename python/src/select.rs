//! `activecal.select`: a D-optimal design from a pool of candidate poses,
//! as `activecal select` chooses it, and the `Design` it returns.

use crate::convert::{arg_err, detached, json_to_py, ndarray, non_negative};
use crate::pool::Pool;
use crate::robot::Robot;
use activecal::experiment::Blocks;
use activecal::experiment::select::{Existing, SelectRun};
use activecal::experiment::visiting::Visiting;
use activecal::io::design::DesignFile;
use activecal::model::ParamSet;
use activecal::names::Choice;
use activecal::options::{Algorithm, CriterionKind, SelectSettings as Settings};
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
    /// The chosen poses' positions in the pool.
    positions: Vec<usize>,
    /// The pool's Jacobian (for the bound).
    x: Arc<Blocks>,
    /// The selection's settings and algorithm (for the how-many curve).
    settings: Settings,
    algorithm: Algorithm,
    /// The pool's pose ids, by position.
    pool_ids: Vec<usize>,
    /// The pool (named by the gap's report).
    pool: Arc<activecal::experiment::Pool>,
    /// The sensor noise given to `select`, metres.
    noise: Option<f64>,
    /// The selection's report (for the report folder).
    typed: Arc<activecal::report::SelectReport>,
    /// How it was made, for pickling.
    recipe: crate::pickling::Recipe,
}

/// The noise of the how-many curve when none is given, metres: the
/// command line's (`select --report` without `--noise`).
const DEFAULT_CURVE_NOISE: f64 = 0.01;

/// Chooses `n` poses to measure from a pool of candidates by D-optimal
/// design (maximising ln det XᵀX of the identification Jacobian X at the
/// nominal parameters), as `activecal select` does with the same options
/// and `--order none`.
///
/// pool: a `Pool` (from `activecal.pool`, with its filters), an (n, dof)
/// array of your own candidate joint values (radians or metres), or a
/// source name: "random" or "sobol" (count samples inside the joint limits,
/// default 4096; pool_seed: the random stream's seed, default 0, or the
/// Sobol scramble's, default none) or "lattice" (levels values per joint,
/// default 5). margin: degrees kept inside every revolute joint's limits
/// (default: 2 for a URDF robot's generated pool, else 0). existing: an
/// (m, dof) array of poses already measured: the new poses are chosen to
/// add most to their information (`--existing`). algorithm: "eae"
/// (default), "fedorov", "detmax", "random" … as the command line names
/// them. seed: seed of every random choice of the search (default 1, the
/// command line's). starts: independent starts (default 2). ils: rounds of
/// iterated local search (default: the command line's, by pool size).
/// noise: the sensor's σ per coordinate, metres: the design then carries
/// the position error predicted after calibrating with it (`predicted`).
/// order: "time" (the poses in the order that takes least time to visit,
/// at the joint speed limits of the robot's description, 1 rad/s where it
/// states none) or "none" (selection order); default "time" for a robot
/// whose description states joint speed limits, else "none", as the
/// command line's `--order`. Either way, with collision filters on the
/// pool, the moves between poses are checked and a pose the path cannot
/// reach freely is turned, routed round or exchanged (`report["moves"]`).
/// progress: a callable `progress(task, done, total, note)` called as the
/// work advances (at most every 0.1 s per task; `total` None when unknown;
/// `note` "done" at a task's end); an exception it raises is raised when
/// the work ends.
#[pyfunction]
#[pyo3(signature = (robot, n, pool=None, count=None, levels=None, pool_seed=None, margin=None, algorithm="eae", seed=1, starts=2, ils=None, kick=3, noise=None, existing=None, order=None, progress=None))]
#[allow(clippy::too_many_arguments)]
pub fn select(
    py: Python<'_>,
    robot: &Bound<'_, Robot>,
    n: i64,
    pool: Option<&Bound<'_, PyAny>>,
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
    existing: Option<&Bound<'_, PyAny>>,
    order: Option<&str>,
    progress: Option<&Bound<'_, PyAny>>,
) -> PyResult<Design> {
    let recipe = crate::recipe!(py, "select";
        robot = robot, n = n, pool = crate::pickling::kept(pool)?, count = count, levels = levels,
        pool_seed = pool_seed, margin = margin, algorithm = algorithm, seed = seed,
        starts = starts, ils = ils, kick = kick, noise = noise,
        existing = crate::pickling::kept(existing)?, order = order);
    let robot = robot.get();
    let reorder = reorder_of(robot, order)?;
    let n = crate::convert::count("n", n, 1)?;
    let algorithm = algorithm_of(algorithm)?;
    let seed = non_negative("seed", seed)?;
    let starts = crate::convert::count("starts", starts, 1)?;
    let kick = crate::convert::count("kick", kick, 1)?;
    let ils = ils
        .map(|i| crate::convert::count("ils", i, 0))
        .transpose()?;
    if let Some(s) = noise.filter(|s| !(s.is_finite() && *s > 0.0)) {
        return Err(arg_err(
            "noise",
            format!("{s}: the sensor noise σ must be a finite number > 0 (metres)"),
        ));
    }
    let candidates = candidates(py, robot, pool, count, levels, pool_seed, margin)?;
    let existing = existing.map(|e| existing_poses(py, robot, e)).transpose()?;
    let prior = existing.as_ref().map(|e| e.prior.clone());
    let r = robot.inner.clone();
    let (x, built) = (candidates.x.clone(), candidates.pool.clone());
    let s = Settings::builder()
        .n(n)
        .initial(Settings::default().initial.min(n))
        .starts(starts)
        .ils(ils.unwrap_or_else(|| activecal::options::default_ils_rounds(x.n_poses(), x.t())))
        .kick(kick)
        .seed(seed)
        .prior(prior.clone())
        .build()
        .map_err(|e| crate::convert::Fail::from(e).into_py())?;
    let run = SelectRun {
        criterion: CriterionKind::Det,
        algorithm,
        settings: s.clone(),
        visiting: Visiting {
            reorder,
            home: None,
            may_swap: true,
        },
        gap: None,
        refine: None,
        noise,
        params: ParamSet::Nominal,
    };
    let outcome = crate::progress::with_callback(progress, || {
        detached(py, move || {
            Ok(activecal::experiment::select::run(
                &r,
                &built,
                &x,
                existing.as_ref(),
                &run,
            )?)
        })
    })?;
    let report = serde_json::to_value(&outcome.report)
        .map_err(|e| crate::convert::Fail::from(e).into_py())?;
    let c = &outcome.report.configurations;
    Ok(Design {
        robot: robot.inner.clone(),
        file: outcome.design,
        report,
        q: c.iter().map(|c| c.q.clone()).collect(),
        ids: c.iter().map(|c| c.id).collect(),
        ln_oid: outcome.selection.ln_oid,
        positions: outcome.selection.poses,
        pool_ids: candidates.pool.ids.clone(),
        pool: candidates.pool.clone(),
        x: candidates.x,
        settings: s,
        algorithm,
        noise,
        typed: Arc::new(outcome.report),
        recipe,
    })
}

impl Design {
    /// What its how-many curve is computed from.
    fn curve_inputs(&self) -> crate::page::CurveInputs {
        crate::page::CurveInputs {
            robot: self.robot.clone(),
            x: self.x.clone(),
            ids: self.pool_ids.clone(),
            settings: self.settings.clone(),
            algorithm: self.algorithm,
            n: self.q.len(),
        }
    }

    /// The files its report folder reads: the robot's description and the
    /// collision filter's mesh directories.
    fn inputs(&self) -> Vec<(&'static str, std::path::PathBuf)> {
        let mut inputs = crate::page::robot_inputs(&self.robot);
        for f in &self.typed.pool.pool.filters {
            if let activecal::options::PoolFilter::Collision(c) = f {
                inputs.extend(
                    c.spec
                        .package_dirs
                        .iter()
                        .map(|d| ("a mesh directory", d.into())),
                );
            }
        }
        inputs
    }

    /// Writes the report folder into `dir` (see `write_report`).
    fn folder(
        &self,
        dir: &std::path::Path,
        noise: Option<f64>,
        target_error: Option<f64>,
    ) -> Result<(), crate::convert::Fail> {
        self.curve_inputs().selection_folder(
            dir,
            &self.typed,
            noise.or(self.noise),
            DEFAULT_CURVE_NOISE,
            target_error,
        )
    }

    /// The design against the certified bound over its own pool: the dict
    /// `activecal gap --json` prints.
    pub(crate) fn gap_dict<'py>(
        &self,
        py: Python<'py>,
        progress: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (x, positions) = (self.x.clone(), self.positions.clone());
        let (robot, pool, ids) = (self.robot.clone(), self.pool.clone(), self.ids.clone());
        let existing = self.file.existing.as_ref().map(|e| e.q.clone());
        let v = crate::progress::with_callback(progress, || {
            detached(py, move || {
                // The report `activecal gap --json` prints for this design.
                let params = activecal::model::ParamSet::Nominal;
                let existing = existing
                    .map(|qs| {
                        Existing::from_poses("existing".into(), qs, Vec::new(), &robot, params)
                    })
                    .transpose()?;
                let on = activecal::experiment::gap::ScoringPool {
                    robot: &robot,
                    pool: &pool,
                    x: &x,
                    params,
                };
                let scored = activecal::experiment::gap::score_design(
                    on,
                    ids,
                    activecal::experiment::gap::DesignPoses::InPool(&positions),
                    existing,
                    &activecal::options::BoundSettings::default(),
                )?;
                Ok(serde_json::to_value(&scored.report)?)
            })
        })?;
        json_to_py(py, &v)
    }
}

/// Whether the `order` argument asks for the visiting order by time: by
/// default when the robot's description states joint speeds, as the CLI.
fn reorder_of(robot: &Robot, order: Option<&str>) -> PyResult<bool> {
    match order {
        Some("time") => Ok(true),
        Some("none") => Ok(false),
        Some(o) => Err(arg_err(
            "order",
            format!("unknown order '{o}': \"time\" or \"none\""),
        )),
        None => activecal::experiment::visiting::default_reorder(&robot.inner)
            .map_err(|e| crate::convert::Fail::from(e).into_py()),
    }
}

/// The `algorithm` argument, by the command line's names.
fn algorithm_of(name: &str) -> PyResult<Algorithm> {
    Algorithm::from_name(name).ok_or_else(|| {
        let names: Vec<&str> = Algorithm::ALL.iter().map(|a| a.name()).collect();
        arg_err(
            "algorithm",
            format!("unknown algorithm '{name}': one of {}", names.join(", ")),
        )
    })
}

/// The candidates a `pool` argument names: a `Pool` as built (no size
/// option beside it), an array of configurations or a source name.
pub(crate) fn candidates(
    py: Python<'_>,
    robot: &Robot,
    pool: Option<&Bound<'_, PyAny>>,
    count: Option<i64>,
    levels: Option<i64>,
    pool_seed: Option<i128>,
    margin: Option<f64>,
) -> PyResult<Pool> {
    if let Some(built) = pool.and_then(|p| p.cast::<Pool>().ok()) {
        for (given, name) in [
            (count.is_some(), "count"),
            (levels.is_some(), "levels"),
            (pool_seed.is_some(), "pool_seed"),
            (margin.is_some(), "margin"),
        ] {
            if given {
                return Err(arg_err(
                    name,
                    "is the pool's own: give it to activecal.pool, not beside a Pool",
                ));
            }
        }
        let b = built.get();
        let same = |r: &activecal::model::Robot| (r.name.clone(), r.dof(), r.parameter_names());
        if !Arc::ptr_eq(&b.robot, &robot.inner) && same(&b.robot) != same(&robot.inner) {
            return Err(arg_err(
                "pool",
                format!(
                    "was built for robot '{}', not '{}'",
                    b.robot.name, robot.inner.name
                ),
            ));
        }
        return Ok(Pool {
            robot: b.robot.clone(),
            pool: b.pool.clone(),
            x: b.x.clone(),
            recipe: None,
        });
    }
    let default = pyo3::types::PyString::new(py, "random").into_any();
    crate::pool::pool_of(
        py,
        robot,
        "pool",
        pool.unwrap_or(&default),
        count,
        levels,
        pool_seed,
        margin,
        Vec::new(),
    )
}

/// Poses already measured (an (m, dof) array, checked as joint values are)
/// and their information `M0` at the nominal parameters.
pub(crate) fn existing_poses(
    py: Python<'_>,
    robot: &Robot,
    e: &Bound<'_, PyAny>,
) -> PyResult<Existing> {
    let dof = robot.inner.dof();
    let joints = activecal::units::joint_names(&robot.inner);
    let e = &crate::convert::named_columns(e, "existing", &joints, "joint")?;
    let (v, _) = crate::convert::float_array(
        py,
        e,
        "existing",
        &[None, Some(dof)],
        "one row of joint values per pose already measured, radians or metres",
    )?;
    let mut qs = crate::convert::rows(&v, dof);
    robot.check_joint_values("existing", &mut qs)?;
    let r = robot.inner.clone();
    detached(py, move || {
        Existing::from_poses("existing".into(), qs, Vec::new(), &r, ParamSet::Nominal)
            .map_err(crate::convert::Fail::from)
    })
}

#[pymethods]
impl Design {
    /// Pickling: made again by the same call with the same arguments
    /// (deterministic: the same result; the robot's files read again).
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, pyo3::types::PyTuple>> {
        self.recipe.reduce(py)
    }
    /// Joint values of the chosen poses, an (n, dof) float64 array in
    /// visiting order (see `order`; radians or metres, as visited: a joint
    /// may be a whole turn from the pool's value).
    #[getter]
    fn q<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let flat: Vec<f64> = self.q.iter().flatten().copied().collect();
        ndarray(py, &flat, &[self.q.len(), self.robot.dof()])
    }

    /// The poses' ids in the pool (a lattice index, a sample's number), in
    /// visiting order (the rows of `q`).
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

    /// The certified bound on ln det of every design of this size from the
    /// same pool (the continuous relaxation, with the existing poses'
    /// information when given) and this design's D-efficiency against it:
    /// the dict `activecal gap --json` prints (`ln_oid`, `ln_bound`,
    /// `d_efficiency` in (0, 1], `bound_status`, `certificate_gap`, …).
    /// Computed on each call (seconds on large pools); progress as
    /// `select` takes it.
    #[pyo3(signature = (progress=None))]
    fn bound<'py>(
        &self,
        py: Python<'py>,
        progress: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.gap_dict(py, progress)
    }

    /// "How many poses do I need?": for each design size from the fewest
    /// that can identify the unknowns to three times that (and this
    /// design's), the best design found by this selection's algorithm and
    /// settings, its D-efficiency against the certified bound and the
    /// position error predicted after calibrating with it at 1,000 random
    /// configurations; the dict `activecal select --report DIR` writes as
    /// `how_many_poses` in report.json (`n_min`, `points` with `n`,
    /// `ln_oid`, `ln_bound`, `d_efficiency`, `predicted` in mm,
    /// `recommended` …). noise: the sensor's σ per coordinate, metres
    /// (default: the noise given to `select`, else 0.01 as the command
    /// line). target_error: the position RMS to reach, mm: the smallest
    /// size predicted to reach it is recommended (else the curve's knee).
    /// Seconds to minutes: a selection and a bound per size.
    #[pyo3(signature = (noise=None, target_error=None, progress=None))]
    fn how_many<'py>(
        &self,
        py: Python<'py>,
        noise: Option<f64>,
        target_error: Option<f64>,
        progress: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let noise = noise.or(self.noise).unwrap_or(DEFAULT_CURVE_NOISE);
        crate::page::check_curve_args(noise, target_error)?;
        let inputs = self.curve_inputs();
        let v = crate::progress::with_callback(progress, || {
            detached(py, move || {
                Ok(serde_json::to_value(&inputs.curve(noise, target_error)?)?)
            })
        })?;
        json_to_py(py, &v)
    }

    /// The report folder `activecal select --report DIR` writes for this
    /// design, written into `path`: report.md, report.json, the figures
    /// (PNG and SVG) and `index.html`, the 3D page of the poses in
    /// visiting order (with the moves between them and the pool's
    /// obstacles). Computes the "how many poses" curve (see `how_many`:
    /// noise, target_error and progress as it takes them; seconds to
    /// minutes). An existing directory is replaced whole; overwrite=False
    /// refuses a non-empty one with `FileError`.
    #[pyo3(signature = (path, overwrite=true, noise=None, target_error=None, progress=None))]
    fn write_report(
        &self,
        py: Python<'_>,
        path: std::path::PathBuf,
        overwrite: bool,
        noise: Option<f64>,
        target_error: Option<f64>,
        progress: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        crate::page::check_curve_args(
            noise.or(self.noise).unwrap_or(DEFAULT_CURVE_NOISE),
            target_error,
        )?;
        crate::progress::with_callback(progress, || {
            crate::page::write_folder(py, &path, overwrite, &self.inputs(), |dir| {
                self.folder(dir, noise, target_error)
            })
        })
    }

    /// The 3D page of `write_report`'s folder (`index.html`), shown inline
    /// by Jupyter (a `Page`; its `html` is the page's text, byte for byte
    /// the command line's). noise and progress as `write_report` takes
    /// them (the page does not show the curve's recommendation, so no
    /// target_error).
    #[pyo3(signature = (noise=None, progress=None))]
    fn show(
        &self,
        py: Python<'_>,
        noise: Option<f64>,
        progress: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<crate::page::Page> {
        crate::page::check_curve_args(noise.or(self.noise).unwrap_or(DEFAULT_CURVE_NOISE), None)?;
        crate::progress::with_callback(progress, || {
            crate::page::page_of(py, |dir| self.folder(dir, noise, None))
        })
    }

    /// The selection's report: the dict `activecal select --json` prints.
    #[getter]
    fn report<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, &self.report)
    }

    /// Writes the design by the extension of `path`: .json (the design
    /// file), .csv (joint values, one pose a row) or .yaml (named joint
    /// configurations), as `activecal select --out` does. An existing file
    /// is replaced (as pandas and NumPy do); overwrite=False refuses it
    /// with `FileError`.
    #[pyo3(signature = (path, overwrite=true))]
    fn write(&self, path: std::path::PathBuf, overwrite: bool) -> PyResult<()> {
        activecal::io::design_formats::write(&self.file, &path, overwrite)
            .map_err(|e| crate::convert::Fail::from(e).into_py())
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

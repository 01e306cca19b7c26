//! `activecal.pool`: the candidate poses a design is chosen from (sampled,
//! a lattice, or the user's own configurations), filtered by what the
//! sensor sees and by collisions, with their identification Jacobian.

use crate::convert::{
    arg_err, count, detached, float_array, json_to_py, ndarray, non_negative, rows,
};
use crate::robot::Robot;
use activecal::experiment::Blocks;
use activecal::io::collision_choice::CollisionChoice;
use activecal::io::configurations::Configurations;
use activecal::options::{PoolFilter, PoolSource, PoolSpec};
use pyo3::prelude::*;
use pyo3::types::PyString;
use std::sync::Arc;

/// Candidate poses and their identification Jacobian at the nominal
/// parameters: what `select` chooses from. Immutable.
#[pyclass(module = "activecal", name = "Pool", frozen)]
pub struct Pool {
    pub(crate) robot: Arc<activecal::model::Robot>,
    pub(crate) pool: Arc<activecal::experiment::Pool>,
    pub(crate) x: Arc<Blocks>,
    /// How it was made, for pickling (`activecal.pool`'s pools).
    pub(crate) recipe: Option<crate::pickling::Recipe>,
}

/// What a pool source string names, with its size options.
pub(crate) fn pool_source(
    arg: &str,
    pool: &str,
    count_: Option<i64>,
    levels: Option<i64>,
    pool_seed: Option<i128>,
) -> PyResult<PoolSource> {
    use activecal::options::PoolKind;
    let kind = match pool {
        "lattice" => PoolKind::Lattice,
        "random" => PoolKind::Random,
        "sobol" => PoolKind::Sobol,
        other => {
            return Err(arg_err(
                arg,
                format!(
                    "unknown pool '{other}': use \"random\", \"sobol\", \"lattice\" or an (n, dof) array of joint values"
                ),
            ));
        }
    };
    let levels = levels.map(|l| count("levels", l, 2)).transpose()?;
    let n = count_.map(|c| count("count", c, 1)).transpose()?;
    let seed = pool_seed
        .map(|s| non_negative("pool_seed", s))
        .transpose()?;
    PoolSource::of(&kind, levels, n, seed).map_err(|e| crate::convert::Fail::from(e).into_py())
}

/// The collision part of a pool's options, checked (argument names in the
/// messages) and resolved against the robot's URDF.
#[allow(clippy::too_many_arguments)]
fn collision_filters(
    robot: &activecal::model::Robot,
    self_collision: bool,
    srdf: Option<String>,
    package_dirs: Vec<String>,
    floor: Option<f64>,
    obstacles: Vec<String>,
    clearance: f64,
) -> PyResult<Vec<PoolFilter>> {
    let chain = activecal::io::UrdfChain::of(robot);
    let choice = collision_choice(
        self_collision,
        srdf,
        package_dirs,
        floor,
        obstacles,
        clearance,
    )?;
    choice_filters(&choice, chain, &robot.name)
}

/// The collision options checked, argument names in the messages (the
/// files named exist; an SRDF or a clearance only with something to
/// check).
pub(crate) fn collision_choice(
    self_collision: bool,
    srdf: Option<String>,
    package_dirs: Vec<String>,
    floor: Option<f64>,
    obstacles: Vec<String>,
    clearance: f64,
) -> PyResult<CollisionChoice> {
    let obstacles = obstacles
        .iter()
        .map(|o| activecal::options::Obstacle::parse(o).map_err(|e| arg_err("obstacles", e)))
        .collect::<PyResult<Vec<_>>>()?;
    let choice = CollisionChoice {
        self_collision,
        skip_always_touching: false,
        srdf,
        package_dirs,
        clearance,
        obstacles,
        floor,
    };
    choice
        .validate()
        .map_err(|e| crate::convert::Fail::from(e).into_py())?;
    files_exist(&choice)?;
    Ok(choice)
}

/// Refuses an SRDF or a package directory that does not exist.
fn files_exist(choice: &CollisionChoice) -> PyResult<()> {
    for (name, p) in choice
        .srdf
        .iter()
        .map(|p| ("srdf", p))
        .chain(choice.package_dirs.iter().map(|p| ("package_dirs", p)))
    {
        if !std::path::Path::new(p).exists() {
            return Err(crate::errors::new_err(
                crate::errors::Kind::File,
                format!("{name}: {p}: no such file or directory"),
            ));
        }
    }
    Ok(())
}

/// The pool filters of a checked `choice` for the URDF chain `chain` (of
/// the robot named `robot`; `None`: not imported from a URDF).
pub(crate) fn choice_filters(
    choice: &CollisionChoice,
    chain: Option<activecal::io::UrdfChain>,
    robot: &str,
) -> PyResult<Vec<PoolFilter>> {
    if !choice.any() {
        return Ok(Vec::new());
    }
    let Some(chain) = chain else {
        return Err(arg_err(
            "self_collision",
            format!(
                "collision checks need a robot imported from a URDF with collision geometry; {robot} has none"
            ),
        ));
    };
    Ok(choice.filters(chain))
}

/// Builds the pool of `spec` for `robot` (listed configurations when
/// `listed` is given) and its Jacobian, with the GIL released.
pub(crate) fn build(
    py: Python<'_>,
    robot: &Arc<activecal::model::Robot>,
    spec: PoolSpec,
    listed: Option<Vec<Vec<f64>>>,
) -> PyResult<Pool> {
    let r = robot.clone();
    let (pool, x) = detached(py, move || {
        let listed = listed.map(|qs| Configurations {
            qs,
            notes: Vec::new(),
        });
        let run = activecal::experiment::pool::build_pool(
            (*r).clone(),
            &spec,
            listed,
            activecal::units::Units::default(),
            activecal::model::ParamSet::Nominal,
            false,
        )?;
        Ok((run.pool, run.x))
    })?;
    Ok(Pool {
        robot: robot.clone(),
        pool: Arc::new(pool),
        x: Arc::new(x),
        recipe: None,
    })
}

/// The pool a `source` argument names: a source string with its options,
/// or an (n, dof) array of the user's own candidate configurations
/// (radians or metres, checked as every reader of joint values checks
/// them); `arg` is the argument's name, for messages.
#[allow(clippy::too_many_arguments)]
pub(crate) fn pool_of(
    py: Python<'_>,
    robot: &Robot,
    arg: &str,
    source: &Bound<'_, PyAny>,
    count_: Option<i64>,
    levels: Option<i64>,
    pool_seed: Option<i128>,
    margin: Option<f64>,
    filters: Vec<PoolFilter>,
) -> PyResult<Pool> {
    if let Some(m) = margin.filter(|m| !(m.is_finite() && *m >= 0.0)) {
        return Err(arg_err("margin", format!("{m}: an angle >= 0 degrees")));
    }
    let inner = &robot.inner;
    let mut filters = filters;
    filters.extend(
        robot
            .visibility
            .iter()
            .map(|v| PoolFilter::Visibility(v.clone())),
    );
    let (src, listed) = if let Ok(s) = source.cast::<PyString>() {
        (
            pool_source(arg, &s.to_cow()?, count_, levels, pool_seed)?,
            None,
        )
    } else {
        for (given, name) in [
            (count_.is_some(), "count"),
            (levels.is_some(), "levels"),
            (pool_seed.is_some(), "pool_seed"),
        ] {
            if given {
                return Err(arg_err(
                    name,
                    "applies to a sampled or lattice pool, not to an array of configurations",
                ));
            }
        }
        let dof = inner.dof();
        let joints = activecal::units::joint_names(&inner);
        let source = &crate::convert::named_columns(source, arg, &joints, "joint")?;
        let (v, _) = float_array(
            py,
            source,
            arg,
            &[None, Some(dof)],
            "one row of joint values per candidate pose, radians or metres",
        )?;
        let mut qs = rows(&v, dof);
        robot.check_joint_values(arg, &mut qs)?;
        (PoolSource::File { path: arg.into() }, Some(qs))
    };
    let margin_deg = margin
        .unwrap_or_else(|| activecal::options::default_margin_deg(inner.source.is_some(), &src));
    let spec = PoolSpec {
        source: src,
        filters,
        margin: margin_deg.to_radians(),
    };
    build(py, inner, spec, listed)
}

/// Candidate poses for `select`: `source` is "random" or "sobol" (`count`
/// samples inside the joint limits less `margin` degrees, default 4096;
/// `pool_seed`), "lattice" (`levels` values per joint, default 5) or an
/// (n, dof) array of your own joint values (radians or metres). Poses the
/// robot's sensor does not see are dropped, and with `self_collision`
/// (pairs listed by `srdf` skipped), `floor` (a height in the base frame,
/// metres) or `obstacles` (``"box:x,y,z,sx,sy,sz"`` … in the base frame,
/// metres, as the command line's `--obstacle`), the poses where the robot
/// touches itself or them, within `clearance` metres (meshes found in
/// `package_dirs`). The pool holds the survivors' joint values (`q`), ids
/// and what each filter removed (`stats`). progress: a callable
/// `progress(task, done, total, note)`, as `select` takes it.
#[pyfunction]
#[pyo3(signature = (robot, source=None, count=None, levels=None, pool_seed=None, margin=None, self_collision=false, srdf=None, package_dirs=None, floor=None, obstacles=None, clearance=0.0, progress=None))]
#[allow(clippy::too_many_arguments)]
pub fn pool(
    py: Python<'_>,
    robot: &Bound<'_, Robot>,
    source: Option<&Bound<'_, PyAny>>,
    count: Option<i64>,
    levels: Option<i64>,
    pool_seed: Option<i128>,
    margin: Option<f64>,
    self_collision: bool,
    srdf: Option<std::path::PathBuf>,
    package_dirs: Option<Vec<std::path::PathBuf>>,
    floor: Option<f64>,
    obstacles: Option<Vec<String>>,
    clearance: f64,
    progress: Option<&Bound<'_, PyAny>>,
) -> PyResult<Pool> {
    let recipe = crate::recipe!(py, "pool";
        robot = robot, source = crate::pickling::kept(source)?, count = count, levels = levels,
        pool_seed = pool_seed, margin = margin, self_collision = self_collision, srdf = &srdf,
        package_dirs = &package_dirs, floor = floor, obstacles = &obstacles, clearance = clearance);
    let robot = robot.get();
    let filters = collision_filters(
        &robot.inner,
        self_collision,
        srdf.map(|p| p.display().to_string()),
        package_dirs
            .unwrap_or_default()
            .iter()
            .map(|p| p.display().to_string())
            .collect(),
        floor,
        obstacles.unwrap_or_default(),
        clearance,
    )?;
    let default = PyString::new(py, "random").into_any();
    let source = source.unwrap_or(&default);
    let mut built = crate::progress::with_callback(progress, || {
        pool_of(
            py, robot, "source", source, count, levels, pool_seed, margin, filters,
        )
    })?;
    built.recipe = Some(recipe);
    Ok(built)
}

#[pymethods]
impl Pool {
    /// Pickling: the pool is built again by the same call.
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, pyo3::types::PyTuple>> {
        match &self.recipe {
            Some(r) => r.reduce(py),
            None => Err(pyo3::exceptions::PyTypeError::new_err(
                "this Pool cannot be pickled: only the pools of activecal.pool can",
            )),
        }
    }

    /// Joint values of the candidates, an (n, dof) float64 array (radians
    /// or metres), in pool order.
    #[getter]
    fn q<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let dof = self.robot.dof();
        let flat: Vec<f64> = (0..self.pool.len()).flat_map(|k| self.pool.q(k)).collect();
        ndarray(py, &flat, &[self.pool.len(), dof])
    }

    /// The candidates' ids (a lattice index, a sample's number, a row of
    /// the array given).
    #[getter]
    fn ids(&self) -> Vec<usize> {
        self.pool.ids.clone()
    }

    /// The joints' names (the columns of `q`).
    #[getter]
    fn joint_names(&self) -> Vec<String> {
        activecal::units::joint_names(&self.robot)
    }

    /// What the pool's filters kept and removed: the dict the command
    /// line's `--json` prints as `pool_stats` (`candidates`, `kept`,
    /// `filters`: each filter's `removed` of `seen`).
    #[getter]
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let v = serde_json::to_value(&self.pool.stats)
            .map_err(|e| crate::convert::Fail::from(e).into_py())?;
        json_to_py(py, &v)
    }

    fn __len__(&self) -> usize {
        self.pool.len()
    }

    fn __repr__(&self) -> String {
        format!(
            "Pool({} candidates of {:?}, {} kept)",
            self.pool.stats.candidates,
            self.robot.name,
            self.pool.len()
        )
    }
}

//! The pool a socket design chooses from: configurations that put the tool
//! point at the socket (joint-space samples projected by
//! [`super::project::project_to_point`], passed through the pool filters),
//! with the contact sensor's own Jacobian (the robot's determined unknowns,
//! the tool offset and the socket's point as columns) as the common
//! [`Blocks`] the criterion and exchange of every selection take
//! (`crate::select::contact` chooses among them).
//!
//! A design is judged by its **predicted consistency error**: with unit
//! noise, the RMS over the pool of the predicted standard deviation of a
//! contact's residual `t − P` (`√(tr(X_q M⁻¹ X_qᵀ) / 3)` per coordinate, `X_q`
//! the pool configuration's 3 rows, `M = XᵀX` of the design): how far a
//! calibrated model's contacts would scatter about the socket, in units of
//! σ. A design whose `M` is singular has an infinite error.

use super::fit::{CONTACT_PIVOT_TOL, gauge_unknowns};
use super::project::project_to_point;
use crate::blocks::Blocks;
use crate::criterion::Prior;
use crate::data::ContactFile;
use crate::identify::Calibration;
use crate::identify::Residuals;
use crate::identify::undetermined::fix_undetermined_below;
use crate::measure::contact::{ContactSensor, KnownDistance};
use crate::model::{ParamTable, Robot};
use crate::pool::{Configurations, PoolFilter, PoolSource, PoolSpec, PoolStats};
use faer::{Mat, MatRef};
use nalgebra::{DMatrix, Vector3};
use rand::{Rng, RngExt};
use serde::Serialize;

/// A socket the tool is to touch: its name and approximate position in
/// the base frame (metres).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Socket {
    /// The point's name (as a contact file's `point` column names it).
    pub name: String,
    /// Its position in the base frame, metres.
    pub position: [f64; 3],
}

/// A pool of configurations at one or more sockets, with their design
/// Jacobian.
#[derive(Clone, Debug)]
pub struct SocketPool {
    /// The robot with the unknowns the pool determines.
    pub robot: Robot,
    /// The configurations (each reaches its socket).
    pub qs: Vec<Vec<f64>>,
    /// The socket each configuration reaches (an index into the sockets).
    pub sockets: Vec<usize>,
    /// Each configuration's 3 × p rows (unknowns: the robot's, the tool
    /// offset, every socket's point), pool position `i` the `i`-th block:
    /// what the common criterion and exchange take.
    pub blocks: Blocks,
    /// The known distances' rows (`c × p`, weighted as a fit weighs them,
    /// [`crate::measure::contact::DISTANCE_WEIGHT`]): information every
    /// design has, whichever configurations it holds.
    pub constraints: DMatrix<f64>,
}

/// Fewest configurations a socket of a pool needs (as a contact file's
/// point needs rows).
pub const MIN_SOCKET_CONFIGURATIONS: usize = 3;

/// For each socket, samples `count` configurations uniformly inside the
/// limits less `margin` and keeps those that project onto it (to `tol`
/// metres), then builds their Jacobian blocks for the unknowns the pool
/// determines with the known `distances` between sockets (indices into
/// `sockets`). A socket that fewer than [`MIN_SOCKET_CONFIGURATIONS`]
/// samples reach is an error naming it.
#[allow(clippy::too_many_arguments)]
pub fn socket_pool<R: Rng + ?Sized>(
    robot: &Robot,
    table: &ParamTable,
    sockets: &[Socket],
    distances: &[KnownDistance],
    count: usize,
    margin: f64,
    tol: f64,
    rng: &mut R,
) -> crate::identify::Result<SocketPool> {
    let file = projected(robot, table, sockets, count, margin, tol, rng)?;
    determined_pool(robot, table, file, distances)
}

/// The pool of the configurations of `file` for the unknowns they
/// determine with the known `distances` (the gauge and the weaker ones
/// fixed): a known distance fixes the scale that contacts alone leave
/// free, so it adds an unknown a fit estimates.
pub fn determined_pool(
    robot: &Robot,
    table: &ParamTable,
    file: ContactFile,
    distances: &[KnownDistance],
) -> crate::identify::Result<SocketPool> {
    let reduced = determined(robot, table, &file, distances)?;
    Ok(pool_of(&reduced, table, file, distances))
}

/// For each socket, `count` configurations sampled uniformly inside the
/// limits less `margin`, each projected onto it (to `tol` metres); those
/// that reach it, as the rows of a contact file (a point per socket). A
/// socket that fewer than [`MIN_SOCKET_CONFIGURATIONS`] samples reach is
/// an error naming it.
#[allow(clippy::too_many_arguments)]
pub fn projected<R: Rng + ?Sized>(
    robot: &Robot,
    table: &ParamTable,
    sockets: &[Socket],
    count: usize,
    margin: f64,
    tol: f64,
    rng: &mut R,
) -> crate::identify::Result<ContactFile> {
    let mut qs = Vec::new();
    let mut groups = Vec::new();
    for (g, s) in sockets.iter().enumerate() {
        let target = Vector3::from(s.position);
        let before = qs.len();
        for _ in 0..count {
            let q0: Vec<f64> = robot
                .limits
                .iter()
                .map(|&[lo, hi]| {
                    lo + margin + rng.random::<f64>() * (hi - lo - 2.0 * margin).max(0.0)
                })
                .collect();
            if let Some(q) = project_to_point(robot, table, &[0.0; 3], &target, &q0, margin, tol) {
                qs.push(q);
                groups.push(g);
            }
        }
        let reached = qs.len() - before;
        if reached < MIN_SOCKET_CONFIGURATIONS {
            let p = s.position;
            return Err(crate::error::Error::Invalid(format!(
                "point '{}' at ({}, {}, {}) m: {reached} of {count} sampled configurations reach it within the joint limits (less the margin), {MIN_SOCKET_CONFIGURATIONS} needed; is it within the arm's reach?",
                s.name, p[0], p[1], p[2]
            ))
            .into());
        }
    }
    Ok(ContactFile {
        origin: "pool".into(),
        groups,
        points: sockets.iter().map(|s| s.name.clone()).collect(),
        planes: Vec::new(),
        lines: (1..=qs.len()).collect(),
        qs,
    })
}

/// What a pool source of projected configurations is called in its
/// statistics.
pub const PROJECTED_SOURCE: &str = "configurations projected onto the sockets";

/// The rows of `file` (projected configurations) that pass every one of
/// `filters` (self-collision, obstacles: the filters of every pool, each
/// configuration's verdict once, evaluated at `table`), with what each
/// filter removed. A filter that removes every row, or leaves a socket
/// fewer than [`MIN_SOCKET_CONFIGURATIONS`] rows, is an error naming it.
pub fn filter_projected(
    robot: &Robot,
    table: &ParamTable,
    file: &ContactFile,
    filters: &[PoolFilter],
) -> crate::identify::Result<(ContactFile, PoolStats)> {
    let spec = PoolSpec {
        filters: filters.to_vec(),
        ..PoolSpec::of(PoolSource::File {
            path: PROJECTED_SOURCE.into(),
        })
    };
    let rows = Configurations {
        qs: file.qs.clone(),
        notes: Vec::new(),
    };
    let pool = spec.build_listed(robot, table, rows)?;
    let kept = file.subset(&pool.ids);
    for (g, name) in file.points.iter().enumerate() {
        let before = file.rows_of(g).len();
        let after = kept.point_index(name).map_or(0, |k| kept.rows_of(k).len());
        if after < MIN_SOCKET_CONFIGURATIONS {
            let by: Vec<String> = pool
                .stats
                .filters
                .iter()
                .map(|f| format!("{} removed {} of {}", f.filter, f.removed, f.seen))
                .collect();
            return Err(crate::error::Error::Invalid(format!(
                "point '{name}': {after} of its {before} configurations pass the pool filters ({}), {MIN_SOCKET_CONFIGURATIONS} needed",
                by.join(", ")
            ))
            .into());
        }
    }
    Ok((kept, pool.stats))
}

/// The pool of `file`'s configurations with `robot`'s unknowns as they are
/// (no gauge or rank reduction): each row's 3 × p block, and the rows of
/// the known `distances` after them.
fn pool_of(
    robot: &Robot,
    table: &ParamTable,
    file: ContactFile,
    distances: &[KnownDistance],
) -> SocketPool {
    let x = jacobian(robot, table, &file, distances);
    let p = x.ncols();
    let n = file.qs.len();
    let blocks = Blocks::new(x.subrows(0, 3 * n).to_owned(), 3);
    let constraints = DMatrix::from_fn(x.nrows() - 3 * n, p, |r, c| x[(3 * n + r, c)]);
    SocketPool {
        robot: robot.clone(),
        qs: file.qs,
        sockets: file.groups,
        blocks,
        constraints,
    }
}

/// The configurations `qs` (touching sockets `sockets[k]` of `names`) as
/// a pool with the unknowns of `pool` (its robot's, the tool offset, one
/// point a name): to judge a design of `pool` on configurations it was not
/// chosen from (other sockets), by the
/// [`consistency_moment`] of the result, whose point columns drop out.
#[must_use]
pub fn with_unknowns_of(
    pool: &SocketPool,
    table: &ParamTable,
    names: &[String],
    qs: Vec<Vec<f64>>,
    sockets: Vec<usize>,
) -> SocketPool {
    let file = ContactFile {
        origin: "evaluation".into(),
        lines: (1..=qs.len()).collect(),
        groups: sockets,
        points: names.to_vec(),
        planes: Vec::new(),
        qs,
    };
    pool_of(&pool.robot, table, file, &[])
}

/// The robot without the gauge and the unknowns the pool does not determine.
fn determined(
    robot: &Robot,
    table: &ParamTable,
    file: &ContactFile,
    distances: &[KnownDistance],
) -> crate::identify::Result<Robot> {
    let gauge = gauge_unknowns(robot, table, &file.qs);
    let mut inner = robot.clone();
    inner.unknowns = (0..robot.n_unknowns())
        .filter(|k| !gauge.contains(k))
        .map(|k| robot.unknowns[k])
        .collect();
    let x = jacobian(&inner, table, file, distances);
    Ok(fix_undetermined_below(&inner, table, &file.qs, &x, &[], CONTACT_PIVOT_TOL)?.robot)
}

/// The contact Jacobian of `file` with the known `distances` at `table`
/// (tool offset 0, the point at the mean tool point): the poses' rows, then
/// the distances'.
fn jacobian(
    robot: &Robot,
    table: &ParamTable,
    file: &ContactFile,
    distances: &[KnownDistance],
) -> Mat<f64> {
    let sensor = ContactSensor::new(file.points.clone(), distances.to_vec());
    let measured: Vec<f64> = file
        .groups
        .iter()
        .flat_map(|&g| ContactSensor::value_of(g))
        .collect();
    let mut prob = Calibration::with_sensor(robot, table, &file.qs, Box::new(sensor), measured);
    let mut theta = robot.unknown_values(table);
    theta.extend(super::start_own(robot, table, file));
    let mut r = vec![0.0; prob.n_residuals()];
    let mut x = Mat::zeros(prob.n_residuals(), prob.n_params());
    prob.eval(&theta, &mut r, Some(&mut x));
    x
}

impl SocketPool {
    /// Number of unknowns (columns of every block).
    #[must_use]
    pub fn p(&self) -> usize {
        self.blocks.p()
    }

    /// Pool configuration `i`'s 3 × p rows.
    #[must_use]
    pub fn block(&self, i: usize) -> DMatrix<f64> {
        to_dmatrix(self.blocks.block(i))
    }

    /// The known distances' information `CᵀC` as the prior every design
    /// adds to, or `None` without a known distance.
    #[must_use]
    pub fn prior(&self) -> Option<Prior> {
        if self.constraints.nrows() == 0 {
            return None;
        }
        let m = self.constraints.transpose() * &self.constraints;
        let m = Mat::from_fn(m.nrows(), m.ncols(), |i, j| m[(i, j)]);
        Some(Prior::from_matrix(m.as_ref(), 0).expect("a finite square information"))
    }
}

/// A faer matrix as a nalgebra one.
fn to_dmatrix(m: MatRef<'_, f64>) -> DMatrix<f64> {
    DMatrix::from_fn(m.nrows(), m.ncols(), |i, j| m[(i, j)])
}

/// `M = CᵀC + Σ X_iᵀ X_i` over `design` (`C` the known distances' rows,
/// [`SocketPool::constraints`]).
#[must_use]
pub fn information(pool: &SocketPool, design: &[usize]) -> DMatrix<f64> {
    pool.constraints.transpose() * &pool.constraints
        + to_dmatrix(pool.blocks.information(design).as_ref())
}

/// The pool's second moment about each socket's mean,
/// `W = Σ_q (X_q − X̄_s(q))ᵀ (X_q − X̄_s(q)) / (3N)`: `tr(M⁻¹ W)` is the mean
/// squared deviation, per coordinate, of a pool configuration's predicted
/// tool point from its socket's mean prediction (a point's own columns are
/// the same for every row of its socket and drop out).
#[must_use]
pub fn consistency_moment(pool: &SocketPool) -> DMatrix<f64> {
    let p = pool.p();
    let n = pool.blocks.n_poses();
    let k = pool.sockets.iter().max().map_or(0, |m| m + 1);
    let mut sums = vec![DMatrix::zeros(3, p); k];
    let mut counts = vec![0usize; k];
    for (i, &g) in pool.sockets.iter().enumerate() {
        sums[g] += pool.block(i);
        counts[g] += 1;
    }
    let means: Vec<DMatrix<f64>> = sums
        .into_iter()
        .zip(&counts)
        .map(|(s, &c)| s / c.max(1) as f64)
        .collect();
    let mut w = DMatrix::zeros(p, p);
    for (i, &g) in pool.sockets.iter().enumerate() {
        let c = pool.block(i) - &means[g];
        w += c.transpose() * c;
    }
    w / (3.0 * n as f64)
}

/// The predicted consistency error of `design` in units of σ: the RMS
/// over the pool, per coordinate, of a calibrated prediction's deviation
/// from the socket's mean prediction, `√tr(M⁻¹ W)` ([`consistency_moment`]);
/// infinite when `M` is singular by the shared rank rule (condition of the
/// equilibrated information above 1e13).
#[must_use]
pub fn predicted_consistency(pool: &SocketPool, design: &[usize]) -> f64 {
    predicted_error(pool, design, &consistency_moment(pool))
}

/// The predicted error `√tr(M⁻¹ W)` of `design` for a moment `w` (p × p,
/// in units of σ²): [`consistency_moment`] gives the consistency error,
/// `predict::true_error_moment` the tool point's true error.
/// Infinite when `M` is singular by the shared rank rule (condition of the
/// equilibrated information above 1e13).
#[must_use]
pub fn predicted_error(pool: &SocketPool, design: &[usize], w: &DMatrix<f64>) -> f64 {
    let m = information(pool, design);
    let d: Vec<f64> = (0..m.nrows()).map(|i| m[(i, i)].max(0.0).sqrt()).collect();
    if d.iter().any(|&v| v <= 0.0) {
        return f64::INFINITY;
    }
    let scaled = DMatrix::from_fn(m.nrows(), m.ncols(), |i, j| m[(i, j)] / (d[i] * d[j]));
    let eig = scaled.clone().symmetric_eigenvalues();
    if eig.min() <= eig.max() / crate::linalg::rank::MAX_CONDITION {
        return f64::INFINITY;
    }
    let ws = DMatrix::from_fn(w.nrows(), w.ncols(), |i, j| w[(i, j)] / (d[i] * d[j]));
    match scaled.cholesky() {
        Some(ch) => (ch.inverse() * ws).trace().max(0.0).sqrt(),
        None => f64::INFINITY,
    }
}

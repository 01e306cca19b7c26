//! Stacked per-pose Jacobian blocks: the identification Jacobian of a whole
//! pose pool in one contiguous, column-major faer matrix.

use crate::kinematics::{Evaluator, Motion};
use crate::measure::sensor_for;
use crate::model::{ParamTable, Robot};
use faer::{Mat, MatRef};
use rayon::prelude::*;

/// The identification Jacobians of `n` poses stacked into one `t·n × p`
/// matrix: the `t` rows of pose `i` are rows `t·i .. t·i + t`.
///
/// `t` is the number of measured coordinates per pose (3 for a point, 6 for a
/// full pose) and `p` the number of unknown parameters. Column-major storage
/// makes the batched products of the selection algorithms (`X · A` with a
/// `p × k` matrix `A`) single dense GEMM calls.
#[derive(Clone, Debug)]
pub struct Blocks {
    mat: Mat<f64>,
    t: usize,
}

impl Blocks {
    /// Wraps a stacked matrix. Panics if its row count is not a multiple of `t`
    /// or `t` is 0 (an internal shape bug, not user input).
    #[must_use]
    pub fn new(mat: Mat<f64>, t: usize) -> Self {
        assert!(
            t > 0 && mat.nrows().is_multiple_of(t),
            "rows must be a multiple of t"
        );
        Self { mat, t }
    }

    /// Builds blocks from a row-major buffer of `n·t` rows of `p` entries.
    #[must_use]
    pub fn from_row_major(rows: &[f64], t: usize, p: usize) -> Self {
        assert!(p > 0 && rows.len().is_multiple_of(t * p));
        let m = rows.len() / p;
        Self::new(Mat::from_fn(m, p, |r, c| rows[r * p + c]), t)
    }

    /// Rows per pose.
    #[must_use]
    pub fn t(&self) -> usize {
        self.t
    }

    /// Number of poses.
    #[must_use]
    pub fn n_poses(&self) -> usize {
        self.mat.nrows() / self.t
    }

    /// Number of columns (unknown parameters).
    #[must_use]
    pub fn p(&self) -> usize {
        self.mat.ncols()
    }

    /// The whole stacked matrix.
    #[must_use]
    pub fn mat(&self) -> MatRef<'_, f64> {
        self.mat.as_ref()
    }

    /// The `t × p` block of pose `i`.
    #[must_use]
    pub fn block(&self, i: usize) -> MatRef<'_, f64> {
        self.mat.as_ref().subrows(i * self.t, self.t)
    }

    /// Copies the blocks of the given poses, in order, into a new stacked matrix.
    #[must_use]
    pub fn select(&self, poses: &[usize]) -> Blocks {
        let t = self.t;
        let mat = Mat::from_fn(poses.len() * t, self.p(), |r, c| {
            self.mat[(poses[r / t] * t + r % t, c)]
        });
        Blocks { mat, t }
    }

    /// `Xᵀ X` summed over the given poses (the information matrix of a design).
    #[must_use]
    pub fn information(&self, poses: &[usize]) -> Mat<f64> {
        let x = self.select(poses);
        x.mat.transpose() * &x.mat
    }
}

/// Identification Jacobian of `n` poses whose joint angles `fill_q(k, q)`
/// writes, computed in parallel into one [`Blocks`]: per pose, the chain's
/// per-unknown motions ([`Evaluator::motions`]) made into rows by the robot's
/// sensor ([`crate::measure::Sensor::motion_rows`], one call per pose).
pub fn jacobian_of<F>(robot: &Robot, table: &ParamTable, n: usize, fill_q: F) -> Blocks
where
    F: Fn(usize, &mut [f64]) + Sync,
{
    let sensor = sensor_for(robot);
    jacobian_with(
        robot,
        table,
        sensor.as_ref(),
        &table.marker_values(),
        n,
        fill_q,
    )
}

/// Identification Jacobian of `n` poses (joint angles written by
/// `fill_q(k, q)`) as `sensor` sees them, its own parameters at `own`:
/// `robot.n_unknowns() + own.len()` columns, the sensor's rows per pose.
/// Any [`crate::measure::Sensor`] (a camera's, a contact's) goes through
/// this one loop.
pub fn jacobian_with<F>(
    robot: &Robot,
    table: &ParamTable,
    sensor: &dyn crate::measure::Sensor,
    own: &[f64],
    n: usize,
    fill_q: F,
) -> Blocks
where
    F: Fn(usize, &mut [f64]) + Sync,
{
    let t = sensor.rows();
    let mut mat = Mat::<f64>::zeros(n * t, robot.n_unknowns() + own.len());
    fill_jacobian(robot, table, sensor, own, &mut mat, fill_q);
    Blocks::new(mat, t)
}

/// [`jacobian_of`] with the matrix reserved fallibly: when the system
/// refuses its memory, an error naming `what` and the figure
/// ([`crate::resources::try_zeros_mat`]) instead of an abort. For the
/// large matrices (a pool's).
pub fn try_jacobian_of<F>(
    what: &str,
    robot: &Robot,
    table: &ParamTable,
    n: usize,
    fill_q: F,
) -> crate::Result<Blocks>
where
    F: Fn(usize, &mut [f64]) + Sync,
{
    let sensor = sensor_for(robot);
    let t = sensor.rows();
    let mut mat = crate::resources::try_zeros_mat(what, n.saturating_mul(t), robot.n_params())?;
    fill_jacobian(
        robot,
        table,
        sensor.as_ref(),
        &table.marker_values(),
        &mut mat,
        fill_q,
    );
    Ok(Blocks::new(mat, t))
}

/// Writes the rows of every pose as `sensor` sees them (its own
/// parameters at `own`) into `mat` (`n·t × p`), straight into the
/// column-major matrix, chunk by chunk of rows (no row-major copy: a
/// 10⁶-pose pool's Jacobian is 650 MB already).
fn fill_jacobian<F>(
    robot: &Robot,
    table: &ParamTable,
    sensor: &dyn crate::measure::Sensor,
    own: &[f64],
    mat: &mut Mat<f64>,
    fill_q: F,
) where
    F: Fn(usize, &mut [f64]) + Sync,
{
    let n_kin = robot.n_unknowns();
    let p = n_kin + own.len();
    debug_assert_eq!(mat.ncols(), p);
    let t = sensor.rows();
    let dof = robot.dof();
    let n = mat.nrows() / t;
    const CHUNK: usize = 256;
    let task = crate::progress::Task::start("jacobian", Some(n as u64));
    mat.as_mut()
        .par_row_chunks_mut(CHUNK * t)
        .enumerate()
        .for_each(|(c, mut chunk)| {
            let mut ev = Evaluator::new(robot, table);
            let mut q = vec![0.0; dof];
            let mut motions = vec![Motion::default(); n_kin];
            let mut jac = vec![0.0; t * p];
            for k in 0..chunk.nrows() / t {
                fill_q(c * CHUNK + k, &mut q);
                let end = ev.motions(&q, &mut motions);
                sensor.motion_rows(&end, own, &motions, &mut jac, p);
                if p > n_kin {
                    sensor.own_rows(&end, own, &mut jac[n_kin..], p);
                }
                for r in 0..t {
                    for col in 0..p {
                        chunk[(k * t + r, col)] = jac[r * p + col];
                    }
                }
            }
            task.inc((chunk.nrows() / t) as u64);
        });
}

mod compress;
pub use compress::COMPRESS_MAX_CONDITION;

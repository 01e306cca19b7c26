//! The errors a calibrated robot is predicted to keep at random
//! configurations, from a design's information alone.

use crate::blocks::Blocks;
use crate::measure::{RowKind, sensor_for};
use crate::model::Robot;
use faer::MatRef;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::Serialize;

/// The errors predicted at a set of configurations.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct PredictedErrors {
    /// RMS over configurations of the position error of a measured point,
    /// mm.
    pub position_rms_mm: f64,
    /// 95th percentile over configurations of the predicted RMS position
    /// error at one configuration, mm.
    pub position_p95_mm: f64,
    /// 95th percentile of the position error a measured point shows (its
    /// distance from the prediction, mm): of the error's distribution over
    /// the configurations and the noise, each configuration's error drawn
    /// [`ERROR_DRAWS`] times from its Gaussian `N(0, σ² J M⁻¹ Jᵀ)` (seeded).
    pub position_error_p95_mm: f64,
    /// RMS orientation error angle, degrees (full-pose sensors).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub orientation_rms_deg: Option<f64>,
    /// 95th percentile of the orientation error angle, degrees.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub orientation_p95_deg: Option<f64>,
}

/// `configurations` joint vectors drawn uniformly within the robot's joint
/// limits (seeded).
#[must_use]
pub fn random_configurations(robot: &Robot, count: usize, seed: u64) -> Vec<Vec<f64>> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..count)
        .map(|_| {
            robot
                .limits
                .iter()
                .map(|&[lo, hi]| lo + (hi - lo) * rng.random::<f64>())
                .collect()
        })
        .collect()
}

/// Draws of each configuration's position error for
/// [`PredictedErrors::position_error_p95_mm`].
pub const ERROR_DRAWS: usize = 32;

/// Appends to `out` [`ERROR_DRAWS`] norms (mm) of a point's position error
/// `e ~ N(0, cov)`, `cov` a 3×3 covariance (m²), drawn from `rng`.
fn error_norms(cov: &[[f64; 3]; 3], rng: &mut ChaCha8Rng, out: &mut Vec<f64>) {
    // Cholesky of a positive semi-definite 3×3, a zero pivot left zero.
    let mut l = [[0.0f64; 3]; 3];
    for i in 0..3 {
        for j in 0..=i {
            let s: f64 = cov[i][j] - (0..j).map(|k| l[i][k] * l[j][k]).sum::<f64>();
            l[i][j] = if i == j {
                s.max(0.0).sqrt()
            } else if l[j][j] > 0.0 {
                s / l[j][j]
            } else {
                0.0
            };
        }
    }
    for _ in 0..ERROR_DRAWS {
        let z: [f64; 3] = std::array::from_fn(|_| {
            // Box–Muller: a standard normal from two uniforms in (0, 1].
            let (u1, u2) = (1.0 - rng.random::<f64>(), rng.random::<f64>());
            (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
        });
        let e: f64 = (0..3)
            .map(|i| (0..=i).map(|k| l[i][k] * z[k]).sum::<f64>().powi(2))
            .sum();
        out.push(e.sqrt() * 1e3);
    }
}

/// The value at quantile `q` (0..=1) of `v` (sorted in place; nearest rank).
pub(super) fn quantile(v: &mut [f64], q: f64) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    v.sort_unstable_by(f64::total_cmp);
    let k = ((q * v.len() as f64).ceil() as usize).clamp(1, v.len()) - 1;
    v[k]
}

/// The rows errors are predicted from: a set of configurations' Jacobian
/// blocks, what each row measures, and the weight of orientation rows.
/// [`ErrorRows::of_robot`] stacks them as the robot's sensor does; a
/// sensor whose rows are not positions (a camera's pixels) gives the
/// Jacobian of the point whose error matters instead (3 position rows a
/// configuration, [`crate::select::camera::CameraDesign::how_many`]).
#[derive(Clone, Debug)]
pub struct ErrorRows {
    /// One block a configuration (`kinds.len()` rows, the unknowns'
    /// columns), metres (or radians times the weight) per unit of each
    /// unknown.
    pub eval: Blocks,
    /// What each row of a block is.
    pub kinds: Vec<RowKind>,
    /// The weight the orientation rows carry (metres per radian; 1 when
    /// there are none).
    pub orientation_weight: f64,
    /// Position rows per measured point: 3, or the coordinates of its
    /// points a sensor reads ([`crate::measure::Sensor::point_coordinates`]:
    /// 1 for a height gauge).
    pub point_rows: usize,
}

impl ErrorRows {
    /// The robot's sensor rows (at `table`) at the configurations `qs`.
    #[must_use]
    pub fn of_robot(robot: &Robot, table: &crate::model::ParamTable, qs: &[Vec<f64>]) -> Self {
        let eval = crate::blocks::jacobian_of(robot, table, qs.len(), |k, q| {
            q.copy_from_slice(&qs[k]);
        });
        let (kinds, orientation_weight, point_rows) = sensor_rows(robot);
        ErrorRows {
            eval,
            kinds,
            orientation_weight,
            point_rows,
        }
    }

    /// The errors these rows predict after a calibration whose
    /// information matrix is `info` and noise σ is `noise` (the unit of
    /// the information's rows: metres, or pixels for a camera); `None`
    /// when `info` is singular.
    #[must_use]
    pub fn errors(&self, info: MatRef<'_, f64>, noise: f64) -> Option<PredictedErrors> {
        errors_of_rows(
            &self.eval,
            &self.kinds,
            self.orientation_weight,
            self.point_rows,
            info,
            noise,
        )
    }
}

/// The robot's sensor's row kinds, orientation weight and position rows
/// per measured point (the coordinates of a point it reads).
fn sensor_rows(robot: &Robot) -> (Vec<RowKind>, f64, usize) {
    let sensor = sensor_for(robot);
    let kinds = sensor.row_kinds().to_vec();
    let w = sensor
        .weights()
        .iter()
        .zip(&kinds)
        .find(|&(_, &k)| k == RowKind::Orientation)
        .map_or(1.0, |(w, _)| *w);
    (kinds, w, sensor.point_coordinates().len())
}

/// The errors predicted at the configurations of `eval` (their Jacobian
/// rows, as the robot's sensor stacks them) after a calibration whose
/// information matrix is `info` and noise σ is `noise` metres; `None` when
/// `info` is singular.
#[must_use]
pub fn predicted_errors(
    robot: &Robot,
    eval: &Blocks,
    info: MatRef<'_, f64>,
    noise: f64,
) -> Option<PredictedErrors> {
    let (kinds, w, point_rows) = sensor_rows(robot);
    errors_of_rows(eval, &kinds, w, point_rows, info, noise)
}

/// [`ErrorRows::errors`] on borrowed rows.
fn errors_of_rows(
    eval: &Blocks,
    kinds: &[RowKind],
    w: f64,
    point_rows: usize,
    info: MatRef<'_, f64>,
    noise: f64,
) -> Option<PredictedErrors> {
    let inv = crate::linalg::chol::spd_inverse(info)?;
    let full = kinds.contains(&RowKind::Orientation);
    let s2 = noise * noise;
    // The position rows, a point's `point_rows` in a row.
    let rows: Vec<usize> = (0..kinds.len())
        .filter(|&r| kinds[r] == RowKind::Position)
        .collect();
    // Measured points per configuration: position rows over a point's rows
    // (three, or the coordinates of its points a sensor reads).
    let points = rows.len() as f64 / point_rows as f64;
    let mut rng = ChaCha8Rng::seed_from_u64(0);
    let (mut pos, mut ori, mut norms) = (Vec::new(), Vec::new(), Vec::new());
    for i in 0..eval.n_poses() {
        let b = eval.block(i);
        let xc = b * inv.as_ref();
        let mut tr = [0.0f64; 2];
        for r in 0..b.nrows() {
            let v: f64 = (0..b.ncols()).map(|c| xc[(r, c)] * b[(r, c)]).sum();
            tr[usize::from(kinds[r] == RowKind::Orientation)] += v.max(0.0);
        }
        pos.push((s2 * tr[0] / points.max(1.0)).sqrt() * 1e3);
        ori.push((s2 * tr[1]).sqrt() / w * 180.0 / std::f64::consts::PI);
        for t in rows.chunks_exact(point_rows) {
            // A point's coordinates the sensor reads; the others' error 0.
            let cov: [[f64; 3]; 3] = std::array::from_fn(|a| {
                std::array::from_fn(|c| {
                    if a < t.len() && c < t.len() {
                        s2 * (0..b.ncols())
                            .map(|k| xc[(t[a], k)] * b[(t[c], k)])
                            .sum::<f64>()
                    } else {
                        0.0
                    }
                })
            });
            error_norms(&cov, &mut rng, &mut norms);
        }
    }
    let rms = |v: &[f64]| (v.iter().map(|x| x * x).sum::<f64>() / v.len().max(1) as f64).sqrt();
    Some(PredictedErrors {
        position_rms_mm: rms(&pos),
        position_p95_mm: quantile(&mut pos.clone(), 0.95),
        position_error_p95_mm: quantile(&mut norms, 0.95),
        orientation_rms_deg: full.then(|| rms(&ori)),
        orientation_p95_deg: full.then(|| quantile(&mut ori, 0.95)),
    })
}

//! Monte-Carlo evaluation of designs: `R` noise realisations, each identified
//! from the nominal start; per-parameter RMSE against the predicted standard
//! deviations, the empirical covariance against the predicted `σ² (XᵀX)⁻¹`
//! (generalised-variance ratio), and the RMS position error on held-out
//! validation poses before and after calibration.
//!
//! Trials run in parallel with rayon. Trial `t` draws its noise from
//! [`trial_rng`]`(seed, t)` and results are reduced in trial order, so a
//! summary depends on the seed only, never on the number of threads.

use super::lm::{LmSettings, Status, identify, predicted_covariance};
use super::simulate::{simulate, trial_rng};
use super::{IdentifyError, Result};
use crate::blocks::jacobian_of;
use crate::kinematics::{pose, position};
use crate::linalg::chol::ln_det_spd_equilibrated as ln_det_spd;
use crate::linalg::gram::{gram_of as gram, product};
use crate::measure::so3;
use crate::measure::{RowKind, sensor_for};
use crate::model::{ParamTable, Robot};
use crate::pool::Pool;
use faer::Mat;
use nalgebra::{UnitQuaternion, Vector3};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// Stream of the validation-pose sampler (trial streams are `0..trials`).
const VALIDATION_STREAM: u64 = u64::MAX;
/// Stream of the bootstrap resampler.
const BOOTSTRAP_STREAM: u64 = u64::MAX - 1;

/// Settings of a Monte-Carlo run, with documented defaults.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct MonteCarloSettings {
    /// Noise realisations `R`. Default 200.
    pub trials: usize,
    /// Measurement noise σ per coordinate, metres. Default 0.01 (paper §V).
    pub sigma: f64,
    /// Seed of the noise, the validation poses and the bootstrap. Default 0.
    pub seed: u64,
    /// Held-out validation poses. Default 500.
    pub validation_poses: usize,
    /// Bootstrap resamples for the spread of the generalised-variance ratio
    /// (0 to skip). Default 200.
    pub bootstrap: usize,
    /// The solver's settings.
    pub lm: LmSettings,
}

impl Default for MonteCarloSettings {
    fn default() -> Self {
        Self {
            trials: 200,
            sigma: 0.01,
            seed: 0,
            validation_poses: 500,
            bootstrap: 200,
            lm: LmSettings::default(),
        }
    }
}

impl MonteCarloSettings {
    /// Sets [`MonteCarloSettings::trials`].
    #[must_use]
    pub fn with_trials(mut self, trials: usize) -> Self {
        self.trials = trials;
        self
    }

    /// Sets [`MonteCarloSettings::sigma`].
    #[must_use]
    pub fn with_sigma(mut self, sigma: f64) -> Self {
        self.sigma = sigma;
        self
    }

    /// Sets [`MonteCarloSettings::seed`].
    #[must_use]
    pub fn with_seed(mut self, seed: u64) -> Self {
        self.seed = seed;
        self
    }

    /// Sets [`MonteCarloSettings::validation_poses`].
    #[must_use]
    pub fn with_validation_poses(mut self, n: usize) -> Self {
        self.validation_poses = n;
        self
    }

    /// Sets [`MonteCarloSettings::bootstrap`].
    #[must_use]
    pub fn with_bootstrap(mut self, b: usize) -> Self {
        self.bootstrap = b;
        self
    }

    /// Checks every setting is in range.
    pub fn validate(&self) -> Result<()> {
        if self.trials == 0 {
            return Err(IdentifyError::Setting {
                name: "trials",
                value: "0".into(),
                reason: "at least one trial is needed",
            });
        }
        if !(self.sigma.is_finite() && self.sigma >= 0.0) {
            return Err(IdentifyError::Setting {
                name: "sigma",
                value: self.sigma.to_string(),
                reason: "the noise standard deviation must be finite and >= 0",
            });
        }
        if self.validation_poses == 0 {
            return Err(IdentifyError::Setting {
                name: "validation_poses",
                value: "0".into(),
                reason: "at least one held-out pose is needed (the RMS error of no poses is no measurement)",
            });
        }
        self.lm.validate()
    }
}

/// Held-out poses and the real robot's end points (and, for a full-pose
/// robot, end orientations) there.
#[derive(Clone, Debug, Serialize)]
pub struct ValidationSet {
    /// Lattice indices of the poses, when they come from a pool.
    pub lattice_indices: Vec<usize>,
    /// Joint vectors.
    pub qs: Vec<Vec<f64>>,
    #[serde(skip)]
    truth: Vec<Vector3<f64>>,
    /// True orientations; empty for a point robot.
    #[serde(skip)]
    truth_rot: Vec<UnitQuaternion<f64>>,
}

impl ValidationSet {
    /// `n` distinct pool poses drawn uniformly (seeded) from those whose pool
    /// positions are not in `exclude`. Errors when fewer than `n` remain.
    pub fn sample(
        robot: &Robot,
        pool: &Pool,
        exclude: &[usize],
        n: usize,
        seed: u64,
    ) -> Result<ValidationSet> {
        let mut taken = vec![false; pool.len()];
        for &k in exclude {
            if k >= pool.len() {
                return Err(IdentifyError::Design {
                    name: "validation".into(),
                    reason: format!("pool position {k} is outside the pool of {}", pool.len()),
                });
            }
            taken[k] = true;
        }
        let mut free: Vec<usize> = (0..pool.len()).filter(|&k| !taken[k]).collect();
        if free.len() < n {
            return Err(IdentifyError::Setting {
                name: "validation_poses",
                value: n.to_string(),
                reason: "more validation poses than pool poses outside the designs",
            });
        }
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        rng.set_stream(VALIDATION_STREAM);
        // Partial Fisher–Yates: the first n entries are a uniform sample.
        for i in 0..n {
            let j = rng.random_range(i..free.len());
            free.swap(i, j);
        }
        free.truncate(n);
        free.sort_unstable();
        let qs = free.iter().map(|&k| pool.q(k)).collect();
        let mut v = Self::from_qs(robot, qs)?;
        v.lattice_indices = free.iter().map(|&k| pool.ids[k]).collect();
        Ok(v)
    }

    /// Validation at given joint vectors.
    pub fn from_qs(robot: &Robot, qs: Vec<Vec<f64>>) -> Result<ValidationSet> {
        for (i, q) in qs.iter().enumerate() {
            robot
                .check_q(q)
                .map_err(|source| IdentifyError::Pose { pose: i, source })?;
        }
        let poses: Vec<_> = qs.iter().map(|q| pose(robot, &robot.real, q)).collect();
        let truth = poses.iter().map(|(_, p)| *p).collect();
        let truth_rot = if sensor_for(robot).observes_orientation() {
            poses.iter().map(|(r, _)| so3::to_quaternion(r)).collect()
        } else {
            Vec::new()
        };
        Ok(ValidationSet {
            lattice_indices: Vec::new(),
            qs,
            truth,
            truth_rot,
        })
    }

    /// Number of poses.
    #[must_use]
    pub fn len(&self) -> usize {
        self.qs.len()
    }

    /// Whether there are no poses.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.qs.is_empty()
    }

    /// RMS distance `√(mean ‖p(table, q) − p(real, q)‖²)` over the poses
    /// (0 for an empty set).
    #[must_use]
    pub fn rms(&self, robot: &Robot, table: &ParamTable) -> f64 {
        if self.qs.is_empty() {
            return 0.0;
        }
        let s: f64 = self
            .qs
            .iter()
            .zip(&self.truth)
            .map(|(q, t)| (position(robot, table, q) - t).norm_squared())
            .sum();
        (s / self.qs.len() as f64).sqrt()
    }

    /// The position error `‖p(table, q) − p(real, q)‖` at every pose, metres.
    #[must_use]
    pub fn position_errors(&self, robot: &Robot, table: &ParamTable) -> Vec<f64> {
        self.qs
            .iter()
            .zip(&self.truth)
            .map(|(q, t)| (position(robot, table, q) - t).norm())
            .collect()
    }

    /// The orientation error angle `∠(R(table, q) R(real, q)ᵀ)` at every
    /// pose, radians; empty for a point robot.
    #[must_use]
    pub fn orientation_errors(&self, robot: &Robot, table: &ParamTable) -> Vec<f64> {
        self.qs
            .iter()
            .zip(&self.truth_rot)
            .map(|(q, t)| {
                let (r, _) = pose(robot, table, q);
                so3::difference(&so3::to_quaternion(&r), t).norm()
            })
            .collect()
    }

    /// RMS orientation error `√(mean ∠(R(table, q) R(real, q)ᵀ)²)`, radians,
    /// over the poses; `None` for a point robot (or an empty set).
    #[must_use]
    pub fn orientation_rms(&self, robot: &Robot, table: &ParamTable) -> Option<f64> {
        if self.truth_rot.is_empty() {
            return None;
        }
        let s: f64 = self
            .qs
            .iter()
            .zip(&self.truth_rot)
            .map(|(q, t)| {
                let (r, _) = pose(robot, table, q);
                so3::difference(&so3::to_quaternion(&r), t).norm_squared()
            })
            .sum();
        Some((s / self.qs.len() as f64).sqrt())
    }

    /// The RMS errors the linearised model predicts after calibration with
    /// estimate covariance `c`, from one Jacobian `X_v` of the validation
    /// poses at the real parameters: the position distance `√(tr_pos / n)`
    /// and, for a full-pose robot, the orientation angle in radians
    /// `√(tr_ori / n)`, where `tr_pos` and `tr_ori` are the traces of
    /// `X_v C X_vᵀ` over the position rows and over the orientation rows
    /// (divided by [`Robot::orientation_scale`]).
    #[must_use]
    pub fn predicted_rms(&self, robot: &Robot, c: &Mat<f64>) -> (f64, Option<f64>) {
        let sensor = sensor_for(robot);
        let pose = sensor.observes_orientation();
        if self.qs.is_empty() {
            return (0.0, pose.then_some(0.0));
        }
        let x = jacobian_of(robot, &robot.real, self.qs.len(), |k, q| {
            q.copy_from_slice(&self.qs[k])
        });
        let t = x.t();
        let xc = product(x.mat(), c.as_ref());
        let m = x.mat();
        // Traces over the position rows and over the orientation rows (the
        // latter carry the orientation weight w, divided out below).
        let kinds = sensor.row_kinds();
        let weights = sensor.weights();
        let mut tr = [0.0, 0.0];
        for j in 0..m.ncols() {
            for i in 0..m.nrows() {
                tr[usize::from(kinds[i % t] == RowKind::Orientation)] += xc[(i, j)] * m[(i, j)];
            }
        }
        let n = self.qs.len() as f64;
        // Position rows per measured point: 3 (several markers per pose share
        // the distance mean over points).
        let per_pose = kinds.iter().filter(|&&k| k == RowKind::Position).count() as f64 / 3.0;
        let w = weights
            .iter()
            .zip(kinds)
            .find(|&(_, &k)| k == RowKind::Orientation)
            .map_or(1.0, |(w, _)| *w);
        (
            (tr[0].max(0.0) / (n * per_pose)).sqrt(),
            pose.then(|| (tr[1].max(0.0) / n).sqrt() / w),
        )
    }
}

/// Monte-Carlo statistics of one unknown.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ParameterStats {
    /// The unknown's name.
    pub name: String,
    /// Its real value.
    pub truth: f64,
    /// Mean estimate.
    pub mean: f64,
    /// `mean − truth`.
    pub bias: f64,
    /// Standard deviation of the estimates (divisor `R − 1`).
    pub std: f64,
    /// `√(mean (θ̂ − θ)²)`.
    pub rmse: f64,
    /// `√(σ² (XᵀX)⁻¹)_jj` at the real parameters.
    pub predicted_std: f64,
}

/// Five-number-ish summary of a sample.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Spread {
    /// Smallest value.
    pub min: f64,
    /// Median.
    pub median: f64,
    /// Mean.
    pub mean: f64,
    /// 95th percentile (nearest rank).
    pub p95: f64,
    /// Largest value.
    pub max: f64,
}

impl Spread {
    fn of(values: &[f64]) -> Option<Spread> {
        if values.is_empty() {
            return None;
        }
        let mut v = values.to_vec();
        v.sort_by(f64::total_cmp);
        let n = v.len();
        let median = if n % 2 == 1 {
            v[n / 2]
        } else {
            0.5 * (v[n / 2 - 1] + v[n / 2])
        };
        let p95 = v[((0.95 * n as f64).ceil() as usize).clamp(1, n) - 1];
        Some(Spread {
            min: v[0],
            median,
            mean: v.iter().sum::<f64>() / n as f64,
            p95,
            max: v[n - 1],
        })
    }
}

/// The empirical against the predicted covariance through their generalised
/// variances: `ln det C_emp − ln det C_pred`.
///
/// Under the linear Gaussian model `(R−1) C_emp ~ Wishart_p(C_pred, R−1)`, so
/// the log ratio is `Σ_{i=1..p} ln χ²_{R−i} − p ln(R−1)`, with mean
/// `Σ [ψ((R−i)/2) + ln 2] − p ln(R−1)` (about `−p(p+1)/(2R)`, not 0) and
/// variance `Σ ψ'((R−i)/2)`; `z` measures the observed ratio in those units.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GeneralizedVariance {
    /// `ln det C_emp − ln det C_pred`.
    pub ln_ratio: f64,
    /// Its expectation under the linear Gaussian model.
    pub expected: f64,
    /// Its standard deviation under that model.
    pub sd_model: f64,
    /// `(ln_ratio − expected) / sd_model`.
    pub z: f64,
    /// Bootstrap standard deviation of `ln det C_emp` over resampled trials
    /// (`None` when no bootstrap was asked for or there are fewer than `4p`
    /// converged trials).
    pub sd_bootstrap: Option<f64>,
    /// `ln det C_emp`.
    pub ln_det_empirical: f64,
    /// `ln det C_pred`.
    pub ln_det_predicted: f64,
}

/// Summary of a Monte-Carlo run on one design.
#[derive(Clone, Debug, Serialize)]
pub struct MonteCarloSummary {
    /// The design's name.
    pub design: String,
    /// Poses in the design.
    pub poses: usize,
    /// Trials run.
    pub trials: usize,
    /// Trials whose status was `Converged` (the statistics use these only).
    pub converged: usize,
    /// Count of each status.
    pub statuses: BTreeMap<String, usize>,
    /// Noise σ, metres.
    pub sigma: f64,
    /// Seed.
    pub seed: u64,
    /// `ln det XᵀX` at the nominal parameters: what pose selection maximises.
    pub ln_det_information_nominal: Option<f64>,
    /// `ln det XᵀX` at the real parameters: what governs the estimate.
    pub ln_det_information_real: Option<f64>,
    /// Outer iterations per trial.
    pub iterations: Option<Spread>,
    /// Per-unknown statistics.
    pub parameters: Vec<ParameterStats>,
    /// `rmse / predicted_std` across the unknowns (≈ 1 when the linearised
    /// covariance is right).
    pub rmse_over_predicted: Option<Spread>,
    /// The generalised-variance comparison (needs `converged > p` and σ > 0).
    pub generalized_variance: Option<GeneralizedVariance>,
    /// Validation poses used.
    pub validation_poses: usize,
    /// RMS position error on the validation poses with the nominal model.
    pub validation_rms_before: f64,
    /// RMS position error on the validation poses after calibration, over trials.
    pub validation_rms_after: Option<Spread>,
    /// The RMS error after calibration that the predicted covariance implies.
    pub validation_rms_predicted: Option<f64>,
    /// Full-pose robots: RMS orientation error (radians) on the validation
    /// poses with the nominal model.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub validation_orientation_rms_before: Option<f64>,
    /// Full-pose robots: RMS orientation error (radians) after calibration,
    /// over trials.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub validation_orientation_rms_after: Option<Spread>,
    /// Full-pose robots: the RMS orientation error (radians) the predicted
    /// covariance implies.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub validation_orientation_rms_predicted: Option<f64>,
}

/// Several designs evaluated on the same noise seeds and validation poses.
#[derive(Clone, Debug, Serialize)]
pub struct Comparison {
    /// The settings used.
    pub settings: MonteCarloSettings,
    /// Lattice indices of the validation poses (outside every design).
    pub validation_indices: Vec<usize>,
    /// One summary per design, in the order given.
    pub designs: Vec<MonteCarloSummary>,
}

/// One trial's outcome.
struct Trial {
    status: Status,
    iterations: usize,
    estimate: Vec<f64>,
    rms_after: f64,
    orientation_rms_after: Option<f64>,
}

/// Runs `settings.trials` noisy identifications of the design `qs` (joint
/// vectors) from the nominal start and summarises them.
pub fn monte_carlo(
    robot: &Robot,
    name: &str,
    qs: &[Vec<f64>],
    validation: &ValidationSet,
    settings: &MonteCarloSettings,
) -> Result<MonteCarloSummary> {
    settings.validate()?;
    robot.validate()?;
    if qs.is_empty() {
        return Err(IdentifyError::Empty);
    }
    let names = robot.parameter_names();
    let p = names.len();
    let truth = robot.unknown_values(&robot.real);

    // Trials in parallel, reduced in trial order.
    let trials = run_trials(robot, qs, validation, settings)?;
    let statuses = status_counts(&trials);
    let used: Vec<&Trial> = trials
        .iter()
        .filter(|t| t.status == Status::Converged)
        .collect();
    let r = used.len();

    // ---- predicted covariance and design information -------------------------
    let c_pred = predicted_covariance(robot, &robot.real, qs, settings.sigma)?;
    let ln_det_info = |table: &ParamTable| {
        let x = jacobian_of(robot, table, qs.len(), |k, q| q.copy_from_slice(&qs[k]));
        ln_det_spd(gram(x.mat()).as_ref())
    };

    let parameters = parameter_stats(&names, &truth, &used, c_pred.as_ref());
    let ratios: Vec<f64> = parameters
        .iter()
        .map(|s| s.rmse / s.predicted_std)
        .filter(|v| v.is_finite())
        .collect();

    // ---- generalised variance ---------------------------------------------------
    let generalized_variance = match &c_pred {
        Some(c) if r > p && settings.sigma > 0.0 => {
            let estimates: Vec<&[f64]> = used.iter().map(|t| t.estimate.as_slice()).collect();
            generalized_variance(&estimates, c, settings)
        }
        _ => None,
    };

    let before = validation.rms(robot, &robot.nominal);
    let predicted = c_pred.as_ref().map(|c| validation.predicted_rms(robot, c));
    let after: Vec<f64> = used.iter().map(|t| t.rms_after).collect();
    let after_rot: Vec<f64> = used
        .iter()
        .filter_map(|t| t.orientation_rms_after)
        .collect();
    Ok(MonteCarloSummary {
        design: name.to_string(),
        poses: qs.len(),
        trials: trials.len(),
        converged: r,
        statuses,
        sigma: settings.sigma,
        seed: settings.seed,
        ln_det_information_nominal: ln_det_info(&robot.nominal),
        ln_det_information_real: ln_det_info(&robot.real),
        iterations: Spread::of(
            &trials
                .iter()
                .map(|t| t.iterations as f64)
                .collect::<Vec<_>>(),
        ),
        parameters,
        rmse_over_predicted: Spread::of(&ratios),
        generalized_variance,
        validation_poses: validation.len(),
        validation_rms_before: before,
        validation_rms_after: Spread::of(&after),
        validation_rms_predicted: predicted.map(|p| p.0),
        validation_orientation_rms_before: validation.orientation_rms(robot, &robot.nominal),
        validation_orientation_rms_after: Spread::of(&after_rot),
        validation_orientation_rms_predicted: predicted.and_then(|p| p.1),
    })
}

/// The trials, in parallel, reduced in trial order (each on its own seeded
/// noise, so the result does not depend on the thread count).
fn run_trials(
    robot: &Robot,
    qs: &[Vec<f64>],
    validation: &ValidationSet,
    settings: &MonteCarloSettings,
) -> Result<Vec<Trial>> {
    let task = crate::progress::Task::start("monte-carlo trials", Some(settings.trials as u64));
    let trials: Vec<Result<Trial>> = (0..settings.trials)
        .into_par_iter()
        .map(|t| {
            let _tick = task.tick();
            let meas = simulate(
                robot,
                &robot.real,
                qs,
                settings.sigma,
                &mut trial_rng(settings.seed, t as u64),
            )?;
            let id = identify(robot, &robot.nominal, &meas, &settings.lm)?;
            let rms_after = validation.rms(robot, &id.table);
            let orientation_rms_after = validation.orientation_rms(robot, &id.table);
            Ok(Trial {
                status: id.status,
                iterations: id.iterations,
                estimate: id.estimate,
                rms_after,
                orientation_rms_after,
            })
        })
        .collect();
    trials.into_iter().collect()
}

/// How many trials ended in each status (by its serialised name).
fn status_counts(trials: &[Trial]) -> BTreeMap<String, usize> {
    let mut statuses = BTreeMap::new();
    for t in trials {
        let key = serde_json::to_value(t.status)
            .ok()
            .and_then(|v| v.as_str().map(str::to_string))
            .unwrap_or_default();
        *statuses.entry(key).or_insert(0) += 1;
    }
    statuses
}

/// Per-parameter statistics of the converged trials `used` against the
/// truth and the predicted covariance.
fn parameter_stats(
    names: &[String],
    truth: &[f64],
    used: &[&Trial],
    c_pred: Option<&Mat<f64>>,
) -> Vec<ParameterStats> {
    let (p, r) = (names.len(), used.len());
    let mean: Vec<f64> = (0..p)
        .map(|j| used.iter().map(|t| t.estimate[j]).sum::<f64>() / r.max(1) as f64)
        .collect();
    if r == 0 {
        Vec::new()
    } else {
        (0..p)
            .map(|j| {
                let var = used
                    .iter()
                    .map(|t| (t.estimate[j] - mean[j]).powi(2))
                    .sum::<f64>()
                    / (r.max(2) - 1) as f64;
                let mse = used
                    .iter()
                    .map(|t| (t.estimate[j] - truth[j]).powi(2))
                    .sum::<f64>()
                    / r as f64;
                ParameterStats {
                    name: names[j].clone(),
                    truth: truth[j],
                    mean: mean[j],
                    bias: mean[j] - truth[j],
                    std: var.sqrt(),
                    rmse: mse.sqrt(),
                    predicted_std: c_pred.map_or(f64::NAN, |c| c[(j, j)].sqrt()),
                }
            })
            .collect()
    }
}

/// Evaluates several designs (pool positions) on the same noise seeds and the
/// same validation poses, drawn from the pool outside every design.
pub fn compare_designs(
    robot: &Robot,
    pool: &Pool,
    designs: &[(String, Vec<usize>)],
    settings: &MonteCarloSettings,
) -> Result<Comparison> {
    settings.validate()?;
    if designs.is_empty() {
        return Err(IdentifyError::Setting {
            name: "designs",
            value: "[]".into(),
            reason: "at least one design is needed",
        });
    }
    let mut union = Vec::new();
    for (name, poses) in designs {
        if poses.is_empty() {
            return Err(IdentifyError::Design {
                name: name.clone(),
                reason: "it has no poses".into(),
            });
        }
        if let Some(&k) = poses.iter().find(|&&k| k >= pool.len()) {
            return Err(IdentifyError::Design {
                name: name.clone(),
                reason: format!("pool position {k} is outside the pool of {}", pool.len()),
            });
        }
        union.extend_from_slice(poses);
    }
    let validation = ValidationSet::sample(
        robot,
        pool,
        &union,
        settings.validation_poses,
        settings.seed,
    )?;
    let summaries = designs
        .iter()
        .map(|(name, poses)| {
            let qs: Vec<Vec<f64>> = poses.iter().map(|&k| pool.q(k)).collect();
            monte_carlo(robot, name, &qs, &validation, settings)
        })
        .collect::<Result<Vec<_>>>()?;
    Ok(Comparison {
        settings: settings.clone(),
        validation_indices: validation.lattice_indices.clone(),
        designs: summaries,
    })
}

/// Sample covariance (divisor `n − 1`) of the rows `idx` of `x`.
fn sample_covariance(x: &[&[f64]], idx: &[usize]) -> Mat<f64> {
    let p = x[0].len();
    let n = idx.len() as f64;
    let mut mean = vec![0.0; p];
    for &i in idx {
        for j in 0..p {
            mean[j] += x[i][j] / n;
        }
    }
    let mut c = Mat::<f64>::zeros(p, p);
    for &i in idx {
        for a in 0..p {
            let da = x[i][a] - mean[a];
            for b in 0..=a {
                c[(a, b)] += da * (x[i][b] - mean[b]);
            }
        }
    }
    for a in 0..p {
        for b in 0..=a {
            let v = c[(a, b)] / (n - 1.0);
            c[(a, b)] = v;
            c[(b, a)] = v;
        }
    }
    c
}

fn generalized_variance(
    estimates: &[&[f64]],
    c_pred: &Mat<f64>,
    settings: &MonteCarloSettings,
) -> Option<GeneralizedVariance> {
    let r = estimates.len();
    let p = c_pred.nrows();
    let all: Vec<usize> = (0..r).collect();
    let ln_emp = ln_det_spd(sample_covariance(estimates, &all).as_ref())?;
    let ln_pred = ln_det_spd(c_pred.as_ref())?;
    let n = (r - 1) as f64;
    let (mut expected, mut var) = (-(p as f64) * n.ln(), 0.0);
    for i in 1..=p {
        let k = (r - i) as f64 / 2.0;
        expected += digamma(k) + std::f64::consts::LN_2;
        var += trigamma(k);
    }
    // A resample repeats trials (about 63% distinct), so it only estimates a
    // p × p covariance well when r is several times p: skip the bootstrap
    // below 4p trials, and skip resamples with at most 2p distinct trials.
    let sd_bootstrap = (settings.bootstrap > 1 && r >= 4 * p)
        .then(|| {
            let mut rng = ChaCha8Rng::seed_from_u64(settings.seed);
            rng.set_stream(BOOTSTRAP_STREAM);
            let draws: Vec<Vec<usize>> = (0..settings.bootstrap)
                .map(|_| (0..r).map(|_| rng.random_range(0..r)).collect())
                .collect();
            let vals: Vec<f64> = draws
                .par_iter()
                .filter(|idx| {
                    let mut seen = vec![false; r];
                    idx.iter().for_each(|&i| seen[i] = true);
                    seen.iter().filter(|&&b| b).count() > 2 * p
                })
                .filter_map(|idx| ln_det_spd(sample_covariance(estimates, idx).as_ref()))
                .collect();
            if vals.len() < 2 {
                return None;
            }
            let m = vals.iter().sum::<f64>() / vals.len() as f64;
            let var = vals.iter().map(|v| (v - m).powi(2)).sum::<f64>() / (vals.len() as f64 - 1.0);
            Some(var.sqrt())
        })
        .flatten();
    let sd_model = var.sqrt();
    let ln_ratio = ln_emp - ln_pred;
    Some(GeneralizedVariance {
        ln_ratio,
        expected,
        sd_model,
        z: (ln_ratio - expected) / sd_model,
        sd_bootstrap: sd_bootstrap.filter(|v| v.is_finite()),
        ln_det_empirical: ln_emp,
        ln_det_predicted: ln_pred,
    })
}

/// Digamma ψ(x) for x > 0: recurrence `ψ(x) = ψ(x+1) − 1/x` up to x ≥ 10,
/// then the asymptotic series to `x⁻¹⁰` (next term < 2e-14 there).
fn digamma(mut x: f64) -> f64 {
    let mut acc = 0.0;
    while x < 10.0 {
        acc -= 1.0 / x;
        x += 1.0;
    }
    let x2 = 1.0 / (x * x);
    acc + x.ln()
        - 0.5 / x
        - x2 * (1.0 / 12.0
            - x2 * (1.0 / 120.0 - x2 * (1.0 / 252.0 - x2 * (1.0 / 240.0 - x2 / 132.0))))
}

/// Trigamma ψ'(x) for x > 0: recurrence `ψ'(x) = ψ'(x+1) + 1/x²` up to
/// x ≥ 10, then the asymptotic series to `x⁻¹¹` (next term < 3e-14 there).
fn trigamma(mut x: f64) -> f64 {
    let mut acc = 0.0;
    while x < 10.0 {
        acc += 1.0 / (x * x);
        x += 1.0;
    }
    let x2 = 1.0 / (x * x);
    acc + 1.0 / x
        + x2 / 2.0
        + (x2 / x)
            * (1.0 / 6.0
                - x2 * (1.0 / 30.0 - x2 * (1.0 / 42.0 - x2 * (1.0 / 30.0 - x2 * 5.0 / 66.0))))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn polygamma_values() {
        // ψ(1) = −γ, ψ(1/2) = −γ − 2 ln 2, ψ'(1) = π²/6, ψ'(1/2) = π²/2.
        let euler = 0.577_215_664_901_532_9;
        let pi2 = std::f64::consts::PI.powi(2);
        assert!((digamma(1.0) + euler).abs() < 1e-12);
        assert!((digamma(0.5) + euler + 2.0 * std::f64::consts::LN_2).abs() < 1e-12);
        assert!((trigamma(1.0) - pi2 / 6.0).abs() < 1e-12);
        assert!((trigamma(0.5) - pi2 / 2.0).abs() < 1e-12);
        assert!((digamma(100.0) - 4.600_161_852_738_087).abs() < 1e-12);
    }

    #[test]
    fn spread_quantiles() {
        let s = Spread::of(&[3.0, 1.0, 2.0, 4.0]).unwrap();
        assert_eq!((s.min, s.median, s.mean, s.max), (1.0, 2.5, 2.5, 4.0));
        assert_eq!(s.p95, 4.0);
        assert!(Spread::of(&[]).is_none());
    }
}

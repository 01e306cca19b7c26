//! Monte-Carlo evaluation of designs: `R` noise realisations, each identified
//! from the nominal start; per-parameter RMSE against the predicted standard
//! deviations, the empirical covariance against the predicted `σ² (XᵀX)⁻¹`
//! (generalised-variance ratio), and the RMS position error on held-out
//! validation poses before and after calibration.
//!
//! Trials run in parallel with rayon. Trial `t` draws its noise from
//! [`trial_rng`]`(seed, t)` and results are reduced in trial order, so a
//! summary depends on the seed only, never on the number of threads.

mod covariance;
mod settings;
mod summary;
mod validation;

pub use settings::MonteCarloSettings;
pub use summary::{Comparison, GeneralizedVariance, MonteCarloSummary, ParameterStats, Spread};
pub use validation::ValidationSet;

use super::lm::{Status, identify, predicted_covariance};
use super::simulate::{simulate, trial_rng};
use super::{IdentifyError, Result};
use crate::blocks::jacobian_of;
use crate::linalg::chol::ln_det_spd_equilibrated as ln_det_spd;
use crate::linalg::gram::gram_of as gram;
use crate::model::{ParamTable, Robot};
use crate::pool::Pool;
use covariance::generalized_variance;
use faer::Mat;
use rayon::prelude::*;
use std::collections::BTreeMap;

/// Stream of the validation-pose sampler (trial streams are `0..trials`).
const VALIDATION_STREAM: u64 = u64::MAX;
/// Stream of the bootstrap resampler.
const BOOTSTRAP_STREAM: u64 = u64::MAX - 1;

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
        return Err(crate::data::DataError::Empty.into());
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

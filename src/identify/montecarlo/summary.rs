//! What a Monte-Carlo run reports: per-unknown statistics, spreads, the
//! generalised-variance comparison, and the summary of one design and of
//! several.

use super::settings::MonteCarloSettings;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

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
    /// The spread of `values`; `None` when there are none.
    pub(super) fn of(values: &[f64]) -> Option<Spread> {
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
    /// RMS position error on the validation poses with the nominal model,
    /// over the coordinates of the end point the sensor reads
    /// ([`super::ValidationSet::rms`]).
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spread_quantiles() {
        let s = Spread::of(&[3.0, 1.0, 2.0, 4.0]).unwrap();
        assert_eq!((s.min, s.median, s.mean, s.max), (1.0, 2.5, 2.5, 4.0));
        assert_eq!(s.p95, 4.0);
        assert!(Spread::of(&[]).is_none());
    }
}

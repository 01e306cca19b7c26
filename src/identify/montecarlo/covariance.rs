//! The empirical covariance of the estimates against the predicted one:
//! the generalised-variance ratio, its Wishart expectation and spread
//! (digamma, trigamma) and its bootstrap spread.

use super::BOOTSTRAP_STREAM;
use super::settings::MonteCarloSettings;
use super::summary::GeneralizedVariance;
use crate::linalg::chol::ln_det_spd_equilibrated as ln_det_spd;
use faer::Mat;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

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

/// The generalised-variance comparison of the converged `estimates`
/// against the predicted covariance `c_pred`, with its bootstrap spread
/// when asked for.
pub(super) fn generalized_variance(
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
}

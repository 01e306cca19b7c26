//! The experiment's settings (the paper's values by default) and their check.

use serde::{Deserialize, Serialize};

/// Settings of the experiment; the defaults are the paper's (with 20 starts
/// and 200 Monte-Carlo trials). Check them with [`PaperSettings::validate`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct PaperSettings {
    /// Lattice values per joint (the paper: 5).
    pub levels: usize,
    /// Poses per design (the paper: 30).
    pub n: usize,
    /// Initial EAE poses (the paper: 12).
    pub initial: usize,
    /// Random designs of the baseline (the paper: 5,000).
    pub designs: usize,
    /// Starts of the multi-start EAE (20).
    pub starts: usize,
    /// Monte-Carlo calibration trials per design (200).
    pub trials: usize,
    /// Measurement noise σ per coordinate, metres (the paper: 0.01).
    pub noise: f64,
    /// Seed of every random choice (1).
    pub seed: u64,
    /// Skip the eigenvalue-OI run (false).
    pub skip_oi: bool,
}

impl Default for PaperSettings {
    fn default() -> Self {
        Self {
            levels: 5,
            n: 30,
            initial: 12,
            designs: 5000,
            starts: 20,
            trials: 200,
            noise: 0.01,
            seed: 1,
            skip_oi: false,
        }
    }
}

impl PaperSettings {
    /// Checks the ranges the pool does not check: at least one random
    /// design, start and trial, and a finite positive noise.
    pub fn validate(&self) -> Result<(), crate::Error> {
        if self.designs == 0 || self.starts == 0 || self.trials == 0 {
            return Err(crate::Error::Invalid(
                "designs, starts and trials must be at least 1".into(),
            ));
        }
        if !(self.noise.is_finite() && self.noise > 0.0) {
            return Err(crate::Error::Invalid(format!(
                "the noise must be finite and > 0, got {}",
                self.noise
            )));
        }
        Ok(())
    }
}

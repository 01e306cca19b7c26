//! The settings of a Monte-Carlo run, with their defaults and check.

use crate::identify::lm::LmSettings;
use crate::identify::{IdentifyError, Result};
use serde::{Deserialize, Serialize};

/// Settings of a Monte-Carlo run, with documented defaults: build with
/// [`MonteCarloSettings::builder`] (validated) or take the default.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
#[non_exhaustive]
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

crate::settings::settings_builder! {
    /// Validated construction of [`MonteCarloSettings`].
    MonteCarloSettingsBuilder for MonteCarloSettings, error IdentifyError {
        /// Noise realisations (default 200).
        trials: usize,
        /// Noise σ per coordinate, metres (default 0.01).
        sigma: f64,
        /// Seed (default 0).
        seed: u64,
        /// Held-out validation poses (default 500).
        validation_poses: usize,
        /// Bootstrap resamples, 0 to skip (default 200).
        bootstrap: usize,
        /// The solver's settings (default [`LmSettings::default`]).
        lm: LmSettings,
    }
}

impl MonteCarloSettings {
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
        Ok(self.lm.validate()?)
    }
}

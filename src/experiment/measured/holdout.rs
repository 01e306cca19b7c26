//! The held-out figures of a calibration from measured data: each split's
//! held-out, nominal and fitted position RMS, their means, and the pruned
//! model's.

use crate::identify::{HoldoutSettings, SplitResult};
use serde::Serialize;

/// Held-out figures over splits.
#[derive(Serialize)]
pub struct HoldoutReport {
    /// The settings.
    pub settings: HoldoutSettings,
    /// Held-out position RMS (mm): mean and per split.
    pub position_rms_mm: Stat,
    /// Held-out orientation RMS (degrees), full poses only.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub orientation_rms_deg: Option<Stat>,
    /// The nominal model's held-out position RMS (mm), mean over splits.
    pub nominal_position_rms_mm: f64,
    /// The fitted model's position RMS on its training poses, mean.
    pub fitted_position_rms_mm: f64,
    /// The pruned model (|t| ≥ 2 kept): unknowns per split and held-out
    /// position RMS.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pruned: Option<PrunedReport>,
    /// Every split.
    pub splits: Vec<SplitResult>,
}

/// A figure over splits.
#[derive(Serialize)]
pub struct Stat {
    /// Mean over splits.
    pub mean: f64,
    /// Each split's value.
    pub per_split: Vec<f64>,
}

impl Stat {
    fn of(v: Vec<f64>) -> Stat {
        Stat {
            mean: v.iter().sum::<f64>() / v.len().max(1) as f64,
            per_split: v,
        }
    }
}

/// The pruned model's held-out figures.
#[derive(Serialize)]
pub struct PrunedReport {
    /// Parameters identified per split.
    pub n_params: Vec<usize>,
    /// Held-out position RMS (mm).
    pub position_rms_mm: Stat,
    /// Held-out orientation RMS (degrees).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub orientation_rms_deg: Option<Stat>,
}

/// The held-out figures over `splits`.
pub(super) fn holdout_report(settings: HoldoutSettings, splits: Vec<SplitResult>) -> HoldoutReport {
    let mean = |v: &mut dyn Iterator<Item = f64>| {
        let x: Vec<f64> = v.collect();
        x.iter().sum::<f64>() / x.len().max(1) as f64
    };
    let ori = |f: &dyn Fn(&SplitResult) -> Option<f64>| -> Option<Stat> {
        splits
            .iter()
            .map(f)
            .collect::<Option<Vec<f64>>>()
            .map(Stat::of)
    };
    let pruned = settings.prune.then(|| PrunedReport {
        n_params: splits
            .iter()
            .filter_map(|s| s.pruned.as_ref().map(|p| p.0))
            .collect(),
        position_rms_mm: Stat::of(
            splits
                .iter()
                .filter_map(|s| s.pruned.as_ref().map(|p| p.1.position_rms_mm))
                .collect(),
        ),
        orientation_rms_deg: ori(&|s| s.pruned.as_ref().and_then(|p| p.1.orientation_rms_deg)),
    });
    HoldoutReport {
        settings,
        position_rms_mm: Stat::of(splits.iter().map(|s| s.held_out.position_rms_mm).collect()),
        orientation_rms_deg: ori(&|s| s.held_out.orientation_rms_deg),
        nominal_position_rms_mm: mean(&mut splits.iter().map(|s| s.nominal.position_rms_mm)),
        fitted_position_rms_mm: mean(&mut splits.iter().map(|s| s.fitted.position_rms_mm)),
        pruned,
        splits,
    }
}
